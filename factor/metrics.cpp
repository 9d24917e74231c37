// Error metrics (see metrics.h).
#include "factor/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bf {

LogTransform LogTransform::of(const SampleSet& s, double eps) {
  if (!(eps > 0.0 && eps <= 1.0))
    throw std::invalid_argument("eps: expected 0 < eps <= 1, found " + std::to_string(eps));
  // Summed in long double: values near the top of double's range do not
  // overflow the sum, and the messages below can tell overflow, underflow and
  // an all-zero channel apart.
  long double sum[3] = {0, 0, 0};
  bool nonzero[3] = {false, false, false};
  size_t n = 0;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) {
      for (int c = 0; c < 3; ++c) {
        sum[c] += s.value[k][c];
        nonzero[c] = nonzero[c] || s.value[k][c] != 0.0;
      }
      ++n;
    }
  if (n == 0) throw std::invalid_argument("log transform: the sample set has no valid sample");
  LogTransform t;
  t.eps = eps;
  for (int c = 0; c < 3; ++c) {
    const long double mean = sum[c] / static_cast<long double>(n);
    const std::string head = "log transform: channel " + std::string(1, "rgb"[c]) + " ";
    if (!nonzero[c])
      throw std::invalid_argument(head + "has mean 0: it is 0 at every valid sample (an all-zero BRDF "
                                  "cannot be factored in log space)");
    if (!(mean <= static_cast<long double>(std::numeric_limits<double>::max())))
      throw std::invalid_argument(head + "has a mean beyond the double range (values up to about 1.8e308 "
                                  "are representable, their mean must be too)");
    t.A[c] = static_cast<double>(mean);  // denormal means stay (tested by the stress case "denormal")
    if (!(t.A[c] > 0.0))
      throw std::invalid_argument(head + "has a mean below the smallest double (underflow: rescale the BRDF)");
  }
  t.eps = eps;
  return t;
}

namespace {

// Sums run in long double: on x86-64 (80-bit) and on AArch64 (quad) its
// exponent range holds the square of any double, so neither a 1e200-scaled BRDF
// (errors^2 ~ 1e400) overflows nor a 1e-300-scaled one (errors^2 ~ 1e-600)
// underflows to 0; the results are rounded back to double.
using Acc = long double;
static_assert(std::numeric_limits<Acc>::max_exponent >= 2 * std::numeric_limits<double>::max_exponent &&
                  std::numeric_limits<Acc>::min_exponent - std::numeric_limits<Acc>::digits <=
                      2 * (std::numeric_limits<double>::min_exponent - std::numeric_limits<double>::digits),
              "metrics need a long double whose range holds the square of every double");

constexpr double kBad = 1e300;  // error charged for a non-finite approximation value; cap of every metric

double capped(Acc x) { return x < Acc(kBad) ? double(x) : kBad; }

}  // namespace

