// Every registered method kind exports what a renderer needs: its run's
// export reloads through --brdf and scores the run's own metrics, and its
// GLSL compiles for GL 3.3, GL 4.5, GLES 3.0 and Vulkan, and it has viewer
// data for report.html when it says it has (has_viewer). A kind added
// without an export fails here. (Pointwise checks per kind: the reload
// against the in-memory factorization in tests/factor/export_test.cpp,
// baseline_export_test.cpp and model_glsl_test.cpp.)
#include "brdfs/catalogue.h"
#include "experiments/methods/method_kind.h"
#include "experiments_helpers.h"
#include "factor/glsl_compile.h"
#include "factor/metrics.h"

using namespace bf;
using namespace bf_test;

TEST_CASE("export: every kind's export reloads with its run's metrics and its GLSL compiles for four targets") {
  REQUIRE(method_kinds().size() >= 7);
  register_loaders();
  const BrdfPtr truth = Catalogue::builtin().make("bluepaint");
  const SampleSet samples = sample_grid(*truth, 6);
  const LogTransform lt = LogTransform::of(samples, 1e-5);
  for (const auto& kind : method_kinds()) {
    INFO(kind->name());
    ScratchDir tmp;
    const std::string cfg = write_text(tmp / "cfg.toml", R"([experiment]
name = "t"
plots = false

[scene]
size = 16

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = ")" + kind->name() + "\"\n" + kind->example());
    const RunSummary s = run_quiet(cfg, tmp / "out");
    REQUIRE(s.failed == 0);
    const auto rows = read_results_csv(tmp / "out/results.csv");
    REQUIRE(rows.size() == 1);
    const Row& row = rows[0];
    const fs::path run = fs::path(tmp / "out/runs") / row.at("run_id");
    // The loadable export: factors.json (homomorphic, SVD, SH) or model.json (model fits).
    const bool model = fs::exists(run / "model.json");
    const fs::path exported = run / (model ? "model.json" : "factors.json");
    INFO(exported.string());
    REQUIRE(fs::exists(exported));
    const BrdfPtr back = Catalogue::global().make(exported.string());
    const Metrics m = evaluate_metrics(*back, samples, lt);
    for (const char* name : {"rel_mse", "rel_max", "lin_rmse", "lin_max", "cos_rmse"}) {
      const double want = std::stod(row.at(name)), got = metric_value(m, name);
      INFO(name << ": run " << want << ", reloaded export " << got);
      CHECK(std::abs(got - want) <= 1e-6 * std::abs(want));
    }
    // The report's viewer data exists exactly for the kinds that declare a
    // viewer (the preflight counts its bytes by has_viewer()).
    CHECK(fs::exists(run / "viewer.js") == kind->has_viewer());
    const fs::path glsl = run / (model ? "model.glsl" : "factors.glsl");
    REQUIRE(fs::exists(glsl));
    const std::string err = compile_glsl_all_targets(read_text(glsl.string()), tmp.path,
                                                     model ? "" : "#define BRDF_FACTOR_EXACT_BILINEAR\n");
    INFO(err);
    CHECK(err.empty());
  }
}
