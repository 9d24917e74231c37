// The homomorphic fit's data preparation (factor/fit_internal.h): options,
// FitData, the joint terms' layouts and lookups, residual targets and the
// extrapolation prior's rows.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include "factor/assembly_kernels.h"
#include "factor/fit_internal.h"
#include "factor/homomorphic_fit.h"
#include "solvers/option_error.h"

namespace bf {

namespace {
// A number as the config reader shows it (12 significant digits).
std::string shown_number(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}
}  // namespace

void FitOptions::validate() const {
  if (!(eps > 0.0 && eps <= 1.0))
    throw OptionError("eps", "eps: expected 0 < eps <= 1, found " + std::to_string(eps));
  if (!(smoothing >= 0.0 && smoothing <= kMaxWeight))
    throw OptionError("smoothing", "smoothing: expected a number in [0, " + shown_number(kMaxWeight) + "], found " +
                                    shown_number(smoothing));
  if (!(extrapolation_prior >= 0.0 && extrapolation_prior <= kMaxWeight))
    throw OptionError("extrapolation_prior", "extrapolation_prior: expected a number in [0, " + shown_number(kMaxWeight) +
                                                 "], found " + shown_number(extrapolation_prior));
  if (solve_last < 1)
    throw OptionError("solve_last", "solve_last: expected >= 1, found " + std::to_string(solve_last));
}

FitData::FitData(const SampleSet& s, double eps) {
  transform = LogTransform::of(s, eps);
  const size_t n = s.valid_count();
  x_wiwo.reserve(n);
  x_halfdiff.reserve(n);
  w.reserve(n);
  for (int c = 0; c < 3; ++c) g[c].reserve(n);
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    x_wiwo.push_back(to_point(Parameterization::WiWo, s.wi[k], s.wo[k]));
    x_halfdiff.push_back(to_point(Parameterization::HalfDiff, s.wi[k], s.wo[k]));
    w.push_back(s.weight_of(k));
    W += s.weight_of(k);
    for (int c = 0; c < 3; ++c) g[c].push_back(transform.g(c, s.value[k][c]));
  }
  if (!(W > 0.0)) throw std::invalid_argument("fit: the valid samples' weights sum to 0");
  for (int c = 0; c < 3; ++c)
    for (size_t k = 0; k < w.size(); ++k) wg2[c] += w[k] * g[c][k] * g[c][k];
  for (int c = 0; c < 3; ++c) {
    const auto [lo, hi] = std::minmax_element(g[c].begin(), g[c].end());
    log_range[c] = {*lo, *hi};
  }
  // Prior points (FitOptions::extrapolation_prior): the centres of a G^4 grid
  // of cells in (cos theta_i, phi_i, cos theta_o, phi_o) (equal solid angle),
  // weighted wbar * exp(-4 n), n = (sample weight in the cell) / wbar; cells
  // holding samples get a negligible weight and are dropped below 1e-12 wbar.
  constexpr int G = kPriorGrid;
  const double wbar = W / static_cast<double>(n);
  const auto cell_of = [](const Vec3& v) {
    const double ct = std::clamp(v.z() / v.norm(), 0.0, 1.0);
    double ph = std::atan2(v.y(), v.x());
    if (ph < 0) ph += 2 * M_PI;
    const int a = std::min(G - 1, static_cast<int>(ct * G));
    const int b = std::min(G - 1, static_cast<int>(ph / (2 * M_PI) * G));
    return a * G + b;
  };
  std::vector<double> in_cell(size_t(G) * G * G * G, 0.0);
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) in_cell[size_t(cell_of(s.wi[k])) * G * G + cell_of(s.wo[k])] += s.weight_of(k);
  std::vector<Vec3> centre;
  for (int a = 0; a < G; ++a)
    for (int b = 0; b < G; ++b) {
      const double ct = (a + 0.5) / G, st = std::sqrt(1 - ct * ct), ph = 2 * M_PI * (b + 0.5) / G;
      centre.emplace_back(st * std::cos(ph), st * std::sin(ph), ct);
    }
  for (size_t i = 0; i < centre.size(); ++i)
    for (size_t o = 0; o < centre.size(); ++o) {
      const double pw = wbar * std::exp(-4.0 * in_cell[i * centre.size() + o] / wbar);
      if (!(pw > 1e-12 * wbar)) continue;
      prior_wiwo.push_back(to_point(Parameterization::WiWo, centre[i], centre[o]));
      prior_halfdiff.push_back(to_point(Parameterization::HalfDiff, centre[i], centre[o]));
      prior_w.push_back(pw);
    }
}

