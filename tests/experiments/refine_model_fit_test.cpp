// The refinement stage and the model-fit kind in experiment configs and the
// runner (issue #9): accepted and refused keys, the before/after columns, the
// refined export, the model-fit row and its file's round trip.
#include <cmath>
#include <nlohmann/json.hpp>

#include "experiments/config/config.h"
#include "experiments/methods/homomorphic.h"
#include "experiments/report/outputs.h"
#include "factor/metrics.h"
#include "factor/model_fit.h"
#include "factor/model_glsl.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

const char* const kRefineBase = kConfigHead;

// Exactly one message for the head plus `text`, containing every fragment.
void require_one(const std::string& text, std::initializer_list<std::string> fragments) {
  require_one_config_error(std::string(kRefineBase) + text, fragments);
}

double row_num(const Row& r, const std::string& k) {
  INFO(k << " = '" << r.at(k) << "'");
  REQUIRE(!r.at(k).empty());
  return std::stod(r.at(k));
}

}  // namespace

TEST_CASE("config: refine values and keys of the homomorphic kinds") {
  register_loaders();
  const Plan p = parse_plan(std::string(kRefineBase) + R"(
[[method]]
kind = "mccool"
refine = ["none", "linear", "cosine", "blend"]
refine_blend = 0.1
refine_iterations = 7
[[method]]
kind = "fit"
projections = [{ name = "h", parameterization = "halfdiff" }, { name = "d", parameterization = "halfdiff" }]
refine = "blend"
[[method]]
kind = "search"
restarts = 1
refine = "linear"
refine_smoothing = 0.5
)", "cfg.toml");
  REQUIRE(p.methods.size() == 6);
  CHECK(p.methods[0].refine == "none");
  CHECK(p.methods[1].refine == "linear");
  CHECK(homomorphic_options(p.methods[1]).refine.objective == "linear");
  CHECK(homomorphic_options(p.methods[1]).refine.max_iterations == 7);
  CHECK(homomorphic_options(p.methods[2]).refine.objective == "cosine");
  CHECK(homomorphic_options(p.methods[3]).refine.blend_weight == 0.1);
  // Refine keys are hashed only when a refinement runs; blend's weight only for blend.
  CHECK(!p.methods[0].options.contains("refine_blend"));
  CHECK(!p.methods[0].options.contains("refine_iterations"));
  CHECK(!p.methods[1].options.contains("refine_blend"));
  CHECK(p.methods[3].options.at("refine_blend") == 0.1);
  // Smoothing defaults to the fit's own.
  CHECK(homomorphic_options(p.methods[1]).refine.smoothing == homomorphic_options(p.methods[1]).fit.smoothing);
  CHECK(p.methods[4].refine == "blend");
  CHECK(homomorphic_options(p.methods[4]).refine.blend_weight == RefineOptions{}.blend_weight);
  CHECK(homomorphic_options(p.methods[5]).refine.smoothing == 0.5);
  // Every variant is its own run; a refine = "none" run's id does not depend on refine keys.
  CHECK(p.runs.size() == 6);
  const Plan q = parse_plan(std::string(kRefineBase) + "[[method]]\nkind = \"mccool\"\n", "cfg.toml");
  CHECK(q.runs[0].run_id == p.runs[0].run_id);
}

TEST_CASE("config: bad refine and model-fit settings name the field") {
  require_one("[[method]]\nkind = \"mccool\"\nrefine = \"quadratic\"\n",
              {"cfg.toml:12: method[0].refine:", "expected one of", "\"quadratic\""});
  require_one("[[method]]\nkind = \"mccool\"\nrefine = \"blend\"\nrefine_blend = -1\n",
              {"cfg.toml:13: method[0].refine_blend:", "expected a number", "-1"});
  require_one("[[method]]\nkind = \"fit\"\nprojections = [{ name = \"wi\" }]\nrefine = \"linear\"\nrefine_iterations = 0\n",
              {"method[0].refine_iterations:", "expected an integer", "0"});
  require_one("[[method]]\nkind = \"sh-k\"\nrefine = \"blend\"\n",
              {"cfg.toml:12: method[0].refine:", "homomorphic kinds", "sh-k"});
  require_one("[[method]]\nkind = \"model-fit\"\nrefine = \"linear\"\n",
              {"method[0].refine:", "homomorphic kinds", "model-fit"});
  require_one("[[method]]\nkind = \"svd\"\nrefine_blend = 0.1\n",
              {"method[0].refine_blend:", "does not apply", "mccool"});
  require_one("[[method]]\nkind = \"model-fit\"\nmodel = \"phong\"\n",
              {"cfg.toml:12: method[0].model:", "'phong'"});
  require_one("[[method]]\nkind = \"model-fit\"\nmodel = \"ward\"\nlobes = 2\n",
              {"method[0].lobes:", "lafortune"});
  require_one("[[method]]\nkind = \"model-fit\"\nmodel = \"cook-torrance\"\nanisotropic = true\n",
              {"method[0].anisotropic:", "cook-torrance"});
  require_one("[[method]]\nkind = \"model-fit\"\nmetric = \"log\"\ncube_root = true\n",
              {"method[0].cube_root:", "metric = \"cosine\""});
  require_one("[[method]]\nkind = \"model-fit\"\nmetric = \"l1\"\n", {"method[0].metric:", "\"l1\""});
  require_one("[[method]]\nkind = \"model-fit\"\nstarts = 0\n", {"method[0].starts:", "1..1000"});
  require_one("[[method]]\nkind = \"model-fit\"\ntexture_size = 8\n",
              {"method[0].texture_size:", "does not apply to kind = \"model-fit\""});
}

