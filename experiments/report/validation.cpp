// Validation sets, held-out samples and flags (see validation.h).
#include "experiments/report/validation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "experiments/common/splitmix.h"
#include "experiments/report/holdout_partition.h"

namespace bf {

HoldoutSplit partition_held(const SampleSet& s, const std::vector<uint8_t>& held) {
  HoldoutSplit out;
  const bool weighted = !s.weight.empty();
  for (size_t k = 0; k < s.size(); ++k) {
    SampleSet& dst = held[k] ? out.held : out.train;
    dst.wi.push_back(s.wi[k]);
    dst.wo.push_back(s.wo[k]);
    dst.value.push_back(s.value[k]);
    dst.valid.push_back(s.valid[k]);
    if (weighted) dst.weight.push_back(s.weight[k]);
  }
  out.train.invalid_value = s.invalid_value;
  out.train.invalid_horizon = s.invalid_horizon;
  out.train.invalid_weight = s.invalid_weight;
  out.train.symmetries = out.held.symmetries = s.symmetries;
  out.train.representatives = out.held.representatives = s.representatives;
  return out;
}

bool holds_out(const SamplingVariant& s, const ExperimentSettings& e) {
  return e.holdout > 0.0 && s.raw();
}

int folds_for(const SamplingVariant& s, const ExperimentSettings& e, size_t valid_samples) {
  if (!s.raw()) return 0;
  if (e.folds == ExperimentSettings::kFoldsAuto)
    return e.holdout > 0.0 && valid_samples <= ExperimentSettings::kAutoFoldsMaxSamples ? ExperimentSettings::kAutoFolds
                                                                                     : 0;
  return e.folds >= 2 ? e.folds : 0;
}

HoldoutSplit split_holdout(const SampleSet& s, double fraction, uint64_t seed) {
  if (!(fraction >= 0.0 && fraction <= 0.5))
    throw std::invalid_argument("holdout: expected a fraction in 0..0.5, found " + std::to_string(fraction));
  std::vector<size_t> valid;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) valid.push_back(k);
  const size_t n_held = static_cast<size_t>(std::llround(fraction * static_cast<double>(valid.size())));
  if (valid.size() - n_held < 2)
    throw std::invalid_argument("holdout: " + std::to_string(valid.size()) + " valid samples leave " +
                                std::to_string(valid.size() - n_held) +
                                " to fit after holding out " + std::to_string(n_held) + "; expected at least 2");
  // Partial Fisher-Yates: the first n_held entries are the held-out samples.
  uint64_t state = seed;
  for (size_t i = 0; i < n_held; ++i) {
    const size_t j = i + static_cast<size_t>(splitmix(state) % (valid.size() - i));
    std::swap(valid[i], valid[j]);
  }
  std::vector<uint8_t> is_held(s.size(), 0);
  for (size_t i = 0; i < n_held; ++i) is_held[valid[i]] = 1;
  HoldoutSplit out = partition_held(s, is_held);
  out.train.description = s.description + " without " + std::to_string(n_held) + " held-out samples";
  out.held.description = std::to_string(n_held) + " held-out samples of " + s.description;
  return out;
}

SampleSet validation_set(const Brdf& brdf, int pairs, uint64_t seed) {
  SampleSet v = sample_stratified(brdf, static_cast<size_t>(pairs), seed);
  v.description = "validation: stratified " + std::to_string(pairs) + " pairs over the hemisphere pair";
  if (const size_t skipped = mask_undefined(brdf, v); skipped > 0)
    v.description += " (" + std::to_string(skipped) + " where the truth has no data skipped)";
  return v;
}

uint64_t validation_block_seed(uint64_t seed, int block) {
  if (block == 0) return seed;
  uint64_t x = seed ^ (0x9E3779B97F4A7C15ull * static_cast<uint64_t>(block));
  return splitmix(x);
}

DomainSet domain_set(const Brdf& brdf, int validation_pairs, uint64_t seed) {
  DomainSet d;
  if (validation_pairs != ExperimentSettings::kValidationAuto) {
    if (validation_pairs < 1)
      throw std::invalid_argument("validation_pairs: expected \"auto\" or a number of pairs >= 1, found " +
                                  std::to_string(validation_pairs));
    d.pairs = validation_set(brdf, validation_pairs, seed);
    return d;
  }
  d.block_pairs = ExperimentSettings::kValidationBlockPairs;
  d.blocks = ExperimentSettings::kValidationMaxBlocks;
  size_t skipped = 0;
  for (int b = 0; b < d.blocks; ++b) {
    SampleSet block = validation_set(brdf, d.block_pairs, validation_block_seed(seed, b));
    skipped += block.size() - block.valid_count();
    for (size_t k = 0; k < block.size(); ++k) {
      d.pairs.wi.push_back(block.wi[k]);
      d.pairs.wo.push_back(block.wo[k]);
      d.pairs.value.push_back(block.value[k]);
      d.pairs.valid.push_back(block.valid[k]);
    }
  }
  d.pairs.description = "validation: " + std::to_string(d.blocks) + " stratified blocks of " +
                        std::to_string(d.block_pairs) + " pairs over the hemisphere pair" +
                        (skipped > 0 ? " (" + std::to_string(skipped) + " where the truth has no data skipped)"
                                     : std::string());
  return d;
}

