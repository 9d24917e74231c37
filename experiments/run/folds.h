// k-fold cross-validation of runs on raw samples (docs/design.md §4.1
// "k-fold"): `[experiment] folds = k` fits each method k times, each time
// without one fold, scores the held-out fold, and reports the mean (and the
// spread) over the folds in the holdout_* columns; the run's own fit, the one
// scored, rendered and exported, uses every sample.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "brdfs/sampleset.h"
#include "experiments/report/validation.h"
#include "factor/metrics.h"

namespace bf {

// The k folds of s: its valid samples in a seeded Fisher-Yates order
// (SplitMix64, the same on every platform), the sample at position i of that
// order in fold i mod k, so fold sizes differ by at most one. Fold f's `held`
// is its samples (in s's order), its `train` every other sample of s
// (masked samples included, never held out). Weights follow their samples.
// Throws std::invalid_argument naming experiment.folds when k < 2, k exceeds
// the valid samples, or a fold would leave fewer than 2 to train on.
std::vector<HoldoutSplit> split_folds(const SampleSet& s, int k, uint64_t seed);

// The mean, the sample standard deviation and the range of the folds'
// held-out rel_mse, and the mean of their cos_rmse (the holdout_* columns).
struct FoldSummary {
  int folds = 0;
  double rel_mse_mean = 0, rel_mse_sd = 0, rel_mse_min = 0, rel_mse_max = 0;
  double cos_rmse_mean = 0;
  std::vector<Metrics> per_fold;
  // "rel_mse sd 0.05, range 0.61-0.78 over 5 folds"
  std::string spread() const;
  // The means as Metrics (rel_mse, cos_rmse; the rest 0).
  Metrics mean() const {
    Metrics m;
    m.rel_mse = rel_mse_mean;
    m.cos_rmse = cos_rmse_mean;
    return m;
  }
};
FoldSummary summarize_folds(const std::vector<Metrics>& per_fold);


}  // namespace bf