namespace {

// The metrics of samples [begin, end) of s, with fa(k) the approximation's
// value at sample k (called once per valid sample).
template <class Values>
Metrics metrics_core(const SampleSet& s, size_t begin, size_t end, Values&& fa_of, const LogTransform& t) {
  Acc W = 0, rel_se = 0, rel_ae = 0, lin_se = 0, lin_ae = 0, cos_se = 0, rel_max = 0, lin_max = 0;
  Acc rel_se_c[3] = {0, 0, 0};
  Metrics m;
  for (size_t k = begin; k < end; ++k) {
    if (!s.valid[k]) continue;
    const Acc w = s.weight_of(k);
    const Rgb fa = fa_of(k);
    ++m.samples;
    W += 3 * w;
    for (int c = 0; c < 3; ++c) {
      const double f = s.value[k][c];
      Acc dg, df, dc;
      if (std::isfinite(fa[c])) {
        dg = Acc(t.g(c, fa[c])) - Acc(t.g(c, f));
        df = Acc(fa[c]) - Acc(f);  // exact for doubles of similar size, never overflows
        dc = df * Acc(s.wi[k].z());
        if (!std::isfinite(dg)) dg = kBad;  // log of 0 where eps * A underflows
      } else {
        dg = df = dc = kBad;
      }
      rel_se += w * dg * dg;
      rel_se_c[c] += w * dg * dg;
      rel_ae += w * std::abs(dg);
      rel_max = std::max(rel_max, std::abs(dg));
      lin_se += w * df * df;
      lin_ae += w * std::abs(df);
      lin_max = std::max(lin_max, std::abs(df));
      cos_se += w * dc * dc;
    }
  }
  if (m.samples == 0) throw std::invalid_argument("metrics: the sample set has no valid sample");
  if (!(W > 0)) throw std::invalid_argument("metrics: the sample weights sum to 0");
  m.rel_mse = capped(rel_se / W);
  for (int c = 0; c < 3; ++c) m.rel_mse_channel[c] = capped(3 * rel_se_c[c] / W);
  m.rel_mae = capped(rel_ae / W);
  m.rel_max = capped(rel_max);
  m.lin_rmse = capped(std::sqrt(lin_se / W));
  m.lin_mae = capped(lin_ae / W);
  m.lin_max = capped(lin_max);
  m.cos_rmse = capped(std::sqrt(cos_se / W));
  return m;
}

template <class Values>
double peak_ratio_core(const SampleSet& s, size_t begin, size_t end, Values&& fa_of) {
  Rgb peak = Rgb::Zero();
  size_t n = 0;
  for (size_t k = begin; k < end; ++k)
    if (s.valid[k]) {
      ++n;
      for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], s.value[k][c]);
    }
  if (n == 0) throw std::invalid_argument("peak ratio: the sample set has no valid sample");
  double worst = 0.0;
  for (size_t k = begin; k < end; ++k) {
    if (!s.valid[k]) continue;
    const Rgb fa = fa_of(k);
    for (int c = 0; c < 3; ++c) {
      if (!(peak[c] > 0.0)) continue;
      const double r = std::isfinite(fa[c]) ? std::max(fa[c], 0.0) / peak[c] : kBad;
      worst = std::max(worst, std::isfinite(r) ? r : kBad);
    }
  }
  return std::min(worst, kBad);
}

void check_range(const SampleSet& s, size_t begin, size_t end, size_t values, const char* what) {
  if (begin > end || end > s.size() || values != s.size())
    throw std::invalid_argument(std::string(what) + ": expected 0 <= begin <= end <= " + std::to_string(s.size()) +
                                " and one value per sample, found [" + std::to_string(begin) + ", " +
                                std::to_string(end) + ") with " + std::to_string(values) + " values");
}

}  // namespace

Metrics evaluate_metrics(const Brdf& approx, const SampleSet& s, const LogTransform& t) {
  return metrics_core(s, 0, s.size(), [&](size_t k) { return approx.eval(s.wi[k], s.wo[k]); }, t);
}

double peak_ratio(const Brdf& approx, const SampleSet& s) {
  return peak_ratio_core(s, 0, s.size(), [&](size_t k) { return approx.eval(s.wi[k], s.wo[k]); });
}

Metrics metrics_of_values(const SampleSet& s, size_t begin, size_t end, const std::vector<Rgb>& values,
                          const LogTransform& t) {
  check_range(s, begin, end, values.size(), "metrics of values");
  return metrics_core(s, begin, end, [&](size_t k) { return values[k]; }, t);
}

double peak_ratio_of_values(const SampleSet& s, size_t begin, size_t end, const std::vector<Rgb>& values) {
  check_range(s, begin, end, values.size(), "peak ratio of values");
  return peak_ratio_core(s, begin, end, [&](size_t k) { return values[k]; });
}

double metric_value(const Metrics& m, const std::string& name) {
  if (name == "rel_mse") return m.rel_mse;
  if (name == "rel_mae") return m.rel_mae;
  if (name == "rel_max") return m.rel_max;
  if (name == "lin_rmse") return m.lin_rmse;
  if (name == "lin_mae") return m.lin_mae;
  if (name == "lin_max") return m.lin_max;
  if (name == "cos_rmse") return m.cos_rmse;
  throw std::invalid_argument("metric: expected one of rel_mse, rel_mae, rel_max, lin_rmse, "
                              "lin_mae, lin_max, cos_rmse, found '" + name + "'");
}

}  // namespace bf
