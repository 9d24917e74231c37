// Error metrics (see metrics.h).
#include "factor/metrics.h"

#include <cmath>
#include <stdexcept>

namespace bf {

LogTransform LogTransform::of(const SampleSet& s, double eps) {
  if (!(eps > 0.0 && eps <= 1.0))
    throw std::invalid_argument("eps: expected 0 < eps <= 1, found " + std::to_string(eps));
  Rgb sum = Rgb::Zero();
  size_t n = 0;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) {
      sum += s.value[k];
      ++n;
    }
  if (n == 0) throw std::invalid_argument("log transform: the sample set has no valid sample");
  LogTransform t;
  t.A = sum / double(n);
  t.eps = eps;
  for (int c = 0; c < 3; ++c)
    if (!(t.A[c] > 0.0) || !std::isfinite(t.A[c]))
      throw std::invalid_argument("log transform: channel " + std::string(1, "rgb"[c]) +
                                  " has mean " + std::to_string(t.A[c]) +
                                  " over the valid samples (an all-zero BRDF cannot be "
                                  "factored in log space)");
  t.eps = eps;
  return t;
}

Metrics evaluate_metrics(const Brdf& approx, const SampleSet& s, const LogTransform& t) {
  constexpr double kBad = 1e300;
  double W = 0, rel_se = 0, rel_ae = 0, lin_se = 0, lin_ae = 0, cos_se = 0;
  Metrics m;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    const double w = s.weight_of(k);
    const Rgb fa = approx.eval(s.wi[k], s.wo[k]);
    ++m.samples;
    W += 3.0 * w;
    for (int c = 0; c < 3; ++c) {
      const double f = s.value[k][c];
      double dg, df;
      if (std::isfinite(fa[c])) {
        dg = t.g(c, fa[c]) - t.g(c, f);
        df = fa[c] - f;
      } else {
        dg = df = kBad;
      }
      const double dc = std::isfinite(fa[c]) ? df * s.wi[k].z() : kBad;
      rel_se += w * std::min(dg * dg, kBad);
      rel_ae += w * std::abs(dg);
      m.rel_max = std::max(m.rel_max, std::abs(dg));
      lin_se += w * std::min(df * df, kBad);
      lin_ae += w * std::abs(df);
      m.lin_max = std::max(m.lin_max, std::abs(df));
      cos_se += w * std::min(dc * dc, kBad);
    }
  }
  if (m.samples == 0) throw std::invalid_argument("metrics: the sample set has no valid sample");
  if (!(W > 0.0)) throw std::invalid_argument("metrics: the sample weights sum to 0");
  m.rel_mse = rel_se / W;
  m.rel_mae = rel_ae / W;
  m.lin_rmse = std::sqrt(lin_se / W);
  m.lin_mae = lin_ae / W;
  m.cos_rmse = std::sqrt(cos_se / W);
  return m;
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
