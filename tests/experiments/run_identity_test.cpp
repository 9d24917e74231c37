// Run identity (docs/experiments.md "Caching and resuming"): a run id is the
// hash of everything that determines the run's outputs. Every key that changes
// results must change it (or a stale cached run would be reused as the
// answer to another question); keys that only change how or where the work
// is done must not (or every cached run would be redone for nothing).
#include <catch2/catch.hpp>

#include "experiments/config/config.h"
#include "experiments_helpers.h"

using namespace bf_test;
using bf::Plan;

namespace {

// One BRDF, one sampling, one method of each seeded and unseeded kind, with
// every experiment and scene key written out so that -D can change each.
const char* const kIdentityBase = R"([experiment]
name = "ident"
seed = 3
description = "identity"
jobs = 1
plots = false
render = true
export = true
metric_eps = 1e-5
validation_pairs = 256
holdout = 0.1

[scene]
size = 16
intensity = 20.0
light = [2.0, 2.0, 4.0]
shade_rmse = true

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "mccool"
texture_size = 6

[[method]]
kind = "search"
terms = 1
restarts = 1
texture_size = 6
threads = 1
)";

Plan plan_with(const std::vector<std::string>& defines) {
  register_loaders();
  return bf::parse_plan(kIdentityBase, "ident.toml", defines);
}

}  // namespace

TEST_CASE("run identity: every key that changes results changes the run id") {
  const Plan base = plan_with({});
  REQUIRE(base.runs.size() == 2);
  // (define, which runs it must change: -1 = all, else the method index)
  const std::vector<std::pair<std::string, int>> changing = {
      {"experiment.seed=4", -1},              // the validation seed and the default method seed
      {"experiment.metric_eps=1e-4", -1},     // the log transform of every fit and metric
      {"experiment.validation_pairs=128", -1},  // the val_* columns
      {"experiment.validation_pairs=0", -1},
      {"experiment.holdout=0.2", -1},         // the held-out split of raw samples
      {"experiment.holdout=0", -1},
      {"experiment.render=false", -1},        // sphere.png, viewer.js
      {"experiment.export=false", -1},        // the factor files
      {"scene.size=24", -1},                  // shade_rmse
      {"scene.intensity=10.0", -1},
      {"scene.light=[1.0, 2.0, 4.0]", -1},
      {"scene.shade_rmse=false", -1},
      {"sampling.resolution=8", -1},
      {"brdf[0].preset=\"cole-cook-torrance\"", -1},
      {"method[0].texture_size=8", 0},
      {"method[1].terms=2", 1},
      {"method[1].seed=9", 1},
      {"method[1].restarts=2", 1},
      {"method[1].search_samples=5000", 1},  // the search runs on a subsample above it
  };
  for (const auto& [define, which] : changing) {
    INFO("-D " << define);
    const Plan p = plan_with({define});
    REQUIRE(p.runs.size() == base.runs.size());
    for (size_t i = 0; i < p.runs.size(); ++i) {
      INFO("run " << i << " (" << p.methods[p.runs[i].method].kind << ")");
      if (which < 0 || static_cast<size_t>(which) == i) CHECK(p.runs[i].run_id != base.runs[i].run_id);
      else CHECK(p.runs[i].run_id == base.runs[i].run_id);
    }
    // The identity that run.json records says what changed: the ids differ
    // because the identities do.
    if (which < 0) CHECK(p.runs[0].identity != base.runs[0].identity);
  }
}

TEST_CASE("run identity: keys that do not change results keep the run id") {
  const Plan base = plan_with({});
  const std::vector<std::string> neutral = {
      "experiment.name=\"other\"",   "experiment.description=\"another text\"", "experiment.jobs=2",
      "experiment.plots=true",       "experiment.out=\"elsewhere\"",            "method[0].label=\"renamed\"",
      "method[1].label=\"renamed\"", "method[1].threads=2",
  };
  for (const auto& define : neutral) {
    INFO("-D " << define);
    const Plan p = plan_with({define});
    REQUIRE(p.runs.size() == base.runs.size());
    for (size_t i = 0; i < p.runs.size(); ++i) CHECK(p.runs[i].run_id == base.runs[i].run_id);
  }
}
