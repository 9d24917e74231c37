// kind = "sh-r": Ramamoorthi–Hanrahan, an isotropic BRDF as coefficients
// rho_lpq about the reflection vector (factor/sh_baseline.h); orders fixed,
// chosen by energy or by a tolerance; optionally the SHRM under the scene's SH
// lighting (factor/lighting.h) as an extra output.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "experiments/methods/tabulating.h"
#include "factor/lighting.h"
#include "factor/sh_baseline.h"
#include "solvers/parallel.h"

namespace bf {

using nlohmann::json;

namespace {

// sh-r's typed options (MethodVariant::typed).
struct ShrKindOptions {
  ShrOptions shr;
  bool shrm = false;  // also the SHRM under the scene's SH lighting
};
ShrKindOptions& shr_options(MethodVariant& m) { return kind_options<ShrKindOptions>(m); }
const ShrKindOptions& shr_options(const MethodVariant& m) { return kind_options<ShrKindOptions>(m); }

const std::vector<KeySpec>& shr_keys() {
  static const std::vector<KeySpec> keys = {
      int_key("order", 0, ShrOptions::kMaxOrder, "",
              "fixed F, with `view_order` (both or neither); without them the orders are chosen by `energy_eps` "
              "or `tolerance`"),
      int_key("view_order", 0, ShrOptions::kMaxViewOrder, "", "fixed P, with `order`"),
      int_key("max_order", 0, ShrOptions::kMaxOrder, "60", "cap of F"),
      int_key("max_view_order", 0, ShrOptions::kMaxViewOrder, "8", "cap of P"),
      num_key("energy_eps", 0.0, 1.0, true, "0.03", "smallest (F, P) capturing 1 − eps of the energy"),
      int_key("theta_i_nodes", 0, ShrOptions::kMaxNodes, "0 = auto", "quadrature"),
      int_key("theta_o_nodes", 0, ShrOptions::kMaxNodes, "0 = auto", "quadrature"),
      int_key("phi_nodes", 0, ShrOptions::kMaxNodes, "0 = auto", "quadrature"),
      num_key("min_cos", 0.0, 1.0, true, "0.01", "as for sh-k"),
      other_key("tolerance", "table", "",
                "orders by a metric target instead of the energy (contradicts fixed orders and `energy_eps`)"),
      bool_key("shrm", "false",
               "also the spherical-harmonic reflection map under the scene's SH lighting (needs `[scene] "
               "environment` or `lighting_order`): `runs/<id>/shrm.json`, and `shrm` in run.json with its orders, "
               "`storage_floats`, seconds and `shade_rmse`")};
  return keys;
}

const KeySpec& key(const std::string& name) { return find_key(shr_keys(), name); }

void record_options(const ShrOptions& s, json& o) {
  o["max_order"] = s.max_order;
  o["max_view_order"] = s.max_view_order;
  o["order"] = s.order;
  o["view_order"] = s.view_order;
  o["energy_eps"] = s.energy_eps;
  o["theta_i_nodes"] = s.theta_i_nodes;
  o["theta_o_nodes"] = s.theta_o_nodes;
  o["phi_nodes"] = s.phi_nodes;
  o["min_cos"] = s.min_cos;
}

class ShrKind final : public MethodKind {
 public:
  std::string name() const override { return "sh-r"; }
  std::string summary() const override {
    return "Ramamoorthi–Hanrahan: isotropic BRDFs as coefficients ρ_lpq about the reflection vector (an "
           "anisotropic BRDF is an error: use sh-k). Under SH scene lighting the lighting's band limit caps "
           "`max_order` and `order`.";
  }
  std::vector<KeySpec> keys() const override { return shr_keys(); }
  std::string example() const override { return "order = 2\nview_order = 1\nmax_order = 4\nmax_view_order = 2\n"; }
  std::vector<std::string> described() const override { return {"order", "view_order"}; }
  std::vector<std::string> columns() const override { return {"order", "view_order"}; }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t) const override {
    ShrOptions& s = shr_options(m).shr;
    m.tolerance = read_tolerance(r, o);
    const bool has_order = r.has("order"), has_view = r.has("view_order");
    s.max_order = static_cast<int>(r.integer(key("max_order"), s.max_order));
    s.max_view_order = static_cast<int>(r.integer(key("max_view_order"), s.max_view_order));
    s.order = static_cast<int>(r.integer(key("order"), -1));
    s.view_order = static_cast<int>(r.integer(key("view_order"), -1));
    if (has_order != has_view)
      r.fail(has_order ? "order" : "view_order",
             "fixed orders need both order and view_order (or neither: orders chosen by energy_eps or tolerance)");
    if ((has_order || has_view) && m.tolerance)
      r.fail("tolerance", "tolerance chooses the orders: remove order/view_order (the caps are max_order, max_view_order)");
    if (has_order && s.order > s.max_order)
      r.fail("order", "order " + std::to_string(s.order) + " exceeds max_order " + std::to_string(s.max_order));
    if (has_view && s.view_order > s.max_view_order)
      r.fail("view_order", "view_order " + std::to_string(s.view_order) + " exceeds max_view_order " +
                               std::to_string(s.max_view_order));
    if (r.has("energy_eps") && (has_order || m.tolerance))
      r.fail("energy_eps", "energy_eps chooses the orders; it contradicts fixed orders or a tolerance");
    s.energy_eps = r.number(key("energy_eps"), s.energy_eps);
    s.theta_i_nodes = static_cast<int>(r.integer(key("theta_i_nodes"), 0));
    s.theta_o_nodes = static_cast<int>(r.integer(key("theta_o_nodes"), 0));
    s.phi_nodes = static_cast<int>(r.integer(key("phi_nodes"), 0));
    s.min_cos = r.number(key("min_cos"), s.min_cos);
    bool& shrm = shr_options(m).shrm;
    shrm = r.boolean(key("shrm"), false);
    if (shrm) o["shrm"] = true;  // absent when false: existing run ids unchanged
    record_options(s, o);
    if (m.tolerance) m.cap = s.max_order;
    m.cores = hardware_threads();
    if (!r.failed()) {
      try {
        s.validate();
      } catch (const std::exception& e) {
        report_invalid(r, e, method_keys(*this));
      }
    }
  }

