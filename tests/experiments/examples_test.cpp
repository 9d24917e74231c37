// Every example config under experiments/ validates at full size and runs at
// reduced size (through -D overrides, as a user would shrink it).
#include "experiments/config/config.h"
#include "experiments/report/outputs.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

const std::vector<std::string> kExamples = {
    "quickstart",      "thesis-bluepaint", "thesis-cook-torrance", "thesis-setup",
    "thesis-measured", "parameterizations", "baselines",          "bench-fit",
    "bench-search",    "bench-baselines", "refine",   "compare-storage",
    "sh-lighting",     "thesis-nongreedy", "thesis-bluepaint-mccool", "refine-blend", "thesis-retro", "thesis-ratio",
    "cornell-validation", "shade-tolerance", "cornell-baselines", "validation-convergence",
    "search-criterion-measured", "search-criterion-grid"};

// Runs experiments/<name>.toml with the overrides; every run must succeed.
void run_example(const std::string& name, const std::vector<std::string>& defines, size_t expected_runs) {
  ScratchDir tmp;
  const std::string cfg = source_path("experiments/" + name + ".toml");
  const RunSummary s = run_quiet(cfg, tmp / "out", defines);
  CHECK(s.planned == expected_runs);
  CHECK(s.executed == expected_runs);
  CHECK(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == expected_runs);
  for (const auto& r : rows) {
    INFO(name << " " << r.at("run_id") << " " << r.at("notes"));
    CHECK(r.at("status") == "ok");
    CHECK(!r.at("rel_mse").empty());
    CHECK(!r.at("cos_rmse").empty());
  }
}

}  // namespace

TEST_CASE("examples: every example config validates at full size") {
  register_loaders();
  for (const auto& name : kExamples) {
    INFO(name);
    const Plan p = load_plan(source_path("experiments/" + name + ".toml"));
    CHECK(!p.runs.empty());
    CHECK(p.experiment.name == name);
    CHECK(p.experiment.out == "results/" + name);
    // Documented: the file starts with a comment saying what it is.
    CHECK(p.config_text.rfind("# ", 0) == 0);
  }
}

TEST_CASE("examples: quickstart at reduced size") {
  run_example("quickstart",
              {"sampling.resolution=6", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1"},
              3);
}

TEST_CASE("examples: thesis-bluepaint at reduced size") {
  run_example("thesis-bluepaint",
              {"sampling.resolution=6", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1", "method.terms=2", "method[2].texture_size=8", "method[3].texture_size=8",
               "scene.size=24"},
              7);
}

TEST_CASE("examples: thesis-cook-torrance at reduced size") {
  run_example("thesis-cook-torrance",
              {"sampling.resolution=6", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1", "method.terms=2", "scene.size=24"},
              5);
}

TEST_CASE("examples: validation-convergence at reduced size") {
  run_example("validation-convergence",
              {"sampling.resolution=6", "method.texture_size=6", "method.restarts=1"}, 2);
}

TEST_CASE("examples: thesis-setup at reduced size") {
  run_example("thesis-setup",
              {"sampling.resolution=6", "method.texture_size=6", "method.restarts=1", "method.terms=2"}, 2);
}

// The measured examples run without the orbit expansion at reduced size (its
// 9 fitted samples per measured one add to CI time); the default expansion is
// run by tests/experiments/symmetry_run_test.cpp.
TEST_CASE("examples: thesis-measured at reduced size") {
  run_example("thesis-measured",
              {"method.texture_size=6", "method.restarts=1", "method.terms=2", "scene.size=24",
               "sampling.symmetries=\"off\""},
              15);
}

TEST_CASE("examples: cornell-validation at reduced size") {
  run_example("cornell-validation",
              {"method.texture_size=6", "method.restarts=1", "method.terms=2", "brdf.model=[\"krylon-blue\"]",
               "sampling.symmetries=\"off\""},
              4);
}

TEST_CASE("examples: cornell-baselines at reduced size") {
  run_example("cornell-baselines",
              {"method.texture_size=6", "brdf.model=[\"krylon-blue\"]", "experiment.holdout=0.1"}, 4);
}

TEST_CASE("examples: parameterizations at reduced size") {
  run_example("parameterizations",
              {"sampling.resolution=6", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1", "method.terms=2", "scene.size=24"},
              24);
}

TEST_CASE("examples: baselines at reduced size") {
  run_example("baselines",
              {"sampling.count=2000", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1", "method[1].terms=[1, 2]", "method.max_order=12", "method[5].order=8",
               "scene.size=24"},
              33);
}

TEST_CASE("examples: bench-fit at reduced size") {
  run_example("bench-fit",
              {"sampling.resolution=[5, 6]", "method.texture_size=[4, 6]", "method.terms=[1, 4]"}, 16);
}

TEST_CASE("examples: bench-search at reduced size") {
  run_example("bench-search",
              {"sampling.resolution=6", "method.texture_size=6", "method.search_texture_size=0",
               "method.restarts=1", "method.terms=1"},
              5);
}

TEST_CASE("examples: bench-baselines at reduced size") {
  run_example("bench-baselines",
              {"sampling.count=1500", "method.texture_size=6", "method.order=[2, 4]", "method[4].order=[2, 4]",
               "method[4].view_order=[2, 3]", "method.max_order=6", "method.max_view_order=4"},
              10);
}

TEST_CASE("examples: refine at reduced size") {
  run_example("refine",
              {"sampling.resolution=5", "method.texture_size=6", "method.refine_iterations=3", "method.starts=1",
               "method.max_iterations=5"},
              48);
}

TEST_CASE("examples: compare-storage at reduced size") {
  // 3 BRDFs x (mccool 2 sizes + search 1 + 3 svd x 2 ranks + sh-k 2 orders + svd auto + mccool auto) = 39
  run_example("compare-storage",
              {"sampling.count=1500", "method[0].texture_size=[4, 6]", "method[1].texture_size=6",
               "method[1].search_texture_size=0", "method[1].restarts=1", "method[1].terms=2",
               "method[2].texture_size=6", "method[2].terms=[1, 2]", "method[3].texture_size=6",
               "method[3].terms=[1, 2]", "method[4].texture_size=6", "method[4].terms=[1, 2]",
               "method[5].texture_size=6", "method[5].order=[2, 3]", "method[6].texture_ladder=[4, 6]",
               "method[6].terms=3", "method[7].texture_ladder=[4, 6]"},
              39);
}
