// kind = "model-fit": an analytic catalogue model fitted to the samples with
// Ceres (multi-start Levenberg–Marquardt; factor/model_fit.h), as one more way
// to compress a BRDF; the fit is written as runs/<id>/model.json, itself a BRDF,
// and its formula with the fitted parameters as runs/<id>/model.glsl.
#include <algorithm>

#include "experiments/common/cli_util.h"
#include "experiments/methods/method_kind.h"
#include "factor/export.h"
#include "factor/model_fit.h"
#include "solvers/option_error.h"
#include "solvers/parallel.h"

namespace bf {

using nlohmann::json;

namespace {

const std::vector<KeySpec>& model_fit_keys() {
  static const std::vector<KeySpec> keys = {
      other_key("model", "string", "`\"cook-torrance\"`",
                "`blinn-phong`, `cook-torrance`, `ward`, `ashikhmin-shirley` or `lafortune`, optionally with fixed "
                "options only: `\"cook-torrance:form=ngan\"`, `\"ward:variant=duer\"`, "
                "`\"lafortune:normalization=ngan\"`, `\"blinn-phong:normalization=ngan\"`, "
                "`\"ashikhmin-shirley:diffuse=lambert\"`"),
      choice_key("metric", {"cosine", "log"}, "cosine",
                 "Ngan et al. 2005's cosine-weighted L2 (= cos_rmse²) or the homomorphic log error (= rel_mse)"),
      bool_key("cube_root", "false", "cosine only: compare cube roots of f·cos θi"),
      bool_key("anisotropic", "false", "ward (ax, ay) and ashikhmin-shirley (nu, nv) only: fit both roughnesses"),
      int_key("lobes", 1, 3, "1", "lafortune only"),
      num_key("eps", 0.0, 1.0, true, "1e-5", "log metric's eps"),
      int_key("starts", 1, 1000, "8",
              "multi-start count: start 0 from documented defaults, the others seeded random"),
      int_key("seed", 0, kIntMax, "`experiment.seed`", "seed of the random starts (the `seed` column)"),
      int_key("max_iterations", 1, 100000, "100", "Levenberg–Marquardt iterations per start"),
      int_key("threads", 0, 1024, "0 = hardware threads", "Ceres threads; not part of the run id")};
  return keys;
}

const KeySpec& key(const std::string& name) { return find_key(model_fit_keys(), name); }

void record_options(const ModelFitOptions& f, json& o) {
  o["model"] = f.model;
  o["metric"] = f.metric;
  o["cube_root"] = f.cube_root;
  o["anisotropic"] = f.anisotropic;
  o["lobes"] = f.lobes;
  o["eps"] = f.eps;
  o["starts"] = f.starts;
  o["seed"] = f.seed;
  o["max_iterations"] = f.max_iterations;
}

class ModelFitKind final : public MethodKind {
 public:
  std::string name() const override { return "model-fit"; }
  std::string summary() const override {
    return "An analytic catalogue model fitted to the samples with Ceres (multi-start Levenberg–Marquardt; "
           "`factor/model_fit.h`): the row is scored on the same samples as every method, `storage_floats` is "
           "the number of fitted parameters, `terms`/`texture_size` are empty, the `model` column holds the "
           "fitted catalogue spec and `runs/<id>/model.json` the fit (format `brdf-factor-model-fit`), itself "
           "a BRDF (`brdf-factor eval --brdf runs/<id>/model.json ...`); `runs/<id>/model.glsl` is the "
           "model's formula with the fitted parameters, `vec3 brdf_factor_eval(vec3 wi, vec3 wo)` for GL 3.3 / "
           "4.5, GLES 3.0 and Vulkan (`factor/model_glsl.h`).";
  }
  std::vector<KeySpec> keys() const override { return model_fit_keys(); }
  bool seeded() const override { return true; }
  std::string example() const override { return "model = \"blinn-phong\"\nstarts = 1\nmax_iterations = 5\nthreads = 1\n"; }
  std::vector<std::string> described() const override {
    return {"model", "metric", "anisotropic", "lobes", "starts", "seed"};
  }
  std::vector<std::string> columns() const override { return {"model"}; }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t base_seed) const override {
    ModelFitOptions& f = kind_options<ModelFitOptions>(m);
    f.model = r.text("model", f.model);
    f.metric = r.choice(key("metric"), f.metric);
    f.cube_root = r.boolean(key("cube_root"), f.cube_root);
    f.anisotropic = r.boolean(key("anisotropic"), f.anisotropic);
    f.lobes = static_cast<int>(r.integer(key("lobes"), f.lobes));
    f.eps = r.number(key("eps"), f.eps);
    f.starts = static_cast<int>(r.integer(key("starts"), f.starts));
    m.seed = static_cast<uint64_t>(r.integer(key("seed"), static_cast<int64_t>(base_seed)));
    f.seed = m.seed;
    f.max_iterations = static_cast<int>(r.integer(key("max_iterations"), f.max_iterations));
    f.threads = static_cast<int>(r.integer(key("threads"), 0));
    record_options(f, o);
    m.execution["threads"] = f.threads;
    m.cores = std::max(1, hardware_threads(f.threads));
    if (r.failed()) return;
    try {
      m.terms = static_cast<int>(check_model_fit(f));
    } catch (const OptionError& e) {
      std::vector<std::string> names;
      for (const auto& k : model_fit_keys()) names.push_back(k.name);
      report_invalid(r, e, names);
    } catch (const std::exception& e) {
      r.fail("model", e.what());  // the model spec's own options (ParamDict)
    }
  }

  MethodOutcome run(const RunContext& c) const override {
    MethodOutcome out;
    auto mf = std::make_shared<ModelFitFactorization>(fit_model(c.samples, kind_options<ModelFitOptions>(c.method)));
    const ModelFitResult& res = mf->result();
    json params = json::object();
    for (const auto& [k, v] : res.parameters) params[k] = v;
    out.record["model_fit"] = {{"spec", res.spec}, {"parameters", params}, {"cost", res.cost},
                               {"best_start", res.best_start}, {"start_costs", res.start_costs},
                               {"iterations", res.iterations}};
    out.evaluations = res.iterations;
    out.result = mf;
    return out;
  }

  void fill_row(const RunContext&, MethodOutcome& out, Row& row) const override {
    row["model"] = std::dynamic_pointer_cast<const ModelFitFactorization>(out.result)->result().spec;
  }

  void export_files(const RunContext& c, const MethodOutcome& out) const override {
    write_export(*out.result, c.run_dir.string(), "model", "run " + c.run.run_id);
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_model_fit_kind() { return std::make_shared<ModelFitKind>(); }

}  // namespace bf