  // SHRM needs SH lighting; its band limit L caps the orders (notes §2.2),
  // recorded in the options (so in run ids) as lighting_cap. sh-r needs
  // isotropic BRDFs.
  void check_plan(const Plan& plan, MethodVariant& m, Ctx& ctx) const override {
    for (const auto& b : plan.brdfs)
      if (!b.brdf->isotropic())
        ctx.issue(m.where, "method.kind", "sh-r needs an isotropic BRDF, but brdf '" + b.label +
                                              "' is anisotropic (use sh-k)");
    if (shr_options(m).shrm && !plan.scene.lighting)
      ctx.issue(m.where, "method.shrm",
                "shrm = true needs SH lighting: set [scene] environment = \"<lat-long map>\" or lighting_order");
    if (!plan.scene.lighting) return;
    const int L = plan.scene.lighting->order;
    json& o = m.options;
    o["lighting_cap"] = L;
    ShrOptions& s = shr_options(m).shr;
    s.max_order = std::min(s.max_order, L);
    if (s.order > L) s.order = L;
    if (m.tolerance) m.cap = std::min(m.cap, L);
    o["max_order"] = s.max_order;
    o["order"] = s.order;
  }

  bool tabulates() const override { return true; }
  void export_files(const RunContext& c, const MethodOutcome& out) const override { export_tabulated(c, out); }
  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    MethodOutcome out;
    if (m.tolerance) {
      out.choice = select_shr_orders_by_metric(*c.brdf.brdf, c.samples, shr_options(m).shr, *m.tolerance);
      out.result = out.choice->result;
    } else {
      out.result = fit_shr(*c.brdf.brdf, shr_options(m).shr);
    }
    return out;
  }

  void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const override {
    const auto shr = std::dynamic_pointer_cast<const ShrFactorization>(out.result);
    row["order"] = std::to_string(shr->order());
    row["view_order"] = std::to_string(shr->view_order());
    add_resampling_note(c, out);
  }

  // The SHRM under the scene's SH lighting: its storage, time and shade_rmse
  // against the original's render (same scene).
  void extra_outputs(const RunContext& c, MethodOutcome& out, Row&) const override {
    if (!shr_options(c.method).shrm || !c.plan.scene.lighting) return;
    const auto shr = std::dynamic_pointer_cast<const ShrFactorization>(out.result);
    const auto t1 = std::chrono::steady_clock::now();
    const Shrm shrm(*shr, *c.plan.scene.lighting);
    json sj = {{"order", shrm.order()}, {"view_order", shrm.view_order()},
               {"storage_floats", shrm.storage_floats()}, {"seconds", shrm.seconds()}};
    if (c.plan.experiment.export_factors)
      write_file_atomic((c.run_dir / "shrm.json").string(),
                        [&](std::ostream& o) { o << shrm.to_json().dump(1) << "\n"; });
    const SphereRender sr = render_sphere_radiance(
        [&](const Vec3& n, const Vec3& v) { return shrm.shade(n, v); }, c.plan.scene.size);
    const double e = shade_rmse(*c.original(), sr);
    sj["shade_rmse"] = std::isfinite(e) ? json(e) : json();
    sj["render_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    out.record["shrm"] = sj;
    out.notes.push_back("shrm F_B " + std::to_string(shrm.order()) + ", P_B " + std::to_string(shrm.view_order()) +
                        ": " + std::to_string(shrm.storage_floats()) + " floats, shade_rmse " + format_number(e));
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_shr_kind() { return std::make_shared<ShrKind>(); }

}  // namespace bf
