// Error metrics of docs/design.md §4: one definition, used by every method, on the
// same samples, so numbers in one table are comparable.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"

namespace bf {

// McCool's log transform (thesis eq. 1.9): g = log((f + eps*A) / A), with A the
// per-channel mean of f over the valid samples (unweighted).
struct LogTransform {
  Rgb A = Rgb::Ones();
  double eps = 1e-5;
  // Throws std::invalid_argument if s has no valid sample, if eps is not in
  // (0, 1], or if a channel's mean is 0 (all-zero BRDF: nothing to factor).
  static LogTransform of(const SampleSet& s, double eps = 1e-5);
  double g(int c, double f) const { return std::log((std::max(f, 0.0) + eps * A[c]) / A[c]); }
};

struct Metrics {
  double rel_mse = 0, rel_mae = 0, rel_max = 0;    // on g (log space)
  double lin_rmse = 0, lin_mae = 0, lin_max = 0;   // on f (1/sr)
  double cos_rmse = 0;                              // on (f_approx - f) cos(theta_i)
  // rel_mse of R, G, B alone: sum_k w_k (g_c(f_approx) - g_c(f))^2 / sum_k w_k
  // (their mean is rel_mse); run.json `validation.channel_rel_mse`.
  std::array<double, 3> rel_mse_channel{0, 0, 0};
  size_t samples = 0;                               // valid samples scored
};

// Scores approx against the valid samples of s (weights w_k from s, 1 if none),
// over the three channels. Sums are in long double, so the metrics of a BRDF
// scaled by 1e200 or 1e-300 are the scaled metrics (no overflow to the cap, no
// underflow to 0). Non-finite approximation values count as an error of 1e300
// and every metric is capped at 1e300 (never NaN or Inf). Throws if s has no
// valid sample or the weights sum to 0.
Metrics evaluate_metrics(const Brdf& approx, const SampleSet& s, const LogTransform& t);

// The largest ratio of the approximation to the original's peak, over the
// valid samples of s and the three channels:
//   max_{k,c} max(f_approx,c(k), 0) / max_k' f_c(k')
// (the `val_max_ratio` column, docs/design.md §4 "validation"). A channel whose
// original is 0 at every valid sample is skipped (no peak to compare with);
// 0 when every channel is skipped. Non-finite approximation values count as
// 1e300 and the result is capped at 1e300. 1 or less: the approximation never
// exceeds what the BRDF reaches on this set. Throws if s has no valid sample.
double peak_ratio(const Brdf& approx, const SampleSet& s);

// The same two on samples [begin, end) of s only, with the approximation's
// values given: values[k] for sample k (values has one entry per sample of s;
// entries outside the range or at masked samples are not read). The
// validation set scores prefixes of one set this way, evaluating the
// approximation once (experiments/report/validation.h). Throws
// std::invalid_argument for a range outside s or a values vector of another
// size, and as above.
Metrics metrics_of_values(const SampleSet& s, size_t begin, size_t end, const std::vector<Rgb>& values,
                          const LogTransform& t);
double peak_ratio_of_values(const SampleSet& s, size_t begin, size_t end, const std::vector<Rgb>& values);

// The metric named `name` ("rel_mse", ..., "cos_rmse"); throws for unknown names.
double metric_value(const Metrics& m, const std::string& name);

}  // namespace bf
