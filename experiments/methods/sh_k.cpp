// kind = "sh-k": Kautz–Sloan–Snyder, per view texel the SH coefficients of
// f·cos θi up to band limit F (factor/sh_baseline.h); with a tolerance the
// smallest order reaching the target. Under SH scene lighting the lighting's
// band limit caps the order.
#include <algorithm>

#include "experiments/methods/tabulating.h"
#include "factor/lighting.h"
#include "factor/sh_baseline.h"
#include "solvers/parallel.h"

namespace bf {

using nlohmann::json;

namespace {

const std::vector<KeySpec>& shk_keys() {
  static const std::vector<KeySpec> keys = {
      int_key("order", 0, ShkOptions::kMaxOrder, "4; 30 with a tolerance", "band limit F; with a tolerance, the cap"),
      int_key("texture_size", 2, ShkOptions::kMaxTextureSize, "32", "view grid resolution"),
      int_key("theta_nodes", 0, ShkOptions::kMaxThetaNodes, "0 = auto", "quadrature nodes in theta"),
      int_key("phi_nodes", 0, ShkOptions::kMaxPhiNodes, "0 = auto", "quadrature nodes in phi"),
      num_key("rim_inset", 0.0, 0.1, true, "1e-4", "view texels beyond radius 1 − rim_inset are evaluated at that radius"),
      num_key("min_cos", 0.0, 1.0, true, "0.01", "eval divides f·cos by max(cos θi, min_cos)"),
      bool_key("float_textures", "false", "round coefficients to float"),
      other_key("tolerance", "table", "", "the smallest order ≤ `order` reaching the target"),
      bool_key("reduce_isotropic", "true",
               "when the run's isotropy test says isotropic, store only the views of azimuth φv = 0: "
               "`texture_size` radial texels instead of the masked square grid, and rotate the coefficients by "
               "D(R_z(φv)) at evaluation (`storage_floats` counts the reduced table)")};
  return keys;
}

const KeySpec& key(const std::string& name) { return find_key(shk_keys(), name); }

class ShkKind final : public MethodKind {
 public:
  std::string name() const override { return "sh-k"; }
  std::string summary() const override {
    return "Kautz–Sloan–Snyder: per view texel, the SH coefficients of f·cos θi. Order F is a band limit: "
           "l = 0..F, (F+1)² coefficients (Kautz's \"fifth order, 25 coefficients\" is `order = 4`). Score it on "
           "`cos_rmse`. Under SH scene lighting the lighting's band limit caps `order`.";
  }
  std::vector<KeySpec> keys() const override { return shk_keys(); }
  std::string example() const override { return "order = 2\ntexture_size = 6\n"; }
  std::vector<std::string> described() const override { return {"order", "texture_size"}; }
  std::vector<std::string> columns() const override { return {"texture_size", "order"}; }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t) const override {
    ShkOptions& k = kind_options<ShkOptions>(m);
    m.tolerance = read_tolerance(r, o);
    k.order = static_cast<int>(r.integer(key("order"), m.tolerance ? 30 : k.order));
    m.texture_size = static_cast<int>(r.integer(key("texture_size"), k.view_res));
    k.view_res = m.texture_size;
    k.theta_nodes = static_cast<int>(r.integer(key("theta_nodes"), 0));
    k.phi_nodes = static_cast<int>(r.integer(key("phi_nodes"), 0));
    k.rim_inset = r.number(key("rim_inset"), k.rim_inset);
    k.min_cos = r.number(key("min_cos"), k.min_cos);
    k.float_textures = r.boolean(key("float_textures"), k.float_textures);
    // Isotropic BRDFs (azimuthal-invariance test at run time) stored along phi_v = 0 only.
    o["reduce_isotropic"] = r.boolean(key("reduce_isotropic"), true);
    o["order"] = k.order;
    o["texture_size"] = k.view_res;
    o["theta_nodes"] = k.theta_nodes;
    o["phi_nodes"] = k.phi_nodes;
    o["rim_inset"] = k.rim_inset;
    o["min_cos"] = k.min_cos;
    o["float_textures"] = k.float_textures;
    if (m.tolerance) m.cap = k.order;
    m.cores = hardware_threads();
    if (!r.failed()) {
      try {
        k.validate();
      } catch (const std::exception& e) {
        report_invalid(r, e, method_keys(*this));
      }
    }
  }

  // The scene's SH lighting band limit L caps the order (notes §2.2: F_B =
  // min(F_L, F_rho)), recorded in the options (so in run ids) as lighting_cap.
  void check_plan(const Plan& plan, MethodVariant& m, Ctx&) const override {
    if (!plan.scene.lighting) return;
    const int L = plan.scene.lighting->order;
    m.options["lighting_cap"] = L;
    if (m.tolerance) m.cap = std::min(m.cap, L);
    ShkOptions& k = kind_options<ShkOptions>(m);
    k.order = std::min(k.order, L);
    m.options["order"] = k.order;
  }

  bool tabulates() const override { return true; }
  void export_files(const RunContext& c, const MethodOutcome& out) const override { export_tabulated(c, out); }
  // Float64 data + float32 EXR + the viewer's base64 copy: about 18 bytes per value.
  uint64_t export_bytes(const MethodVariant& m) const override {
    const ShkOptions& k = kind_options<ShkOptions>(m);
    const uint64_t res = uint64_t(std::max(k.view_res, 2));
    const uint64_t order = uint64_t(std::max({k.order, m.cap, 0}) + 1);
    return order * order * res * res * 3 * 18;
  }
  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    // An isotropic BRDF (by the azimuthal-invariance test) is stored along phi_v = 0 only.
    ShkOptions ko = kind_options<ShkOptions>(m);
    ko.reduced = m.options.value("reduce_isotropic", false) && c.isotropy.isotropic;
    MethodOutcome out;
    if (m.tolerance) {
      out.choice = select_shk_order(*c.brdf.brdf, c.samples, ko, *m.tolerance, m.cap);
      out.result = out.choice->result;
    } else {
      out.result = fit_shk(*c.brdf.brdf, ko);
    }
    return out;
  }

  void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const override {
    const auto shk = std::dynamic_pointer_cast<const ShkFactorization>(out.result);
    row["texture_size"] = std::to_string(shk->options().view_res);
    row["order"] = std::to_string(shk->order());
    if (shk->negative_fraction > 0)
      out.notes.push_back("ringing: product negative at " +
                          format_short(format_number(100.0 * shk->negative_fraction)) + "% of the quadrature nodes");
    add_resampling_note(c, out);
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_shk_kind() { return std::make_shared<ShkKind>(); }

}  // namespace bf