double model_log_value(double s, const FitOptions& opt) {
  if (opt.subtract_eps) return std::max(s, std::log(opt.eps));
  // log(exp(s) + eps), computed without overflow.
  return s > 0 ? s + std::log1p(opt.eps * std::exp(-s)) : std::log(std::exp(s) + opt.eps);
}

std::array<std::vector<double>, 3> fixed_sum(const FitData& d,
                                             const std::vector<FactorTerm>& fixed) {
  std::array<std::vector<double>, 3> out;
  for (int c = 0; c < 3; ++c) out[c].assign(d.size(), 0.0);
  for (const FactorTerm& t : fixed) {
    const std::vector<Vec4>& x = d.points(t.proj.param);
    const Projection conj = t.proj.conjugate();
    for (size_t k = 0; k < d.size(); ++k) {
      const Eigen::Vector2d s = t.proj.texel_coords(x[k]);
      for (int c = 0; c < 3; ++c) out[c][k] += t.lookup(c, s);
      if (t.reciprocal) {
        const Eigen::Vector2d sc = conj.texel_coords(x[k]);
        for (int c = 0; c < 3; ++c) out[c][k] += t.lookup(c, sc);
      }
    }
  }
  return out;
}

std::vector<TermSpec> mccool_terms(int res) {
  TermSpec p{projection_first_pair(Parameterization::WiWo, res), true, std::nullopt};
  TermSpec q{projection_first_pair(Parameterization::HalfDiff, res), false, std::nullopt};
  return {p, q};
}

}  // namespace bf

namespace bf::fit {

void add_layout(const FitData& d, const TermSpec& s, int& M, std::vector<TermLayout>& terms,
                std::array<Lookups, 2>& lk) {
  const size_t N = d.size();
  s.proj.validate();
  TermLayout t{FastProj(s.proj), FastProj(s.proj.conjugate()), s.reciprocal,
               &d.points(s.proj.param), {}, projection_mask(s.proj), 0, 0};
  const std::vector<Vec4>& x = *t.x;
  const int R = s.proj.res;
  thread_local std::vector<uint8_t> touched;  // cells a sample falls into
  for (int h = 0; h < (t.reciprocal ? 2 : 1); ++h) {
    const FastProj& fp = h == 0 ? t.proj : t.conj;
    Lookups& L = lk[h];
    L.cell.resize(N);
    L.fa.resize(N);
    L.fb.resize(N);
    const double m[8] = {fp.M(0, 0), fp.M(0, 1), fp.M(0, 2), fp.M(0, 3),
                         fp.M(1, 0), fp.M(1, 1), fp.M(1, 2), fp.M(1, 3)};
    touched.assign(size_t(R) * R, 0);
    kernels::lookup_cells(N, x.empty() ? nullptr : x[0].data(), m, fp.off, R, L.cell.data(), L.fa.data(),
                          L.fb.data(), touched.data());
    // Every texel a sample reads joins the mask: the 4 corners of each touched cell.
    for (int c = 0; c < R * R; ++c)
      if (touched[c]) t.mask[c] = t.mask[c + 1] = t.mask[c + R] = t.mask[c + R + 1] = 1;
  }
  t.unk.assign(t.mask.size(), -1);
  t.first = M;
  for (size_t i = 0; i < t.mask.size(); ++i)
    if (t.mask[i]) t.unk[i] = M++;
  t.count = M - t.first;
  terms.push_back(std::move(t));
}

Workspace& workspace() {
  thread_local Workspace ws;
  return ws;
}

void residual_targets(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                      std::array<std::vector<double>, 3>& r) {
  for (int c = 0; c < 3; ++c) {
    r[c].resize(d.size());
    for (size_t k = 0; k < d.size(); ++k) r[c][k] = d.g[c][k] - fixed_values[c][k];
  }
}

bool all_zero(const std::array<std::vector<double>, 3>& fixed_values) {
  constexpr uint64_t kNoSign = ~(uint64_t(1) << 63);
  for (const std::vector<double>& v : fixed_values) {
    const size_t n = v.size();
    for (size_t k = 0; k < n; k += 256) {
      const size_t e = std::min(n, k + 256);
      uint64_t bits = 0;
      for (size_t i = k; i < e; ++i) {
        uint64_t b;
        std::memcpy(&b, &v[i], sizeof b);
        bits |= b & kNoSign;
      }
      if (bits != 0) return false;
    }
  }
  return true;
}

void weighted_square_sums(const FitData& d, const std::array<const double*, 3>& r, double out[3]) {
  typedef double v4 __attribute__((vector_size(32)));
  const double* w = d.w.data();
  const size_t n = d.size();
  const double* r0 = r[0];
  const double* r1 = r[1];
  const double* r2 = r[2];
  v4 s0 = {0, 0, 0, 0}, s1 = s0, s2 = s0;
  size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    v4 wk, a, b, c;
    std::memcpy(&wk, w + k, sizeof wk);
    std::memcpy(&a, r0 + k, sizeof a);
    std::memcpy(&b, r1 + k, sizeof b);
    std::memcpy(&c, r2 + k, sizeof c);
    s0 += wk * a * a;
    s1 += wk * b * b;
    s2 += wk * c * c;
  }
  for (; k < n; ++k) {
    s0[k & 3] += w[k] * r0[k] * r0[k];
    s1[k & 3] += w[k] * r1[k] * r1[k];
    s2[k & 3] += w[k] * r2[k] * r2[k];
  }
  out[0] = (s0[0] + s0[1]) + (s0[2] + s0[3]);
  out[1] = (s1[0] + s1[1]) + (s1[2] + s1[3]);
  out[2] = (s2[0] + s2[1]) + (s2[2] + s2[3]);
}

