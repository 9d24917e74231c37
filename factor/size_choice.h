// The types of tolerance-driven size selection (docs/design.md §9 "what a scene
// needs"), shared by the SVD and SH baselines (factor/svd_baseline.h,
// factor/sh_baseline.h), the homomorphic fits (factor/size_select.h) and the
// search's stopping rule: an error target, the candidates scored, the choice.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/factorization.h"
#include "factor/metrics.h"

namespace bf {

// An error target: a metric of factor/metrics.h (metric_value names) and a
// value. A metric that is not computed on the fit's own samples (shade_rmse,
// the validation metrics val_*: external_metric_names()) is scored by `score`,
// which the caller supplies (the experiment runner renders the scene or scores
// the validation set); every selection goes through error_of(), so each of
// them accepts every metric.
struct Tolerance {
  std::string metric = "cos_rmse";
  double value = 0.0;  // > 0
  // Scorer of a candidate for an external metric; empty for sample metrics.
  std::function<double(const Brdf& candidate)> score;
  // Throws std::invalid_argument for an unknown metric, value <= 0 / NaN, or
  // an external metric without a scorer.
  void validate() const;
  // The metric of `candidate`: score(candidate) when a scorer is set, else
  // metric_value(evaluate_metrics(candidate, samples, lt), metric).
  double error_of(const Brdf& candidate, const SampleSet& samples, const LogTransform& lt) const;
};

// Metrics a Tolerance scores through its `score` (not on the fit's samples):
// shade_rmse, val_rel_mse, val_cos_rmse, val_max_ratio.
const std::vector<std::string>& external_metric_names();
bool is_external_metric(const std::string& name);

// One scored candidate of a selection.
struct SizeTrial {
  int value = 0;        // rank K or order F
  int view_order = -1;  // SH-R: view order P; -1 otherwise
  double error = 0;     // the tolerance metric
  int texture_size = 0; // resolution of the trial when it is chosen too (select_*_size); 0 otherwise
};

// What a selection chose, with its error and time (a row of a report).
struct SizeChoice {
  std::string method;   // "svd", "sh-k", "sh-r"
  std::string knob;     // "terms" (SVD rank) or "order" (SH band limit F)
  int value = 0;        // the chosen rank / order
  int view_order = -1;  // SH-R: the chosen view order P; -1 otherwise
  int texture_size = 0; // the chosen resolution (select_*_size); 0 when the resolution was fixed
  std::string metric;   // tolerance metric
  double error = 0;     // metric at the choice
  bool reached = false; // error <= tolerance; false: nothing up to the cap reached it, value is the best tried
  double seconds = 0;   // wall time: tabulation/projection + decompositions + scoring
  std::vector<SizeTrial> tried;  // in the order scored
  FactorizationPtr result;       // the chosen approximation
  std::vector<double> errors_after_term;  // homomorphic: rel_mse after each term of the chosen fit
};

// The resolutions tried when texture_size = "auto": 8, 12, 16, 24, 32.
const std::vector<int>& default_texture_ladder();
// Throws std::invalid_argument unless ladder is non-empty, strictly
// ascending and every entry lies in lo..hi; `what` names the field.
void validate_texture_ladder(const std::vector<int>& ladder, int lo, int hi, const std::string& what);

}  // namespace bf
