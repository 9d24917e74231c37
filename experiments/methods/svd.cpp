// kind = "svd": Kautz–McCool, the BRDF tabulated on a parabolic grid of
// (wi, wo) or (h, d) and truncated to rank K per channel
// (factor/svd_baseline.h); with a tolerance the smallest rank (and with
// texture_size = "auto" the resolution) reaching the target.
#include <algorithm>

#include "experiments/methods/tabulating.h"
#include "factor/svd_baseline.h"
#include "solvers/parallel.h"

namespace bf {

using nlohmann::json;

namespace {

constexpr int kTextureMin = 2, kTextureMax = 256;

const std::vector<KeySpec>& svd_keys() {
  static const std::vector<KeySpec> keys = {
      other_key("texture_size", "integer 2..256 or `\"auto\"`", "32",
                "grid resolution for rows and columns; `\"auto\"`: chosen by the tolerance from `texture_ladder`"),
      int_key("terms", 1, 100000, "1; 16 with a tolerance", "rank K; with a tolerance, the cap"),
      choice_key("parameterization", {"wiwo", "halfdiff"}, "wiwo", ""),
      bool_key("log", "false", "decompose McCool's log transform instead of f"),
      num_key("eps", 0.0, 1.0, true, "1e-5", "log mode only (an error without `log = true`)"),
      bool_key("subtract_eps", "false", "log mode only"),
      num_key("rim_inset", 0.0, 0.5, false, "0",
              "texels beyond radius 1 − rim_inset are evaluated at that radius; 0 = half a texel, "
              "1/(texture_size − 1) (a tiny inset tabulates grazing values ~1e7 of Cook–Torrance that wreck the "
              "linear SVD)"),
      bool_key("extend_below_horizon", "true", "halfdiff: fill texel pairs below the horizon by the lifted extension (else 0)"),
      bool_key("float_textures", "false", "round factors to float (what an EXR holds)"),
      other_key("tolerance", "table", "", "the smallest rank ≤ `terms` reaching the target"),
      other_key("texture_ladder", "list of integers", "[8, 12, 16, 24, 32]",
                "the resolutions `texture_size = \"auto\"` tries, ascending")};
  return keys;
}

const KeySpec& key(const std::string& name) { return find_key(svd_keys(), name); }

void record_options(const SvdOptions& v, json& o) {
  o["terms"] = v.rank;
  o["parameterization"] = to_string(v.param);
  o["log"] = v.log;
  o["eps"] = v.eps;
  o["subtract_eps"] = v.subtract_eps;
  o["rim_inset"] = v.rim_inset;
  o["extend_below_horizon"] = v.extend_below_horizon;
  o["float_textures"] = v.float_textures;
}

class SvdKind final : public MethodKind {
 public:
  std::string name() const override { return "svd"; }
  std::string summary() const override {
    return "Kautz–McCool: the BRDF tabulated on a parabolic grid of (wi, wo) or (h, d), truncated to rank K per "
           "channel (`factor/svd_baseline.h`).";
  }
  std::vector<KeySpec> keys() const override { return svd_keys(); }
  std::string example() const override { return "terms = 2\ntexture_size = 6\n"; }
  std::vector<std::string> described() const override { return {"terms", "texture_size", "parameterization", "log"}; }
  std::vector<std::string> columns() const override {
    return {"parameterization", "terms", "texture_size", "negative_texels", "errors_after_term"};
  }
  bool array_is_value(const std::string& key, const toml::array& a) const override {
    return key == "texture_ladder" && !all_arrays(a);
  }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t) const override {
    SvdOptions& v = kind_options<SvdOptions>(m);
    m.texture_size = read_texture_size(r, m, o, v.res, kTextureMin, kTextureMax);
    m.tolerance = read_tolerance(r, o);
    m.terms = static_cast<int>(r.integer(key("terms"), m.tolerance ? 16 : v.rank));
    v.param = read_param(r, "parameterization", v.param);
    v.log = r.boolean(key("log"), v.log);
    if (!v.log)
      for (const char* k : {"eps", "subtract_eps"})
        if (r.has(k)) {
          r.fail(k, std::string(k) + " applies only to the log-space SVD: set log = true or remove " + k);
          r.take(k);
        }
    v.eps = r.number(key("eps"), v.eps);
    v.subtract_eps = r.boolean(key("subtract_eps"), v.subtract_eps);
    v.rim_inset = r.number(key("rim_inset"), v.rim_inset);  // 0: half a texel (SvdOptions)
    v.extend_below_horizon = r.boolean(key("extend_below_horizon"), v.extend_below_horizon);
    v.float_textures = r.boolean(key("float_textures"), v.float_textures);
    v.res = m.texture_size;
    v.rank = m.terms;
    record_options(v, o);
    if (m.tolerance) m.cap = m.terms;
    m.cores = hardware_threads();
    if (!r.failed()) {
      try {
        v.validate();
      } catch (const std::exception& e) {
        report_invalid(r, e, method_keys(*this));
      }
    }
  }

  bool tabulates() const override { return true; }
  // rel_mse of the rank-k truncations on the samples, when given.
  void report_call(const RunContext& c, const MethodOutcome& out, bool samples_given,
                   std::vector<double>& errors_after_term, json& info) const override {
    (void)info;
    const auto svd = std::dynamic_pointer_cast<const SvdFactorization>(out.result);
    if (!svd || !samples_given) return;
    for (int k = 1; k <= svd->rank(); ++k)
      errors_after_term.push_back(evaluate_metrics(*svd->truncated(k), c.samples, c.lt).rel_mse);
  }
  void export_files(const RunContext& c, const MethodOutcome& out) const override { export_tabulated(c, out); }
  // Float64 data + float32 EXR + the viewer's base64 copy: about 18 bytes per value.
  uint64_t export_bytes(const MethodVariant& m) const override {
    const SvdOptions& v = kind_options<SvdOptions>(m);
    const uint64_t res = uint64_t(std::max(v.res, 2));
    return uint64_t(std::max({v.rank, m.terms, m.cap, 1})) * 2 * res * res * 3 * 18;
  }
  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    const SvdOptions& v = kind_options<SvdOptions>(m);
    MethodOutcome out;
    if (m.tolerance && !m.texture_ladder.empty())
      out.choice = select_svd_size(*c.brdf.brdf, c.samples, v, *m.tolerance, m.cap, m.texture_ladder);
    else if (m.tolerance)
      out.choice = select_svd_rank(*c.brdf.brdf, c.samples, v, *m.tolerance, m.cap);
    else
      out.result = fit_svd(*c.brdf.brdf, v);
    if (out.choice) out.result = out.choice->result;
    return out;
  }

  void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const override {
    const auto svd = std::dynamic_pointer_cast<const SvdFactorization>(out.result);
    row["parameterization"] = to_string(svd->options().param);
    row["terms"] = std::to_string(svd->rank());
    row["texture_size"] = std::to_string(svd->options().res);
    row["negative_texels"] = std::to_string(svd->negative_texels());
    std::vector<std::string> ec;
    for (int k = 1; k <= svd->rank(); ++k)
      ec.push_back(format_number(evaluate_metrics(*svd->truncated(k), c.samples, c.lt).rel_mse));
    row["errors_after_term"] = join(ec, ";");
    add_resampling_note(c, out);
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_svd_kind() { return std::make_shared<SvdKind>(); }

}  // namespace bf