Prior extrapolation_prior(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermLayout>& terms,
                          const std::vector<const std::array<Lookups, 2>*>& lookups, int M,
                          const FitOptions& opt) {
  Prior p;
  const size_t N = d.size();
  const double rho = opt.extrapolation_prior;
  if (!(rho > 0.0) || M == 0 || N == 0) return p;
  const double wbar = d.W / static_cast<double>(N);
  std::array<double, 3> mean_r = {0, 0, 0};
  for (size_t k = 0; k < N; ++k)
    for (int c = 0; c < 3; ++c) mean_r[c] += d.w[k] * (d.g[c][k] - fixed_values[c][k]);
  for (int c = 0; c < 3; ++c) mean_r[c] /= d.W;
  p.start.push_back(0);
  // Prior points: their lookups, as add_layout computes a sample's (every cell
  // a point of the domain reads lies in the projection mask; a point whose
  // cell is not an unknown is skipped).
  for (size_t v = 0; v < d.prior_w.size(); ++v) {
    const size_t e0 = p.idx.size();
    bool ok = true;
    for (const TermLayout& t : terms) {
      const Vec4& x = t.x == &d.x_wiwo ? d.prior_wiwo[v] : d.prior_halfdiff[v];
      const int R = t.proj.res;
      for (int h = 0; h < (t.reciprocal ? 2 : 1); ++h) {
        const FastProj& fp = h == 0 ? t.proj : t.conj;
        const double u = std::clamp(fp.M.row(0).dot(x) + fp.off, 0.0, double(R - 1));
        const double w = std::clamp(fp.M.row(1).dot(x) + fp.off, 0.0, double(R - 1));
        const int i = std::min(static_cast<int>(u), R - 2), j = std::min(static_cast<int>(w), R - 2);
        const int c = j * R + i;
        const double fa = u - i, fb = w - j;
        const int id[4] = {t.unk[c], t.unk[c + 1], t.unk[c + R], t.unk[c + R + 1]};
        const double bw[4] = {(1 - fa) * (1 - fb), fa * (1 - fb), (1 - fa) * fb, fa * fb};
        for (int e = 0; e < 4; ++e) {
          ok = ok && id[e] >= 0;
          p.idx.push_back(id[e]);
          p.val.push_back(bw[e]);
        }
      }
    }
    if (!ok) {
      p.idx.resize(e0);
      p.val.resize(e0);
      continue;
    }
    p.start.push_back(static_cast<int>(p.idx.size()));
    p.w.push_back(rho * d.prior_w[v]);
    p.target.push_back(mean_r);
  }
  // Texels no sample reaches.
  std::vector<double> reach(M, 0.0);
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    const int R = t.proj.res;
    for (int h = 0; h < (t.reciprocal ? 2 : 1); ++h) {
      const Lookups& lk = (*lookups[ti])[h];
      for (size_t k = 0; k < N; ++k) {
        const int c = lk.cell[k];
        const double a = lk.fa[k], b = lk.fb[k], w = d.w[k];
        reach[t.unk[c]] += w * (1 - a) * (1 - b);
        reach[t.unk[c + 1]] += w * a * (1 - b);
        reach[t.unk[c + R]] += w * (1 - a) * b;
        reach[t.unk[c + R + 1]] += w * a * b;
      }
    }
  }
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    Prior::Level lv;
    for (int i = t.first; i < t.first + t.count; ++i) {
      const double lw = rho * wbar * std::exp(-20.0 * reach[i] / wbar);
      if (!(lw > 1e-12 * wbar)) continue;
      lv.idx.push_back(i);
      lv.w.push_back(lw);
      lv.sum += lw;
    }
    if (lv.idx.size() > 1) p.levels.push_back(std::move(lv));
  }
  return p;
}

}  // namespace bf::fit
