// Validation of every run on data its fit never saw (docs/design.md §4
// "validation"): a stratified set over the whole hemisphere pair scored
// against the BRDF (for measured BRDFs: their interpolant), and, for runs on
// raw samples (sampling kind "measured" or "file"), a held-out fraction of
// those samples the fit is trained without. Also the flags that mark a run
// whose validation error is far above its training error or whose values
// exceed the BRDF's peak. The runner applies all of it to every run, whatever
// its method kind.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "brdfs/sampleset.h"
#include "experiments/plan/plan.h"
#include "experiments/report/outputs.h"
#include "factor/metrics.h"

namespace bf {

// Flag thresholds (docs/design.md §4 "flags").
// A validation or held-out rel_mse above kFlagErrorFactor x the training
// rel_mse and above kFlagErrorFloor (so near-perfect fits are not flagged for
// a ratio of tiny numbers).
inline constexpr double kFlagErrorFactor = 10.0;
inline constexpr double kFlagErrorFloor = 0.05;
// val_max_ratio above this: the approximation exceeds the BRDF's peak that
// many times somewhere in the domain (unbounded extrapolation).
inline constexpr double kFlagMaxRatio = 10.0;

// Whether runs on this sampling hold samples out of the fit (raw samples:
// kind "measured" or "file") when experiment.holdout > 0.
bool holds_out(const SamplingVariant& s, const ExperimentSettings& e);

// The number of folds a run on this sampling uses, 0 for none (the single
// fraction, or nothing held out): experiment.folds when set (k >= 2) on raw
// samples; with folds = "auto" (the default), kAutoFolds when the samples
// have at most kAutoFoldsMaxSamples valid samples, where a 10% fraction holds
// out too few to measure (for 1,439 Cornell samples, 144), else 0.
int folds_for(const SamplingVariant& s, const ExperimentSettings& e, size_t valid_samples);

// The fit's samples and the held-out ones: round(fraction x valid samples)
// valid samples chosen by a seeded shuffle (deterministic for a seed, the
// same on every platform); masked samples stay in `train` (masked). Weights
// follow their samples. Throws std::invalid_argument when fraction is not in
// [0, 0.5] or fewer than 2 valid samples would remain to train on.
struct HoldoutSplit {
  SampleSet train, held;
};
HoldoutSplit split_holdout(const SampleSet& s, double fraction, uint64_t seed);

// The whole-domain validation set of a BRDF: sample_stratified(brdf, pairs,
// seed) (Latin-hypercube in cos theta and phi of both directions, uniform in
// solid angle, so grazing directions are sampled as often as their solid angle).
// Pairs where brdf has no data (Brdf::defined_at: a MERL table's missing
// cells) are masked, and the description counts them: the whole-domain
// columns compare only where the truth holds.
SampleSet validation_set(const Brdf& brdf, int pairs, uint64_t seed);
// The seed of block b of the "auto" set: seed itself for block 0 (so block 0
// is validation_set(brdf, kValidationBlockPairs, seed)), a SplitMix64 draw of
// (seed, b) for the others.
uint64_t validation_block_seed(uint64_t seed, int block);
// A run's whole-domain set. With experiment.validation_pairs = N: one
// stratified set of N pairs, scored whole (block_pairs = 0). With "auto"
// (the default): `blocks` independent stratified blocks of block_pairs pairs
// each (block b drawn with validation_block_seed(seed, b)), one after the
// other in `pairs`; score_validation scores a prefix of whole blocks, as
// many as its precision rule needs.
struct DomainSet {
  SampleSet pairs;
  int block_pairs = 0;
  int blocks = 1;
};
// Throws std::invalid_argument for pairs < 1 (other than kValidationAuto).
DomainSet domain_set(const Brdf& brdf, int validation_pairs, uint64_t seed);
// The "auto" rule's precision: the standard error of the rel_mse over b equal
// blocks, sd(block rel_mse) / sqrt(b), relative to their mean (0 when the mean
// is 0; the blocks are independent stratified sets, so their errors are
// independent draws). blocks with fewer than 2 entries give +infinity.
double relative_standard_error(const std::vector<double>& block_rel_mse);
// Scores of one approximation on the validation data.
struct ValidationScores {
  bool domain = false;    // a whole-domain set was scored
  Metrics val;            // on the whole-domain set (with the fit's log transform)
  double max_ratio = 0;   // peak_ratio on the whole-domain set
  size_t pairs = 0;       // pairs of the domain set scored (a prefix of it with "auto")
  int blocks = 0;         // "auto": blocks scored; 0 for a set scored whole
  double rel_se = -1;     // "auto": relative_standard_error of val rel_mse; -1 otherwise
  bool holdout = false;   // held-out samples were scored
  Metrics held;           // on the held-out samples
};
// domain / held may be null (not scored). With an "auto" domain: blocks
// kValidationMinBlocks, then doubled (up to the domain's blocks) while the
// relative standard error of val rel_mse is above kValidationTargetSe; the
// approximation is evaluated once per pair scored.
ValidationScores score_validation(const Brdf& approx, const DomainSet* domain, const SampleSet* held,
                                  const LogTransform& lt);
// Fills val_rel_mse, val_cos_rmse, val_max_ratio, holdout_rel_mse,
// holdout_cos_rmse and `validation` (the scheme in words) from the scores;
// appends to `notes` a "flag: ..." entry per threshold crossed (and sets
// the `flag` column to the short names, comma-separated). training_rel_mse:
// the run's rel_mse on its fit samples.
void fill_validation_columns(const ValidationScores& v, double training_rel_mse, const std::string& scheme,
                             Row& row, std::vector<std::string>& notes);

}  // namespace bf
