// The search's stratified subsample (see subsample.h).
#include "search/subsample.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

namespace bf {

namespace {

// Polar angle (0..pi/2) and azimuth (0..2 pi) of the direction whose parabolic point is (a, b).
void angles(double a, double b, double& theta, double& phi) {
  theta = 2 * std::atan(std::sqrt(a * a + b * b));
  phi = std::atan2(b, a);
  if (phi < 0) phi += 2 * M_PI;
}

int bin(double v, int n) { return std::clamp(static_cast<int>(v * n), 0, n - 1); }

}  // namespace

size_t subsample_stratum(const Vec4& x, int coarsen) {
  double th, ph, td, pd;
  angles(x[0], x[1], th, ph);
  angles(x[2], x[3], td, pd);
  const int nh = std::max(1, kThetaHBins >> coarsen), na = std::max(1, kAngleBins >> coarsen);
  const int ih = bin(std::sqrt(std::max(0.0, th) / (M_PI / 2)), nh);
  const int jh = bin(ph / (2 * M_PI), na);
  const int id = bin(td / (M_PI / 2), na);
  const int jd = bin(pd / (2 * M_PI), na);
  return ((size_t(ih) * kAngleBins + jh) * kAngleBins + id) * kAngleBins + jd;
}

FitData stratified_subsample(const FitData& d, size_t n, uint64_t seed, SubsampleInfo* info) {
  const size_t N = d.size();
  if (n < 1 || n >= N)
    throw std::invalid_argument("search_samples: a subsample needs 1 <= n < " + std::to_string(N) +
                                " samples, found " + std::to_string(n));
  constexpr size_t S = size_t(kThetaHBins) * kAngleBins * kAngleBins * kAngleBins;
  // Members of each stratum, in sample order (counting sort).
  std::vector<uint32_t> stratum(N);
  std::vector<size_t> start(S + 1, 0);
  int coarsen = 0;
  for (;; ++coarsen) {  // the finest strata with at most n / 2 non-empty ones
    std::fill(start.begin(), start.end(), 0);
    for (size_t k = 0; k < N; ++k) {
      stratum[k] = static_cast<uint32_t>(subsample_stratum(d.x_halfdiff[k], coarsen));
      ++start[stratum[k] + 1];
    }
    size_t nonempty = 0;
    for (size_t s = 1; s <= S; ++s) nonempty += start[s] != 0;
    if (2 * nonempty <= n || (kThetaHBins >> coarsen) <= 1) break;
  }
  for (size_t s = 0; s < S; ++s) start[s + 1] += start[s];
  std::vector<size_t> member(N);
  {
    std::vector<size_t> at(start.begin(), start.end() - 1);
    for (size_t k = 0; k < N; ++k) member[at[stratum[k]]++] = k;
  }
  const auto count = [&](size_t s) { return start[s + 1] - start[s]; };
  // The largest cap with sum min(count, cap) <= n (binary search; n < N, so
  // the cap is below the largest count).
  const auto kept = [&](size_t cap) {
    size_t t = 0;
    for (size_t s = 0; s < S; ++s) t += std::min(count(s), cap);
    return t;
  };
  size_t lo = 0, hi = N;  // kept(lo) <= n < kept(hi)
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    (kept(mid) <= n ? lo : hi) = mid;
  }
  const size_t cap = lo;
  std::vector<size_t> quota(S);
  std::vector<size_t> above;  // strata with more samples than the cap
  size_t total = 0;
  for (size_t s = 0; s < S; ++s) {
    quota[s] = std::min(count(s), cap);
    total += quota[s];
    if (count(s) > cap) above.push_back(s);
  }
  std::mt19937_64 rng(seed * 0x9e3779b97f4a7c15ull + 0x5ab5a3b1e5ull);
  // n - total < |above| (else cap + 1 would fit): one more for the first strata in a seeded order.
  std::shuffle(above.begin(), above.end(), rng);
  for (size_t i = 0; total < n && i < above.size(); ++i, ++total) ++quota[above[i]];
  // Each stratum's kept samples: a seeded partial shuffle of its members;
  // weights scaled to keep the stratum's total weight.
  std::vector<double> scale(N, 0.0);  // 0 = not kept
  size_t strata = 0;
  for (size_t s = 0; s < S; ++s) {
    const size_t c = count(s);
    if (c == 0) continue;
    ++strata;
    size_t* m = member.data() + start[s];
    const size_t q = quota[s];
    if (q < c)
      for (size_t i = 0; i < q; ++i) {
        std::uniform_int_distribution<size_t> pick(i, c - 1);
        std::swap(m[i], m[pick(rng)]);
      }
    double all = 0, sel = 0;
    for (size_t i = 0; i < c; ++i) all += d.w[m[i]];
    for (size_t i = 0; i < q; ++i) sel += d.w[m[i]];
    // A stratum whose kept samples weigh nothing while others do cannot carry
    // its weight: keep them at their own weight (0).
    const double f = sel > 0 ? all / sel : 1.0;
    for (size_t i = 0; i < q; ++i) scale[m[i]] = f;
  }
  FitData out;
  out.transform = d.transform;
  out.log_range = d.log_range;
  out.prior_wiwo = d.prior_wiwo;
  out.prior_halfdiff = d.prior_halfdiff;
  out.prior_w = d.prior_w;
  out.x_wiwo.reserve(n);
  out.x_halfdiff.reserve(n);
  out.w.reserve(n);
  for (int c = 0; c < 3; ++c) out.g[c].reserve(n);
  for (size_t k = 0; k < N; ++k) {
    if (scale[k] == 0.0) continue;
    out.x_wiwo.push_back(d.x_wiwo[k]);
    out.x_halfdiff.push_back(d.x_halfdiff[k]);
    out.w.push_back(d.w[k] * scale[k]);
    out.W += out.w.back();
    for (int c = 0; c < 3; ++c) {
      out.g[c].push_back(d.g[c][k]);
      out.wg2[c] += out.w.back() * d.g[c][k] * d.g[c][k];
    }
  }
  if (info) *info = SubsampleInfo{out.size(), N, seed, strata, cap, coarsen};
  return out;
}

}  // namespace bf
