// k-fold splits (see folds.h).
#include "experiments/run/folds.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "experiments/report/outputs.h"
#include "experiments/common/splitmix.h"
#include "experiments/report/holdout_partition.h"

namespace bf {

std::vector<HoldoutSplit> split_folds(const SampleSet& s, int k, uint64_t seed) {
  std::vector<size_t> valid;
  for (size_t i = 0; i < s.size(); ++i)
    if (s.valid[i]) valid.push_back(i);
  const size_t n = valid.size();
  if (k < 2)
    throw std::invalid_argument("experiment.folds: expected a number of folds >= 2 (0 = off), found " +
                                std::to_string(k));
  if (static_cast<size_t>(k) > n)
    throw std::invalid_argument("experiment.folds: expected at most the " + std::to_string(n) +
                                " valid samples (each fold holds one at least), found " + std::to_string(k));
  const size_t largest = (n + static_cast<size_t>(k) - 1) / static_cast<size_t>(k);
  if (n - largest < 2)
    throw std::invalid_argument("experiment.folds: " + std::to_string(n) + " valid samples in " +
                                std::to_string(k) + " folds leave " + std::to_string(n - largest) +
                                " to fit without a fold; expected at least 2");
  // Full Fisher-Yates; position i of the order goes to fold i mod k.
  uint64_t state = seed;
  for (size_t i = 0; i + 1 < n; ++i) {
    const size_t j = i + static_cast<size_t>(splitmix(state) % (n - i));
    std::swap(valid[i], valid[j]);
  }
  std::vector<int> fold_of(s.size(), -1);
  for (size_t i = 0; i < n; ++i) fold_of[valid[i]] = static_cast<int>(i % static_cast<size_t>(k));
  std::vector<HoldoutSplit> out(static_cast<size_t>(k));
  for (int f = 0; f < k; ++f) {
    std::vector<uint8_t> held(s.size(), 0);
    for (size_t i = 0; i < s.size(); ++i) held[i] = fold_of[i] == f;
    HoldoutSplit& h = out[static_cast<size_t>(f)];
    h = partition_held(s, held);
    const std::string name = "fold " + std::to_string(f + 1) + " of " + std::to_string(k);
    h.train.description = s.description + " without " + name + " (" + std::to_string(h.held.size()) + " samples)";
    h.held.description = name + " of " + s.description;
  }
  return out;
}

FoldSummary summarize_folds(const std::vector<Metrics>& per_fold) {
  FoldSummary s;
  s.per_fold = per_fold;
  s.folds = static_cast<int>(per_fold.size());
  if (per_fold.empty()) return s;
  s.rel_mse_min = s.rel_mse_max = per_fold[0].rel_mse;
  for (const Metrics& m : per_fold) {
    s.rel_mse_mean += m.rel_mse / s.folds;
    s.cos_rmse_mean += m.cos_rmse / s.folds;
    s.rel_mse_min = std::min(s.rel_mse_min, m.rel_mse);
    s.rel_mse_max = std::max(s.rel_mse_max, m.rel_mse);
  }
  if (s.folds > 1) {
    double ss = 0;
    for (const Metrics& m : per_fold) ss += (m.rel_mse - s.rel_mse_mean) * (m.rel_mse - s.rel_mse_mean);
    s.rel_mse_sd = std::sqrt(ss / (s.folds - 1));
  }
  return s;
}

std::string FoldSummary::spread() const {
  return "rel_mse sd " + format_short(format_number(rel_mse_sd)) + ", range " +
         format_short(format_number(rel_mse_min)) + "-" + format_short(format_number(rel_mse_max)) + " over " +
         std::to_string(folds) + " folds";
}

}  // namespace bf