TEST_CASE("runner: a refined row reports the fit before and after and the export is the refined one") {
  // The linear objective without smoothing minimizes lin_rmse (unclamped;
  // the clamp only lowers it) from the log fit: it cannot end higher, and on
  // this grid it ends far lower.
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "r.toml", R"([experiment]
name = "r"
render = false
plots = false
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[[method]]
kind = "mccool"
texture_size = 6
refine = ["none", "linear"]
refine_smoothing = 0
refine_iterations = 20
)");
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.failed == 0);
  const std::vector<Row> rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 2);
  const Row& none = rows[0].at("refine").empty() ? rows[0] : rows[1];
  const Row& lin = rows[0].at("refine").empty() ? rows[1] : rows[0];
  REQUIRE(lin.at("refine") == "linear");
  INFO("none: lin_rmse " << none.at("lin_rmse") << "; linear: " << lin.at("lin_rmse_before") << " -> "
                         << lin.at("lin_rmse"));
  // The *_before columns are the unrefined run's metrics.
  for (const char* k : {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse"})
    CHECK(row_num(lin, std::string(k) + "_before") == Approx(row_num(none, k)).epsilon(1e-6));
  CHECK(row_num(lin, "lin_rmse") < 0.9 * row_num(lin, "lin_rmse_before"));
  CHECK(row_num(lin, "refine_seconds") > 0);
  CHECK(row_num(lin, "seconds") >= row_num(lin, "refine_seconds"));
  CHECK(none.at("rel_mse_before").empty());

  // The exported factors are the refined ones: reloading gives the refined metrics.
  const std::string sidecar = tmp / ("out/runs/" + lin.at("run_id") + "/factors.json");
  const auto back = load_factorization(sidecar);
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet smp = sample_grid(*b, 6);
  const Metrics m = evaluate_metrics(*back, smp, LogTransform::of(smp, 1e-5));
  CHECK(m.lin_rmse == Approx(row_num(lin, "lin_rmse")).epsilon(1e-6));
  CHECK(m.rel_mse == Approx(row_num(lin, "rel_mse")).epsilon(1e-6));
  const nlohmann::json rec = nlohmann::json::parse(read_text(tmp / ("out/runs/" + lin.at("run_id") + "/run.json")));
  CHECK(rec.at("refinement").at("objective") == "linear");
  CHECK(rec.at("refinement").at("final_cost").get<double>() < rec.at("refinement").at("initial_cost").get<double>());
}

TEST_CASE("runner: a model-fit row, and its model.json loads back through --brdf") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "m.toml", R"([experiment]
name = "m"
render = false
plots = false
[[brdf]]
model = "ward"
kd = 0.2
ks = 0.25
ax = 0.2
ay = 0.2
[sampling]
kind = "grid"
resolution = 6
[[method]]
kind = "model-fit"
model = "ward"
metric = ["cosine", "log"]
starts = 2
)");
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.failed == 0);
  const std::vector<Row> rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 2);
  for (const Row& r : rows) {
    INFO(r.at("model"));
    CHECK(r.at("method") == "model-fit");
    CHECK(r.at("storage_floats") == "7");  // kd, ks (RGB) and a
    CHECK(row_num(r, "rel_mse") < 1e-12);      // the model's own data: recovered exactly
    CHECK(r.at("model").rfind("ward:", 0) == 0);
    const std::string file = tmp / ("out/runs/" + r.at("run_id") + "/model.json");
    REQUIRE(fs::exists(file));
    // The catalogue loads it back (the .json loader dispatches on the format).
    const BrdfPtr back = Catalogue::global().make(file);
    const BrdfPtr truth = Catalogue::builtin().make("ward:kd=0.2,ks=0.25,ax=0.2,ay=0.2");
    const Vec3 wi = Vec3(0.3, 0.1, 0.9).normalized(), wo = Vec3(-0.2, 0.05, 0.95).normalized();
    CHECK((back->eval(wi, wo) - truth->eval(wi, wo)).abs().maxCoeff() < 1e-6 * truth->eval(wi, wo).maxCoeff());
    // model.glsl beside it: the fitted model's formula (factor/model_glsl.h;
    // compiled and run against eval in tests/factor/model_glsl_test.cpp).
    CHECK(read_text(tmp / ("out/runs/" + r.at("run_id") + "/model.glsl")) ==
          generate_model_glsl(*back, "run " + r.at("run_id")));
    std::string out;
    CHECK(run_cli("eval --brdf " + file + " --wi 0,0,1 --wo 0.5,0,0.866", &out) == 0);
    INFO(out);
    CHECK(out.find("brdf-factor:") == std::string::npos);
  }
}
