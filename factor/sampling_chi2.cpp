#include "factor/sampling_chi2.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace bf {

double gamma_q(double a, double x) {
  if (!(a > 0) || !(x >= 0)) return std::nan("");
  if (x == 0) return 1.0;
  const double lg = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1) {  // series for P(a, x)
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(lg));
  }
  // Continued fraction for Q(a, x) (modified Lentz).
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-16) break;
  }
  return std::min(1.0, std::exp(lg) * h);
}

double sidak(double p_min, int n) { return 1.0 - std::pow(1.0 - p_min, n); }

Chi2Result chi2_test(const BrdfSampler& s, const Vec3& wo, const Chi2Options& o) {
  const int T = o.theta_res, P = o.phi_res, K = o.refine;
  auto pdf = o.pdf ? o.pdf : [&s](const Vec3& wi, const Vec3& w) { return s.pdf(wi, w); };
  Chi2Result res;
  std::vector<double> obs(static_cast<size_t>(T) * P, 0.0), expc(obs.size(), 0.0);
  const double phi_o = wo.x() == 0 && wo.y() == 0 ? 0.0 : std::atan2(wo.y(), wo.x());
  std::mt19937_64 rng(o.seed);
  auto uni = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (size_t k = 0; k < o.samples; ++k) {
    const double u1 = uni(), u2 = uni();
    const DirectionSample d = s.sample(wo, u1, u2);
    if (!(d.pdf > 0)) continue;
    if (!(d.wi.z() > 0)) {
      res.problem = "a sample with pdf > 0 below the horizon";
      return res;
    }
    const double p = s.pdf(d.wi, wo);
    if (!(std::abs(p - d.pdf) <= 1e-9 * std::max(p, d.pdf))) {
      res.problem = "sample() returned pdf " + std::to_string(d.pdf) + ", pdf() says " + std::to_string(p);
      return res;
    }
    ++res.valid;
    const double th = std::acos(std::min(1.0, d.wi.z()));
    double ph = std::atan2(d.wi.y(), d.wi.x()) - phi_o;
    while (ph < 0) ph += 2 * M_PI;
    while (ph >= 2 * M_PI) ph -= 2 * M_PI;
    const int r = std::min(static_cast<int>(th / (M_PI / 2) * T), T - 1);
    const int c = std::min(static_cast<int>(ph / (2 * M_PI) * P), P - 1);
    obs[static_cast<size_t>(r) * P + c] += 1;
  }
  double best = -1;
  for (int r = 0; r < T; ++r) {
    const double ca = std::cos(r * (M_PI / 2) / T), cb = std::cos((r + 1) * (M_PI / 2) / T);
    for (int c = 0; c < P; ++c) {
      double sum = 0;
      for (int i = 0; i < K; ++i) {
        const double ct = ca + (cb - ca) * (i + 0.5) / K, st = std::sqrt(std::max(0.0, 1 - ct * ct));
        for (int j = 0; j < K; ++j) {
          const double ph = phi_o + (c + (j + 0.5) / K) * 2 * M_PI / P;
          sum += pdf(Vec3(st * std::cos(ph), st * std::sin(ph), ct), wo);
        }
      }
      const double e = sum / (K * K) * (ca - cb) * 2 * M_PI / P * static_cast<double>(o.samples);
      expc[static_cast<size_t>(r) * P + c] = e;
      if (e > best) best = e, res.max_theta = r, res.max_phi = c;
    }
  }
  std::vector<size_t> order(obs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expc[a] < expc[b]; });
  std::vector<std::pair<double, double>> cells;  // (observed, expected)
  double po = 0, pe = 0;
  for (size_t i : order) {
    if (expc[i] <= 0 && obs[i] > 0) {
      res.problem = "samples in a cell whose pdf integrates to 0";
      return res;
    }
    po += obs[i], pe += expc[i];
    if (pe >= 5) cells.emplace_back(po, pe), po = pe = 0;
  }
  if (pe > 0 || po > 0) {
    if (cells.empty()) cells.emplace_back(po, pe);
    else cells.back().first += po, cells.back().second += pe;
  }
  for (const auto& [ob, ex] : cells) res.chi2 += (ob - ex) * (ob - ex) / ex;
  res.dof = static_cast<int>(cells.size()) - 1;
  res.p = res.dof > 0 ? gamma_q(0.5 * res.dof, 0.5 * res.chi2) : 1.0;
  return res;
}

}  // namespace bf