double relative_standard_error(const std::vector<double>& block_rel_mse) {
  const size_t n = block_rel_mse.size();
  if (n < 2) return std::numeric_limits<double>::infinity();
  long double mean = 0;
  for (double e : block_rel_mse) mean += e;
  mean /= static_cast<long double>(n);
  if (!(mean > 0)) return 0.0;
  long double ss = 0;
  for (double e : block_rel_mse) ss += (e - mean) * (e - mean);
  const long double sd = std::sqrt(ss / static_cast<long double>(n - 1));
  return static_cast<double>(sd / std::sqrt(static_cast<long double>(n)) / mean);
}

namespace {

// An "auto" domain: whole blocks, kValidationMinBlocks first, doubled while
// the val rel_mse is less precise than kValidationTargetSe.
void score_blocks(const Brdf& approx, const DomainSet& d, const LogTransform& lt, ValidationScores& v) {
  const SampleSet& s = d.pairs;
  const size_t bp = static_cast<size_t>(d.block_pairs);
  std::vector<Rgb> values(s.size(), Rgb::Zero());
  std::vector<double> block_err;
  int blocks = std::min(ExperimentSettings::kValidationMinBlocks, d.blocks);
  int done = 0;
  while (true) {
    for (; done < blocks; ++done) {
      const size_t b0 = static_cast<size_t>(done) * bp, b1 = b0 + bp;
      size_t valid = 0;
      for (size_t k = b0; k < b1; ++k)
        if (s.valid[k]) values[k] = approx.eval(s.wi[k], s.wo[k]), ++valid;
      if (valid > 0) block_err.push_back(metrics_of_values(s, b0, b1, values, lt).rel_mse);
    }
    v.rel_se = relative_standard_error(block_err);
    if (v.rel_se <= ExperimentSettings::kValidationTargetSe || blocks >= d.blocks) break;
    blocks = std::min(2 * blocks, d.blocks);
  }
  const size_t end = static_cast<size_t>(blocks) * bp;
  v.blocks = blocks;
  v.pairs = end;
  v.val = metrics_of_values(s, 0, end, values, lt);
  v.max_ratio = peak_ratio_of_values(s, 0, end, values);
}

}  // namespace

ValidationScores score_validation(const Brdf& approx, const DomainSet* domain, const SampleSet* held,
                                  const LogTransform& lt) {
  ValidationScores v;
  if (domain && domain->pairs.valid_count() > 0) {
    v.domain = true;
    if (domain->block_pairs > 0) {
      score_blocks(approx, *domain, lt, v);
    } else {
      v.val = evaluate_metrics(approx, domain->pairs, lt);
      v.max_ratio = peak_ratio(approx, domain->pairs);
      v.pairs = domain->pairs.size();
    }
  }
  if (held && held->valid_count() > 0) {
    v.holdout = true;
    v.held = evaluate_metrics(approx, *held, lt);
  }
  return v;
}

void fill_validation_columns(const ValidationScores& v, double training_rel_mse, const std::string& scheme,
                             Row& row, std::vector<std::string>& notes) {
  std::vector<std::string> flags;
  auto far_above = [&](double e) {
    return e > kFlagErrorFactor * training_rel_mse && e > kFlagErrorFloor;
  };
  auto flag_error = [&](const char* col, double e) {
    if (!far_above(e)) return;
    flags.push_back(col);
    notes.push_back(std::string("flag: ") + col + " " + format_short(format_number(e)) + " is " +
                    (training_rel_mse > 0 ? format_short(format_number(e / training_rel_mse)) + "x"
                                          : std::string("far above")) +
                    " the training rel_mse " + format_short(format_number(training_rel_mse)) + " (threshold " +
                    format_short(format_number(kFlagErrorFactor)) + "x and " +
                    format_short(format_number(kFlagErrorFloor)) + "): the fit does not generalize");
  };
  if (v.domain) {
    row["val_rel_mse"] = format_number(v.val.rel_mse);
    row["val_cos_rmse"] = format_number(v.val.cos_rmse);
    row["val_max_ratio"] = format_number(v.max_ratio);
    flag_error("val_rel_mse", v.val.rel_mse);
    if (v.max_ratio > kFlagMaxRatio) {
      flags.push_back("val_max_ratio");
      notes.push_back("flag: val_max_ratio " + format_short(format_number(v.max_ratio)) + " > " +
                      format_short(format_number(kFlagMaxRatio)) +
                      ": somewhere in the domain the approximation exceeds the BRDF's peak that many times "
                      "(extrapolation where no sample constrains it)");
    }
  }
  if (v.holdout) {
    row["holdout_rel_mse"] = format_number(v.held.rel_mse);
    row["holdout_cos_rmse"] = format_number(v.held.cos_rmse);
    flag_error("holdout_rel_mse", v.held.rel_mse);
  }
  row["validation"] = scheme;
  std::string f;
  for (const auto& x : flags) f += (f.empty() ? "" : ",") + x;
  row["flag"] = f;
}

}  // namespace bf
