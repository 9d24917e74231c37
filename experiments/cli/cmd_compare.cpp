// Subcommand `compare`: scores one BRDF against a reference on the
// whole-domain validation design (experiments/report/validation.h, the set
// behind a run's val_* columns), with the reference's own log transform:
// A = the reference's channel means on that set, eps = --eps. Typical uses:
// an exported factorization (runs/<id>/factors.json) against the analytic
// model its samples came from, and a measured table (a MERL .binary written
// by export-merl) against that model, its binning floor.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "brdfs/catalogue.h"
#include "experiments/cli/commands.h"
#include "experiments/report/validation.h"
#include "factor/metrics.h"

namespace bf {

namespace {

constexpr int kMaxComparePairs = 10'000'000;

}  // namespace

void add_cmd_compare(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare",
      "Score a BRDF (e.g. runs/<id>/factors.json) against a reference on the whole-domain validation set; "
      "prints one JSON line (rel_mse etc. with the reference's log transform)");
  struct Args {
    std::string brdf, reference;
    int pairs = 20000;
    double eps = 1e-5;
    unsigned long long seed = 1;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--brdf", a->brdf, "the BRDF scored: catalogue name[:k=v,...], measured file or factors.json")
      ->required();
  cmd->add_option("--reference", a->reference, "the truth: catalogue name[:k=v,...] or measured file")->required();
  cmd->add_option("--pairs", a->pairs, "direction pairs of the validation design")->capture_default_str();
  cmd->add_option("--seed", a->seed, "seed of the validation design")
      ->check(non_negative_integer())
      ->capture_default_str();
  cmd->add_option("--eps", a->eps, "log transform's eps (relative to the reference's channel mean)")
      ->capture_default_str();
  cmd->callback([a] {
    if (a->pairs < 16 || a->pairs > kMaxComparePairs)
      throw std::invalid_argument("compare: --pairs: expected 16.." + std::to_string(kMaxComparePairs) +
                                  ", found " + std::to_string(a->pairs));
    if (!(a->eps > 0 && a->eps <= 1))
      throw std::invalid_argument("compare: --eps: expected a number in (0, 1], found " + std::to_string(a->eps));
    const Catalogue& cat = Catalogue::global();
    const BrdfPtr f = cat.make(a->brdf, "--brdf");
    const BrdfPtr ref = cat.make(a->reference, "--reference");
    const SampleSet set = validation_set(*ref, a->pairs, a->seed);
    if (set.valid_count() == 0)
      throw std::invalid_argument("compare: --reference " + a->reference +
                                  ": no valid value on the validation set (nothing to compare with)");
    const LogTransform lt = LogTransform::of(set, a->eps);
    const Metrics m = evaluate_metrics(*f, set, lt);
    nlohmann::json out{{"brdf", a->brdf},
                       {"reference", a->reference},
                       {"set", set.description},
                       {"pairs", a->pairs},
                       {"valid", m.samples},
                       {"seed", a->seed},
                       {"eps", a->eps},
                       {"rel_mse", m.rel_mse},
                       {"rel_mae", m.rel_mae},
                       {"rel_max", m.rel_max},
                       {"lin_rmse", m.lin_rmse},
                       {"cos_rmse", m.cos_rmse},
                       {"max_ratio", peak_ratio(*f, set)}};
    std::printf("%s\n", out.dump().c_str());
  });
}

}  // namespace bf
