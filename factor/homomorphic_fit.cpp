// Homomorphic least-squares fit (see homomorphic_fit.h for the formulation).
#include "factor/homomorphic_fit.h"
#include "factor/assembly_kernels.h"
#include "factor/dense_kernels.h"
#include "solvers/cancel.h"
#include "solvers/option_error.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#ifdef BF_FACTOR_CHOLMOD
#include <cholmod.h>
#include <dlfcn.h>
#endif
#include <algorithm>
#include <cstring>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

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

namespace {

// A projection prepared for fast per-sample use: P pre-multiplied by the row
// scale and the affine map to texel coordinates.
struct FastProj {
  Eigen::Matrix<double, 2, 4> M;
  double off;
  int res;
  explicit FastProj(const Projection& p) : res(p.res) {
    const Eigen::Vector2d sc = p.row_scale();
    const double half = 0.5 * (p.res - 1);
    M.row(0) = p.P.row(0) * (sc[0] * half);
    M.row(1) = p.P.row(1) * (sc[1] * half);
    off = half;
  }
  Bilinear at(const Vec4& x) const {
    return bilinear(Eigen::Vector2d(M.row(0).dot(x) + off, M.row(1).dot(x) + off), res);
  }
};

struct TermLayout {
  FastProj proj, conj;
  bool reciprocal;
  const std::vector<Vec4>* x;
  std::vector<int> unk;  // texel -> unknown index, -1 outside the mask
  std::vector<uint8_t> mask;
  int first = 0, count = 0;
};

// Graph-Laplacian rows of one term's mask, accumulated as mu * L^T L.
template <class AddFn>
void laplacian_rows(const TermLayout& t, AddFn add_row) {
  const int R = t.proj.res;
  int idx[5];
  double val[5];
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < R; ++i) {
      const int c = t.unk[j * R + i];
      if (c < 0) continue;
      int n = 1;
      idx[0] = c;
      val[0] = 0.0;
      const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
      for (const auto& q : nb) {
        if (q[0] < 0 || q[0] >= R || q[1] < 0 || q[1] >= R) continue;
        const int u = t.unk[q[1] * R + q[0]];
        if (u < 0) continue;
        idx[n] = u;
        val[n] = -1.0;
        val[0] += 1.0;
        ++n;
      }
      if (n > 1) add_row(idx, val, n);
    }
}


// A term's lookups: per sample, the lower-left texel of its bilinear cell and
// the fractions (projection, and conjugate if reciprocal).
struct Lookups {
  std::vector<int> cell;           // per sample: j * res + i
  std::vector<double> fa, fb;      // per sample: fractions in [0, 1]
};

// Appends one joint term: mask (thesis 3.2.4) extended by every texel a sample
// touches, so no sample ever reads a texel that is not an unknown; unknowns
// numbered from M on.
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

// Scratch buffers of the dense path, one set per thread, reused across fits so
// that the search's inner loop does not allocate (glibc returns the large
// normal matrix to the OS with munmap at every free, and every fit then paid
// its page faults again). Only buffers whose contents are rebuilt by every fit
// live here; nothing is carried from one fit to the next.
struct Workspace {
  std::vector<double> A;                    // normal matrix, M x M column-major
  std::vector<double> cells;                // per-cell sums of one lookup (kernels::cell_sums)
  std::vector<int> corners;                 // per lookup and cell: its 4 unknowns
  std::array<std::vector<double>, 3> r;     // residual targets g - fixed, per channel (both paths)
  std::vector<std::array<Lookups, 2>> own;  // lookups of the terms not in a prefix
  // Buffers above this many doubles (32 MB) are released after the fit.
  static constexpr size_t kKeep = size_t(4) << 20;
  void trim() {
    if (A.capacity() > kKeep) std::vector<double>().swap(A);
  }
};

Workspace& workspace() {
  thread_local Workspace ws;
  return ws;
}

// Emits one lookup's per-cell sums (kernels::cell_sums' layout: Q (i, j) at
// 4 j + i, R at 16 + 4 c + v) for term t: add(i, j, v) for the 10 entries i >= j
// (corner order) of every cell's 4x4 self product, with i, j unknowns, and the
// 4 x 3 right-hand side sums into rhs. Cells no sample fell into are skipped.
template <class Add>
void scatter_cell_sums(const TermLayout& t, const double* cells, Eigen::Ref<Eigen::MatrixXd> rhs, Add add) {
  static constexpr int pairs[10][2] = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {1, 1},
                                       {2, 1}, {3, 1}, {2, 2}, {3, 2}, {3, 3}};
  const int R = t.proj.res;
  for (size_t c0 = 0; c0 < size_t(R) * R; ++c0) {
    const double* acc = cells + c0 * kernels::kCellDoubles;
    if (acc[0] == 0 && acc[5] == 0 && acc[10] == 0 && acc[15] == 0) continue;
    const int id[4] = {t.unk[c0], t.unk[c0 + 1], t.unk[c0 + R], t.unk[c0 + R + 1]};
    for (const auto& e : pairs) add(id[e[0]], id[e[1]], acc[4 * e[1] + e[0]]);
    for (int v = 0; v < 4; ++v)
      for (int c = 0; c < 3; ++c) rhs(id[v], c) += acc[16 + 4 * c + v];
  }
}

// The residual targets r_c = g_c - fixed_c of every valid sample, per channel.
void residual_targets(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                      std::array<std::vector<double>, 3>& r) {
  for (int c = 0; c < 3; ++c) {
    r[c].resize(d.size());
    for (size_t k = 0; k < d.size(); ++k) r[c][k] = d.g[c][k] - fixed_values[c][k];
  }
}

// True when every fixed value is +-0 (no fixed term: the residual targets are
// g itself and need no copy). The bits below the sign are or-ed over blocks
// of 256 values (integer operations: vectorized), stopping at the first
// block with a nonzero.
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

// sum_k w_k r_ck^2 per channel, in one pass: 4 interleaved partial sums per
// channel (sample k into k mod 4), added pairwise at the end.
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

// The data part of the dense normal equations (lower triangle of A and rhs)
// for terms first_new.. and their products with the
// earlier terms; blocks among terms before first_new are left as they are (a
// JointPrefix filled them). A's lower triangle (and, for reciprocal new terms,
// their whole diagonal block) and rhs must be zero where they are assembled.
// r: the residual targets g - fixed per channel (residual_targets).
//
// Each lookup (a term's projection, or a reciprocal term's conjugate) is
// handled in its own pass over the samples, in sample order, so every matrix
// entry receives its sums in the same order as a per-sample loop would, for
// non-reciprocal terms bit for bit:
//  - a lookup's 4x4 self-product only touches the texels of its bilinear cell,
//    so it is accumulated (10 sums, plus 4x3 right-hand side sums) per cell in
//    a small array that stays in cache and is scattered once;
//  - products of two different lookups (different terms, or a reciprocal
//    term's projection and conjugate) go straight into A (column-major, 4
//    columns x 4 rows each), through a per-cell table of the 4 unknowns.
void assemble_dense(const FitData& d, const std::array<const double*, 3>& r,
                    const std::vector<TermLayout>& terms,
                    const std::vector<const std::array<Lookups, 2>*>& lookups, size_t first_new,
                    Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::MatrixXd> rhs) {
  const size_t N = d.size();
  const double* w = d.w.data();
  double* Ad = A.data();
  const size_t MM = static_cast<size_t>(A.outerStride());
  Workspace& ws = workspace();

  // Flattened lookup list: (term, half) pairs in order, with each lookup's
  // cell -> 4 unknowns table.
  struct Sub {
    int term, half;
    const Lookups* lk;
    size_t corners;  // offset into ws.corners
  };
  std::vector<Sub> subs;
  int first_new_sub = -1;
  size_t ncorner = 0;
  for (size_t ti = 0; ti < terms.size(); ++ti)
    for (int h = 0; h < (terms[ti].reciprocal ? 2 : 1); ++h) {
      if (ti >= first_new && first_new_sub < 0) first_new_sub = static_cast<int>(subs.size());
      subs.push_back({int(ti), h, &(*lookups[ti])[h], ncorner});
      if (h == 0) ncorner += 4 * size_t(terms[ti].proj.res) * terms[ti].proj.res;
    }
  const int S = static_cast<int>(subs.size());
  if (first_new_sub < 0) first_new_sub = S;
  if (S > 1) {
    ws.corners.resize(ncorner);
    for (Sub& s : subs) {
      if (s.half == 1) {
        s.corners = subs[&s - subs.data() - 1].corners;  // same term, same table
        continue;
      }
      const TermLayout& t = terms[s.term];
      const int R = t.proj.res;
      int* cn = ws.corners.data() + s.corners;
      for (int j = 0; j + 1 < R; ++j)
        for (int i = 0; i + 1 < R; ++i) {
          const int cell = j * R + i;
          cn[4 * cell] = t.unk[cell];
          cn[4 * cell + 1] = t.unk[cell + 1];
          cn[4 * cell + 2] = t.unk[cell + R];
          cn[4 * cell + 3] = t.unk[cell + R + 1];
        }
    }
  }

  // Cross products of different lookups, pair by pair: q later than p, so for
  // different terms idx_q > idx_p (lower triangle); same-term (reciprocal)
  // pairs are folded below. Pairs with both lookups before first_new are the
  // prefix's.
  for (int p = 0; p < S; ++p)
    for (int q = std::max(p + 1, first_new_sub); q < S; ++q) {
      const Lookups& lp = *subs[p].lk;
      const Lookups& lq = *subs[q].lk;
      kernels::cross_products(N, lp.cell.data(), lp.fa.data(), lp.fb.data(), lq.cell.data(), lq.fa.data(),
                              lq.fb.data(), w, ws.corners.data() + subs[p].corners,
                              ws.corners.data() + subs[q].corners, Ad, MM);
    }
  // Fold reciprocal terms' upper-triangle entries into the lower triangle.
  // Each cross product s_p s_q^T was added once; the symmetric pair
  // s_p s_q^T + s_q s_p^T needs its diagonal twice. (So far only these
  // same-term cross products have touched the term's diagonal block.)
  for (size_t ti = first_new; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    if (!t.reciprocal) continue;
    for (int j = t.first; j < t.first + t.count; ++j) {
      A(j, j) *= 2.0;
      for (int i = t.first; i < j; ++i) {
        A(j, i) += A(i, j);
        A(i, j) = 0.0;
      }
    }
  }

  // Self-products of the new lookups, per cell.
  for (int p = first_new_sub; p < S; ++p) {
    const TermLayout& t = terms[subs[p].term];
    const int R = t.proj.res;
    ws.cells.assign(size_t(R) * R * kernels::kCellDoubles, 0.0);
    const Lookups& lk = *subs[p].lk;
    kernels::cell_sums(N, lk.cell.data(), lk.fa.data(), lk.fb.data(), w, r[0], r[1], r[2], ws.cells.data());
    // Scatter the per-cell sums into the lower triangle and the right-hand side.
    scatter_cell_sums(t, ws.cells.data(), rhs,
                      [&A](int i, int j, double v) { A(std::max(i, j), std::min(i, j)) += v; });
  }

}

// The bounded-extrapolation prior (FitOptions::extrapolation_prior, see
// homomorphic_fit.h), as weighted rows sum_r w_r (b_r . y - c_r)^2 added to the
// least-squares problem like samples:
//  - one row per prior point of d (the function there pulled toward the joint
//    terms' neutral sum, the weighted mean of the targets r), b_r its bilinear
//    lookups as for a sample, w_r = rho * d.prior_w;
//  - one row per unknown texel (b_r = e_i) with w_r = rho * wbar * exp(-q_i),
//    q_i = (weight reaching the texel through samples' bilinear weights) / wbar,
//    target its term's neutral value (first joint term: the mean target,
//    halved for a reciprocal term, which is read twice; later joint terms: 0,
//    the level the gauge gives them).
struct Prior {
  std::vector<int> start;    // row r: entries start[r] .. start[r + 1] - 1
  std::vector<int> idx;
  std::vector<double> val;
  std::vector<double> w;     // per row
  std::vector<std::array<double, 3>> target;  // per row
  // Texels no sample reaches, per joint term: sum_i w_i (y_i - ybar)^2 with
  // ybar the w-weighted mean of the same texels (a free level of the term).
  struct Level {
    std::vector<int> idx;
    std::vector<double> w;
    double sum = 0;
    double energy(const Eigen::MatrixXd& Y, int c) const {
      double s1 = 0, s2 = 0;
      for (size_t a = 0; a < idx.size(); ++a) {
        s1 += w[a] * Y(idx[a], c);
        s2 += w[a] * Y(idx[a], c) * Y(idx[a], c);
      }
      return s2 - s1 * s1 / sum;
    }
  };
  std::vector<Level> levels;
  bool on() const { return !w.empty() || !levels.empty(); }
  size_t rows() const { return w.size(); }
  // (b_r . y) for channel column y.
  double dot(size_t r, const Eigen::MatrixXd& Y, int c) const {
    double v = 0;
    for (int e = start[r]; e < start[r + 1]; ++e) v += val[e] * Y(idx[e], c);
    return v;
  }
};

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

// The least-squares objective (rel_mse, unclamped) read off the normal
// equations at their solution Y (A Y = rhs): the data residual is
// sum w r^2 - y.rhs - (the regularization's quadratic form at y), the latter
// being ridge (reg_diag |y|^2), Laplacian (mu |L y|^2), gauge (gauge(c, reg)
// adds the path's own penalty to reg) and prior (its rows w b b^T and w c b restored by
// sum_r w_r ((b_r.y)^2 - 2 c_r (b_r.y)), plus the levels' energy).
template <class Gauge>
double objective_from_solution(const FitData& d, const std::vector<TermLayout>& terms, const Prior& prior,
                               const Eigen::MatrixXd& Y, const Eigen::MatrixXd& rhs, const double sum_wr2[3],
                               double mu, double reg_diag, Gauge gauge) {
  double se = 0;
  for (int c = 0; c < 3; ++c) {
    double reg = reg_diag * Y.col(c).squaredNorm();
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        double v = 0;
        for (int a2 = 0; a2 < n; ++a2) v += lv[a2] * Y(li[a2], c);
        reg += mu * v * v;
      });
    gauge(c, reg);
    for (size_t pr = 0; pr < prior.rows(); ++pr) {
      const double by = prior.dot(pr, Y, c);
      reg += prior.w[pr] * by * (by - 2.0 * prior.target[pr][c]);
    }
    for (const Prior::Level& lv : prior.levels) reg += lv.energy(Y, c);
    se += sum_wr2[c] - Y.col(c).dot(rhs.col(c)) - reg;
  }
  return std::max(0.0, se) / (3.0 * d.W);
}

// Adds the prior to a dense normal matrix (lower triangle) and rhs.
void add_prior_dense(const Prior& p, Eigen::Ref<Eigen::MatrixXd> A, Eigen::MatrixXd* rhs) {
  for (const Prior::Level& lv : p.levels)  // Lambda - lambda lambda^T / sum(lambda)
    for (size_t a = 0; a < lv.idx.size(); ++a)
      for (size_t b = 0; b < lv.idx.size(); ++b)
        if (lv.idx[a] >= lv.idx[b]) A(lv.idx[a], lv.idx[b]) += (a == b ? lv.w[a] : 0.0) - lv.w[a] * lv.w[b] / lv.sum;
  for (size_t r = 0; r < p.rows(); ++r) {
    const double w = p.w[r];
    for (int a = p.start[r]; a < p.start[r + 1]; ++a) {
      for (int b = p.start[r]; b < p.start[r + 1]; ++b)
        if (p.idx[a] >= p.idx[b]) A(p.idx[a], p.idx[b]) += w * p.val[a] * p.val[b];
      if (rhs)
        for (int c = 0; c < 3; ++c) (*rhs)(p.idx[a], c) += w * p.val[a] * p.target[r][c];
    }
  }
}

// ---- Sparse path: the normal matrix assembled directly (no B, no sparse product).

using SparseUpper = Eigen::SparseMatrix<double>;  // column-major, int indices

// One sample's data for the cross products of two lookups p and q: p's and
// q's cell fractions, its weight and q's cell.
struct SampleRec {
  double pa, pb, qa, qb, w;
  int cq;
};

// Buffers of the triplet assembly (assemble_sparse, the tests' reference), one
// set per thread, reused across fits. Nothing is carried from one fit to the next.
struct SparseWorkspace {
  std::vector<Eigen::Triplet<double>> trip;  // (row <= col) contributions to A
  std::vector<double> cells;                 // per-cell self sums of one lookup (kernels::cell_sums)
  std::vector<int> count;                    // per cell of the earlier lookup: bucket end
  std::vector<SampleRec> rec;                // samples' data, bucketed by that cell (48 bytes per
                                             // sample, kept across fits so that a search's
                                             // fits do not allocate it again)
  std::vector<int> slot;                     // per cell of the later lookup: block slot or -1
  std::vector<int> slot_cell;                // per block slot: the later lookup's cell
  std::vector<double> blk;                   // per block slot: 16 sums
};

SparseWorkspace& sparse_workspace() {
  thread_local SparseWorkspace ws;
  return ws;
}

// The triplet assembly the sparse path used before assemble_sparse_csc, kept
// as the reference the tests compare it with (sparse_normal_equations):
// the sparse path's normal equations A y = rhs without the gauge and ridge:
// A (M x M, upper triangle only, compressed with sorted rows, every diagonal
// entry stored, hence last in its column; with CHOLMOD about 4% faster than
// the lower triangle at texture 32) =
// B^T W B of the sample rows + mu L^T L + the prior's rows, rhs = B^T W r + the
// prior's targets, with r the residual targets g - fixed per channel. Equal to
// (B^T B) of the stacked rows of the earlier implementation up to summation
// order.
//  - each lookup's self-products are summed per bilinear cell (kernels::cell_sums, 10
//    sums and 4x3 right-hand side sums) and emitted once per cell;
//  - each pair of lookups (p earlier than q): samples bucketed by p's cell,
//    within a bucket the 4x4 products summed per q cell (a slot table over q's
//    cells), emitted once per (p cell, q cell) pair. A reciprocal term's
//    projection/conjugate pair lands in its own diagonal block: each product
//    goes to (min, max) and the diagonal takes it twice (b b^T holds
//    s_p s_q^T + s_q s_p^T).
void assemble_sparse(const FitData& d, const std::array<const double*, 3>& r,
                     const std::vector<TermLayout>& terms,
                     const std::vector<const std::array<Lookups, 2>*>& lookups, double mu,
                     const Prior& prior, int M, SparseUpper& A, Eigen::MatrixXd& rhs) {
  const size_t N = d.size();
  const double* w = d.w.data();
  SparseWorkspace& ws = sparse_workspace();
  std::vector<Eigen::Triplet<double>>& trip = ws.trip;
  trip.clear();
  rhs.setZero(M, 3);
  for (int i = 0; i < M; ++i) trip.emplace_back(i, i, 0.0);  // every diagonal entry stored
  struct Sub {
    const TermLayout* t;
    const Lookups* lk;
  };
  std::vector<Sub> subs;
  for (size_t ti = 0; ti < terms.size(); ++ti)
    for (int h = 0; h < (terms[ti].reciprocal ? 2 : 1); ++h) subs.push_back({&terms[ti], &(*lookups[ti])[h]});
  const auto push = [&trip](int i, int j, double v) {
    if (i >= j) trip.emplace_back(j, i, v);
    else trip.emplace_back(i, j, v);
  };

  // Self-products, per cell.
  for (const Sub& s : subs) {
    const TermLayout& t = *s.t;
    const int R = t.proj.res;
    ws.cells.assign(size_t(R) * R * kernels::kCellDoubles, 0.0);
    kernels::cell_sums(N, s.lk->cell.data(), s.lk->fa.data(), s.lk->fb.data(), w, r[0], r[1], r[2],
                       ws.cells.data());
    scatter_cell_sums(t, ws.cells.data(), rhs, push);
  }

  // Cross products of different lookups, per (p cell, q cell) pair.
  for (size_t p = 0; p < subs.size(); ++p)
    for (size_t q = p + 1; q < subs.size(); ++q) {
      const TermLayout& tp = *subs[p].t;
      const TermLayout& tq = *subs[q].t;
      const Lookups& lp = *subs[p].lk;
      const Lookups& lq = *subs[q].lk;
      const bool same = &tp == &tq;
      const int Rp = tp.proj.res, Rq = tq.proj.res;
      // Samples bucketed by p's cell (counting sort, sample order kept): each
      // sample's data copied into its bucket in one pass in sample order, so
      // the buckets are then read sequentially (gathering by sample index
      // missed the cache on every read at 1M samples).
      ws.count.assign(size_t(Rp) * Rp + 1, 0);
      for (size_t k = 0; k < N; ++k) ++ws.count[lp.cell[k] + 1];
      for (size_t c = 1; c < ws.count.size(); ++c) ws.count[c] += ws.count[c - 1];
      ws.rec.resize(N);
      {
        const int* cp_ = lp.cell.data();
        const int* cq_ = lq.cell.data();
        const double* pa = lp.fa.data();
        const double* pb = lp.fb.data();
        const double* qa = lq.fa.data();
        const double* qb = lq.fb.data();
        SampleRec* rec = ws.rec.data();
        int* next = ws.count.data();
        for (size_t k = 0; k < N; ++k) rec[next[cp_[k]]++] = {pa[k], pb[k], qa[k], qb[k], w[k], cq_[k]};
      }
      // count[c] is now the end of bucket c (and the start of bucket c + 1).
      ws.slot.assign(size_t(Rq) * Rq, -1);
      size_t begin = 0;
      for (int cp = 0; cp < Rp * Rp; ++cp) {
        const size_t end = static_cast<size_t>(ws.count[cp]);
        if (end == begin) continue;
        int nslot = 0;
        for (size_t e = begin; e < end; ++e) {
          const SampleRec& sr = ws.rec[e];
          const int cq = sr.cq;
          int sl = ws.slot[cq];
          if (sl < 0) {
            sl = ws.slot[cq] = nslot++;
            if (ws.slot_cell.size() < size_t(nslot)) ws.slot_cell.resize(nslot);
            if (ws.blk.size() < 16 * size_t(nslot)) ws.blk.resize(16 * size_t(nslot));
            ws.slot_cell[sl] = cq;
            std::fill_n(ws.blk.data() + 16 * size_t(sl), 16, 0.0);
          }
          const double a = sr.pa, b = sr.pb, wk = sr.w;
          const double sp[4] = {wk * ((1 - a) * (1 - b)), wk * (a * (1 - b)), wk * ((1 - a) * b), wk * (a * b)};
          const double c2 = sr.qa, d2 = sr.qb;
          const double sq[4] = {(1 - c2) * (1 - d2), c2 * (1 - d2), (1 - c2) * d2, c2 * d2};
          double* bk = ws.blk.data() + 16 * size_t(sl);
          for (int a2 = 0; a2 < 4; ++a2)
            for (int b2 = 0; b2 < 4; ++b2) bk[4 * a2 + b2] += sp[a2] * sq[b2];
        }
        const int ip[4] = {tp.unk[cp], tp.unk[cp + 1], tp.unk[cp + Rp], tp.unk[cp + Rp + 1]};
        for (int sl = 0; sl < nslot; ++sl) {
          const int cq = ws.slot_cell[sl];
          ws.slot[cq] = -1;
          const int iq[4] = {tq.unk[cq], tq.unk[cq + 1], tq.unk[cq + Rq], tq.unk[cq + Rq + 1]};
          const double* bk = ws.blk.data() + 16 * size_t(sl);
          for (int a2 = 0; a2 < 4; ++a2)
            for (int b2 = 0; b2 < 4; ++b2) {
              const double v = bk[4 * a2 + b2];
              if (same && ip[a2] == iq[b2]) push(ip[a2], ip[a2], 2.0 * v);
              else push(iq[b2], ip[a2], v);
            }
        }
        begin = end;
      }
    }

  // Laplacian rows, mu L^T L.
  for (const TermLayout& t : terms)
    laplacian_rows(t, [&](const int* li, const double* lv, int n) {
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
          if (li[a] >= li[b]) trip.emplace_back(li[b], li[a], mu * lv[a] * lv[b]);
    });
  // The prior (as add_prior_dense).
  for (const Prior::Level& lv : prior.levels)  // Lambda - lambda lambda^T / sum(lambda)
    for (size_t a = 0; a < lv.idx.size(); ++a)
      for (size_t b = 0; b < lv.idx.size(); ++b)
        if (lv.idx[a] >= lv.idx[b])
          trip.emplace_back(lv.idx[b], lv.idx[a], (a == b ? lv.w[a] : 0.0) - lv.w[a] * lv.w[b] / lv.sum);
  for (size_t pr = 0; pr < prior.rows(); ++pr) {
    const double pw = prior.w[pr];
    for (int a = prior.start[pr]; a < prior.start[pr + 1]; ++a) {
      for (int b = prior.start[pr]; b < prior.start[pr + 1]; ++b)
        if (prior.idx[a] >= prior.idx[b])
          trip.emplace_back(prior.idx[b], prior.idx[a], pw * prior.val[a] * prior.val[b]);
      for (int c = 0; c < 3; ++c) rhs(prior.idx[a], c) += pw * prior.val[a] * prior.target[pr][c];
    }
  }
  A.resize(M, M);
  A.setFromTriplets(trip.begin(), trip.end());
  if (trip.capacity() > (size_t(4) << 20)) std::vector<Eigen::Triplet<double>>().swap(trip);
}

// The sparse normal matrix in compressed columns (upper triangle: column j
// holds rows i <= j, sorted, its diagonal entry always stored, hence last).
struct Csc {
  std::vector<int> p;     // M + 1 column starts
  std::vector<int> i;     // row of each entry
  std::vector<double> x;  // value of each entry
};

// Buffers of the column-by-column assembly (assemble_sparse_csc), one set per
// thread, reused across fits so that a search's fits do not allocate them
// again; nothing is carried from one fit to the next.
struct CscWorkspace {
  std::vector<double> cells;     // every lookup's per-cell sums (kernels::cell_sums), one after another
  std::vector<int> start;        // bucket starts (cells + 1) of the current term's lookups
  std::vector<int> next;         // bucket fill positions
  std::vector<double> rec;       // the current term's lookups' samples, bucketed by the lookup's
                                 // cell: w, fa, fb, then (fa, fb) of each other lookup
  std::vector<int> rec_cell;     // the same samples: the other lookups' cells
  std::vector<int> slot;         // per cell of the other lookup: its block in the current cell, or -1
  std::vector<int> pair_start;   // per (lookup, other lookup): per cell, the start of its blocks
  std::vector<int> pair_cell;    // per block: the other lookup's cell
  std::vector<double> pair_blk;  // per block: 16 sums w b_a b'_c (a: the lookup's corner, c: the other's)
  std::vector<double> acc;       // the column being assembled, by row (M)
  std::vector<uint64_t> bits;    // its rows that received a value
  std::vector<int> prior_start;  // per unknown (M + 1): its entries in the prior's rows ...
  std::vector<int> prior_entry;  // ... as indices into Prior::idx
  std::vector<int> prior_row;    // ... and their rows
  std::vector<int> level_of;     // per unknown: its Prior::levels index, or -1
  Csc A;
  std::vector<int> group, perm;  // the ordering's groups (texel_pairs) and the ordering
};

CscWorkspace& csc_workspace() {
  thread_local CscWorkspace ws;
  return ws;
}

// The sparse path's normal equations A y = rhs without the gauge and ridge:
// the same as assemble_sparse up to summation order, assembled column by
// column straight into compressed storage (no triplets, no sort). Column j, a
// texel of term t, receives (rows <= j only):
//  - the self products of each of t's lookups from the per-cell sums
//    (kernels::cell_sums) of the up to 4 cells having j as a corner, and j's
//    right-hand side from the same cells;
//  - the cross products with the lookups of earlier terms and with t's other
//    lookup (reciprocal): each of t's lookups has its samples bucketed by its
//    cell (counting sort, sample order kept) together with the other lookups'
//    cells and fractions, and per cell the 4 x 4 products w b b'^T summed per
//    cell of the other lookup (a slot table), one block per (cell, other cell)
//    pair, as assemble_sparse does; column j adds row k of the blocks of each
//    cell it is corner k of (summing per sample instead, 4 visits of every
//    sample, cost 20% more a fit at 1M samples);
//  - mu L^T L (the Laplacian rows of j and of its neighbours), the prior's
//    rows through j and j's prior level.
// A column's rows are summed in a dense accumulator with a bitset of the rows
// set, read back in row order.
void assemble_sparse_csc(const FitData& d, const std::array<const double*, 3>& r,
                         const std::vector<TermLayout>& terms,
                         const std::vector<const std::array<Lookups, 2>*>& lookups, double mu,
                         const Prior& prior, int M, Csc& A, Eigen::MatrixXd& rhs) {
  const size_t N = d.size();
  const double* w = d.w.data();
  CscWorkspace& ws = csc_workspace();
  rhs.setZero(M, 3);

  struct Sub {
    int term;
    const Lookups* lk;
    size_t cells;             // offset into ws.cells
    std::vector<int> others;  // lookups of earlier terms and this term's other lookup
    size_t start = 0, rec = 0, rec_cell = 0;  // offsets, while its term is assembled
    std::vector<size_t> pairs;                // per other lookup: offset into ws.pair_start
  };
  std::vector<Sub> subs;
  size_t ncells = 0;
  for (size_t ti = 0; ti < terms.size(); ++ti)
    for (int h = 0; h < (terms[ti].reciprocal ? 2 : 1); ++h) {
      subs.push_back({int(ti), &(*lookups[ti])[h], ncells, {}, 0, 0, 0, {}});
      ncells += size_t(terms[ti].proj.res) * terms[ti].proj.res * kernels::kCellDoubles;
    }
  for (size_t s = 0; s < subs.size(); ++s)
    for (size_t o = 0; o < subs.size(); ++o)
      if (o != s && subs[o].term <= subs[s].term) subs[s].others.push_back(int(o));
  ws.cells.assign(ncells, 0.0);
  for (const Sub& s : subs)
    kernels::cell_sums(N, s.lk->cell.data(), s.lk->fa.data(), s.lk->fb.data(), w, r[0], r[1], r[2],
                       ws.cells.data() + s.cells);

  // The prior: per unknown, its entries in the prior's rows, and its level.
  const bool has_rows = prior.rows() > 0;
  if (has_rows) {
    ws.prior_start.assign(size_t(M) + 1, 0);
    for (const int u : prior.idx) ++ws.prior_start[u + 1];
    for (int u = 0; u < M; ++u) ws.prior_start[u + 1] += ws.prior_start[u];
    ws.prior_entry.resize(prior.idx.size());
    ws.prior_row.resize(prior.idx.size());
    ws.next.assign(ws.prior_start.begin(), ws.prior_start.end() - 1);
    for (size_t pr = 0; pr < prior.rows(); ++pr)
      for (int e = prior.start[pr]; e < prior.start[pr + 1]; ++e) {
        const int at = ws.next[prior.idx[e]]++;
        ws.prior_entry[at] = e;
        ws.prior_row[at] = static_cast<int>(pr);
      }
  }
  const bool has_levels = !prior.levels.empty();
  if (has_levels) {
    ws.level_of.assign(M, -1);
    for (size_t l = 0; l < prior.levels.size(); ++l)
      for (const int u : prior.levels[l].idx) ws.level_of[u] = static_cast<int>(l);
  }

  ws.acc.assign(M, 0.0);
  ws.bits.assign((size_t(M) + 63) / 64, 0);
  double* acc = ws.acc.data();
  uint64_t* bits = ws.bits.data();
  const auto add = [acc, bits](int row, double v) {
    acc[row] += v;
    bits[row >> 6] |= uint64_t(1) << (row & 63);
  };
  A.p.resize(size_t(M) + 1);
  A.i.clear();
  A.x.clear();
  A.p[0] = 0;
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    const int R = t.proj.res;
    const int* unk = t.unk.data();

    // Bucket the samples by the cell of each of this term's lookups that has others.
    size_t nstart = 0, nrec = 0, nrec_cell = 0;
    for (Sub& s : subs) {
      if (s.term != int(ti) || s.others.empty()) continue;
      s.start = nstart;
      s.rec = nrec;
      s.rec_cell = nrec_cell;
      nstart += size_t(R) * R + 1;
      nrec += N * (3 + 2 * s.others.size());
      nrec_cell += N * s.others.size();
    }
    ws.start.assign(nstart, 0);
    ws.rec.resize(nrec);
    ws.rec_cell.resize(nrec_cell);
    for (const Sub& s : subs) {
      if (s.term != int(ti) || s.others.empty()) continue;
      int* start = ws.start.data() + s.start;
      const int* cell = s.lk->cell.data();
      for (size_t k = 0; k < N; ++k) ++start[cell[k] + 1];
      for (int c = 0; c < R * R; ++c) start[c + 1] += start[c];
      ws.next.assign(start, start + size_t(R) * R);
      const size_t no = s.others.size(), sd = 3 + 2 * no;
      double* rec = ws.rec.data() + s.rec;
      int* rec_cell = ws.rec_cell.data() + s.rec_cell;
      const double* fa = s.lk->fa.data();
      const double* fb = s.lk->fb.data();
      for (size_t k = 0; k < N; ++k) {
        const size_t e = static_cast<size_t>(ws.next[cell[k]]++);
        double* rd = rec + e * sd;
        rd[0] = w[k];
        rd[1] = fa[k];
        rd[2] = fb[k];
        for (size_t o = 0; o < no; ++o) {
          const Lookups& lo = *subs[s.others[o]].lk;
          rd[3 + 2 * o] = lo.fa[k];
          rd[4 + 2 * o] = lo.fb[k];
          rec_cell[e * no + o] = lo.cell[k];
        }
      }
    }
    // Per cell of each lookup and per other lookup, the samples' cross
    // products summed per cell of the other lookup (a slot table over its
    // cells): one 4 x 4 block per (cell, other cell) pair, in sample order.
    ws.pair_start.clear();
    ws.pair_cell.clear();
    ws.pair_blk.clear();
    for (Sub& s : subs) {
      if (s.term != int(ti) || s.others.empty()) continue;
      const int* start = ws.start.data() + s.start;
      const size_t no = s.others.size(), sd = 3 + 2 * no;
      const double* rec = ws.rec.data() + s.rec;
      const int* rec_cell = ws.rec_cell.data() + s.rec_cell;
      s.pairs.assign(no, 0);
      for (size_t o = 0; o < no; ++o) {
        const int Ro = terms[subs[s.others[o]].term].proj.res;
        s.pairs[o] = ws.pair_start.size();
        ws.slot.assign(size_t(Ro) * Ro, -1);
        ws.pair_start.push_back(static_cast<int>(ws.pair_cell.size()));
        for (int c = 0; c < R * R; ++c) {
          const size_t first = ws.pair_cell.size();
          for (int e = start[c]; e < start[c + 1]; ++e) {
            const double* rd = rec + size_t(e) * sd;
            const int co = rec_cell[size_t(e) * no + o];
            int sl = ws.slot[co];
            if (sl < 0) {
              sl = ws.slot[co] = static_cast<int>(ws.pair_cell.size() - first);
              ws.pair_cell.push_back(co);
              ws.pair_blk.resize(ws.pair_blk.size() + 16, 0.0);
            }
            const double a = rd[1], b = rd[2], wk = rd[0];
            const double sp[4] = {wk * ((1 - a) * (1 - b)), wk * (a * (1 - b)), wk * ((1 - a) * b), wk * (a * b)};
            const double a2 = rd[3 + 2 * o], b2 = rd[4 + 2 * o];
            const double sq[4] = {(1 - a2) * (1 - b2), a2 * (1 - b2), (1 - a2) * b2, a2 * b2};
            double* bk = ws.pair_blk.data() + 16 * (first + size_t(sl));
            for (int p2 = 0; p2 < 4; ++p2)
              for (int q2 = 0; q2 < 4; ++q2) bk[4 * p2 + q2] += sp[p2] * sq[q2];
          }
          for (size_t pb = first; pb < ws.pair_cell.size(); ++pb) ws.slot[ws.pair_cell[pb]] = -1;
          ws.pair_start.push_back(static_cast<int>(ws.pair_cell.size()));
        }
      }
    }

    // The Laplacian's neighbours of a texel: texels of the mask, left, right, below, above.
    const auto nbrs = [&](int tex, int* out) {
      const int tx = tex % R, ty = tex / R;
      int n = 0;
      if (tx > 0 && unk[tex - 1] >= 0) out[n++] = tex - 1;
      if (tx < R - 1 && unk[tex + 1] >= 0) out[n++] = tex + 1;
      if (ty > 0 && unk[tex - R] >= 0) out[n++] = tex - R;
      if (ty < R - 1 && unk[tex + R] >= 0) out[n++] = tex + R;
      return n;
    };

    for (int tex = 0; tex < R * R; ++tex) {
      const int j = unk[tex];
      if (j < 0) continue;
      const int x = tex % R, y = tex / R;
      for (const Sub& s : subs) {
        if (s.term != int(ti)) continue;
        const double* cells = ws.cells.data() + s.cells;
        // The cells having texel (x, y) as corner k (0: lower left, 1: lower
        // right, 2: upper left, 3: upper right).
        for (int k = 0; k < 4; ++k) {
          const int cx = x - (k & 1), cy = y - (k >> 1);
          if (cx < 0 || cy < 0 || cx > R - 2 || cy > R - 2) continue;
          const int c = cy * R + cx;
          const double* cs = cells + size_t(c) * kernels::kCellDoubles;
          if (cs[0] == 0 && cs[5] == 0 && cs[10] == 0 && cs[15] == 0) continue;  // no sample in the cell
          const int id[4] = {unk[c], unk[c + 1], unk[c + R], unk[c + R + 1]};  // increasing
          for (int a = 0; a <= k; ++a) add(id[a], cs[4 * a + k]);  // Q(k, a), rows id[a] <= j
          for (int ch = 0; ch < 3; ++ch) rhs(j, ch) += cs[16 + 4 * ch + k];
          if (s.others.empty()) continue;
          for (size_t o = 0; o < s.others.size(); ++o) {
            const TermLayout& to = terms[subs[s.others[o]].term];
            const int Ro = to.proj.res;
            const int* unko = to.unk.data();
            const bool same = &to == &t;  // rows above j possible
            const int* ps = ws.pair_start.data() + s.pairs[o];
            for (int pb = ps[c]; pb < ps[c + 1]; ++pb) {
              const int co = ws.pair_cell[pb];
              const int io[4] = {unko[co], unko[co + 1], unko[co + Ro], unko[co + Ro + 1]};
              const double* bk = ws.pair_blk.data() + 16 * size_t(pb) + 4 * k;
              for (int q = 0; q < 4; ++q)
                if (!same || io[q] <= j) add(io[q], bk[q]);
            }
          }
        }
      }
      // mu L^T L: row j of L (deg j at j, -1 at its neighbours) and the rows of
      // its neighbours n (deg n at n, -1 at n's neighbours, j among them).
      int nj[4];
      const int degj = nbrs(tex, nj);
      if (degj > 0) {
        add(j, mu * degj * degj);
        for (int a = 0; a < degj; ++a) {
          if (unk[nj[a]] < j) add(unk[nj[a]], -mu * degj);
          int nn[4];
          const int degn = nbrs(nj[a], nn);
          if (unk[nj[a]] < j) add(unk[nj[a]], -mu * degn);
          for (int b = 0; b < degn; ++b)
            if (unk[nn[b]] <= j) add(unk[nn[b]], mu);
        }
      }
      // The prior's rows through j, and j's level.
      if (has_rows)
        for (int at = ws.prior_start[j]; at < ws.prior_start[j + 1]; ++at) {
          const int ea = ws.prior_entry[at], pr = ws.prior_row[at];
          const double va = prior.w[pr] * prior.val[ea];
          for (int eb = prior.start[pr]; eb < prior.start[pr + 1]; ++eb)
            if (prior.idx[eb] <= j) add(prior.idx[eb], va * prior.val[eb]);
        }
      if (has_levels && ws.level_of[j] >= 0) {
        const Prior::Level& lv = prior.levels[ws.level_of[j]];
        const size_t a = static_cast<size_t>(std::lower_bound(lv.idx.begin(), lv.idx.end(), j) - lv.idx.begin());
        for (size_t b = 0; b <= a; ++b) add(lv.idx[b], (a == b ? lv.w[a] : 0.0) - lv.w[a] * lv.w[b] / lv.sum);
      }
      // Read the column back in row order; the diagonal, always stored, comes last.
      bits[j >> 6] |= uint64_t(1) << (j & 63);
      for (int wd = 0; wd <= (j >> 6); ++wd) {
        uint64_t m = bits[wd];
        if (!m) continue;
        bits[wd] = 0;
        while (m) {
          const int row = wd * 64 + __builtin_ctzll(m);
          m &= m - 1;
          A.i.push_back(row);
          A.x.push_back(acc[row]);
          acc[row] = 0.0;
        }
      }
      A.p[j + 1] = static_cast<int>(A.i.size());
    }
  }
  // The prior's right-hand side (as add_prior_dense).
  for (size_t pr = 0; pr < prior.rows(); ++pr)
    for (int a = prior.start[pr]; a < prior.start[pr + 1]; ++a)
      for (int c = 0; c < 3; ++c) rhs(prior.idx[a], c) += prior.w[pr] * prior.val[a] * prior.target[pr][c];
}

#ifdef BF_FACTOR_CHOLMOD
// CHOLMOD's supernodal factorization opens OpenMP parallel regions (Debian's
// build asks for 4 threads in its larger supernodes). The fits already run one
// per thread (bench, search restarts), so nested threads only add wake-ups and
// task switches (10-15% of a texture-64 fit). OpenMP's max-active-levels = 0
// makes every parallel region run on the thread that meets it. The setter is
// looked up at run time in the OpenMP runtime CHOLMOD loaded (nothing else in
// the project uses OpenMP), so the library does not link one itself.
void cholmod_serial_openmp() {
  using Setter = void (*)(int);
  static const Setter set = reinterpret_cast<Setter>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  if (set) set(0);
}

// One CHOLMOD workspace per thread, with the sparse path's settings: AMD as
// the only ordering (CHOLMOD's default also tries METIS on larger matrices:
// AMD gives less fill here and costs less, docs/speed.md), a weighted
// postorder, the supernodal LL^T kept as it is, no messages on stdout
// (failures are thrown). Only workspace lives here: every fit orders, analyses
// and factors its own matrix.
struct CholmodCommon {
  cholmod_common c;
  CholmodCommon() {
    cholmod_start(&c);
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_AMD;
    c.postorder = 1;
    c.supernodal = CHOLMOD_SUPERNODAL;
    c.final_asis = 1;
    c.print = 0;
  }
  ~CholmodCommon() { cholmod_finish(&c); }
  CholmodCommon(const CholmodCommon&) = delete;
  CholmodCommon& operator=(const CholmodCommon&) = delete;
};

// Solves A Y = rhs (A: M x M, its upper triangle in A's compressed columns)
// with CHOLMOD's supernodal Cholesky, called directly on views of A's arrays
// and of rhs (no copies; upper storage is the form cholmod_factorize permutes
// in one transpose), ordered by grouped_amd on `group` (texel_pairs). Throws
// std::runtime_error if CHOLMOD fails or A is not positive definite.
// The ordering's groups (grouped_amd): each term's texels in pairs of
// horizontal neighbours, (2 i, j) and (2 i + 1, j), the pairs of the terms one
// after another. Coupled through the Laplacian and every cell they share, the
// two texels of a pair have nearly the same neighbours, and AMD on the pairs'
// graph costs a fraction of AMD on the texels' (measured, docs/speed.md,
// "Texture 32: the sparse path, round 3": at texture 32, 1 ms instead of
// 3.2 ms, for 11% more flops in the factorization; 2 x 2 groups were as fast
// with 20% more flops, 1 x 2 groups slower). group receives each unknown's
// group (groups without unknowns stay isolated nodes); returns the number of
// groups.
int texel_pairs(const std::vector<TermLayout>& terms, int M, std::vector<int>& group) {
  group.assign(M, -1);
  int ngroups = 0;
  for (const TermLayout& t : terms) {
    const int R = t.proj.res, G = (R + 1) / 2;
    for (int tex = 0; tex < R * R; ++tex)
      if (t.unk[tex] >= 0) group[t.unk[tex]] = ngroups + (tex / R) * G + (tex % R) / 2;
    ngroups += G * R;
  }
  return ngroups;
}

// AMD on the quotient graph of `group` (per unknown: its group, 0 .. ngroups - 1):
// the groups ordered by AMD on the graph where two groups are adjacent if A
// couples any of their unknowns, each group's unknowns then in index order.
// perm receives the fill-reducing order of the M unknowns.
bool grouped_amd(const Csc& A, int M, const std::vector<int>& group, int ngroups, std::vector<int>& perm,
                 cholmod_common& cc) {
  // The quotient graph's upper triangle, one column per group: duplicates
  // dropped with a marker, rows unsorted.
  std::vector<int> count(size_t(ngroups) + 1, 0);
  for (int j = 0; j < M; ++j)
    for (int e = A.p[j]; e < A.p[j + 1]; ++e) {
      const int gi = group[A.i[e]], gj = group[j];
      if (gi != gj) ++count[std::max(gi, gj) + 1];
    }
  for (int g = 0; g < ngroups; ++g) count[g + 1] += count[g];
  std::vector<int> rows(size_t(count[ngroups]));
  std::vector<int> next(count.begin(), count.end() - 1);
  for (int j = 0; j < M; ++j)
    for (int e = A.p[j]; e < A.p[j + 1]; ++e) {
      const int gi = group[A.i[e]], gj = group[j];
      if (gi != gj) rows[next[std::max(gi, gj)]++] = std::min(gi, gj);
    }
  std::vector<int> cp(size_t(ngroups) + 1, 0), mark(ngroups, -1);
  int nz = 0;
  for (int g = 0; g < ngroups; ++g) {
    for (int e = count[g]; e < count[g + 1]; ++e)
      if (mark[rows[e]] != g) {
        mark[rows[e]] = g;
        rows[nz++] = rows[e];
      }
    cp[g + 1] = nz;
  }
  cholmod_sparse Q{};
  Q.nrow = Q.ncol = static_cast<size_t>(ngroups);
  Q.nzmax = static_cast<size_t>(std::max(nz, 1));
  Q.p = cp.data();
  Q.i = rows.data();
  Q.stype = 1;
  Q.itype = CHOLMOD_INT;
  Q.xtype = CHOLMOD_PATTERN;
  Q.dtype = CHOLMOD_DOUBLE;
  Q.sorted = 0;
  Q.packed = 1;
  std::vector<int> gperm(ngroups);
  if (!cholmod_amd(&Q, nullptr, 0, gperm.data(), &cc)) return false;
  // Each group's unknowns in index order, the groups in AMD's order.
  std::vector<int> gstart(size_t(ngroups) + 1, 0);
  for (int j = 0; j < M; ++j) ++gstart[group[j] + 1];
  for (int g = 0; g < ngroups; ++g) gstart[g + 1] += gstart[g];
  std::vector<int> members(M);
  next.assign(gstart.begin(), gstart.end() - 1);
  for (int j = 0; j < M; ++j) members[next[group[j]]++] = j;
  perm.clear();
  for (const int g : gperm)
    for (int e = gstart[g]; e < gstart[g + 1]; ++e) perm.push_back(members[e]);
  return true;
}

void cholmod_solve_upper(const Csc& A, int M, const Eigen::MatrixXd& rhs, Eigen::MatrixXd& Y,
                         const std::vector<int>& group, int ngroups) {
  cholmod_serial_openmp();
  thread_local CholmodCommon common;
  cholmod_common& cc = common.c;
  cholmod_sparse As{};
  As.nrow = As.ncol = static_cast<size_t>(M);
  As.nzmax = A.x.size();
  As.p = const_cast<int*>(A.p.data());
  As.i = const_cast<int*>(A.i.data());
  As.x = const_cast<double*>(A.x.data());
  As.stype = 1;  // upper triangle
  As.itype = CHOLMOD_INT;
  As.xtype = CHOLMOD_REAL;
  As.dtype = CHOLMOD_DOUBLE;
  As.sorted = 1;
  As.packed = 1;
  const auto failed = [&cc, M]() {
    return std::runtime_error("fit: CHOLMOD failed with status " + std::to_string(cc.status) + " (" +
                              std::to_string(M) + " unknowns)");
  };
  // The ordering: AMD on the quotient graph of `group` (grouped_amd), given to
  // CHOLMOD, which follows it with its weighted postorder; AMD on A itself if
  // that fails.
  std::vector<int>& perm = csc_workspace().perm;
  cholmod_factor* L = nullptr;
  if (grouped_amd(A, M, group, ngroups, perm, cc)) {
    cc.method[0].ordering = CHOLMOD_GIVEN;
    L = cholmod_analyze_p(&As, perm.data(), nullptr, 0, &cc);
    cc.method[0].ordering = CHOLMOD_AMD;
  } else {
    cc.status = CHOLMOD_OK;
    L = cholmod_analyze(&As, &cc);
  }
  if (!L || cc.status < 0) {
    if (L) cholmod_free_factor(&L, &cc);
    throw failed();
  }
  cholmod_factorize(&As, L, &cc);
  if (cc.status < 0) {
    cholmod_free_factor(&L, &cc);
    throw failed();
  }
  if (L->minor < L->n) {
    cholmod_free_factor(&L, &cc);
    throw std::runtime_error("fit: the normal matrix is not positive definite (" + std::to_string(M) +
                             " unknowns)");
  }
  cholmod_dense B{};
  B.nrow = static_cast<size_t>(M);
  B.ncol = static_cast<size_t>(rhs.cols());
  B.nzmax = B.nrow * B.ncol;
  B.d = B.nrow;
  B.x = const_cast<double*>(rhs.data());
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* X = cholmod_solve(CHOLMOD_A, L, &B, &cc);
  cholmod_free_factor(&L, &cc);
  if (!X || cc.status < 0) {
    if (X) cholmod_free_dense(&X, &cc);
    throw failed();
  }
  Y = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(X->x), M, rhs.cols());
  cholmod_free_dense(&X, &cc);
}
#endif

}  // namespace

struct JointPrefix::Impl {
  std::vector<TermSpec> known;
  std::vector<TermLayout> terms;
  std::vector<std::array<Lookups, 2>> lookups;
  int M = 0;
  Eigen::MatrixXd A, rhs;  // data block of the known terms (lower triangle), M x M and M x 3
  std::array<std::vector<double>, 3> r;  // residual targets g - fixed_values, per channel
  double sum_wr2[3] = {0, 0, 0};         // sum of w r^2 per channel
};

JointPrefix::JointPrefix(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                         const std::vector<TermSpec>& known, const FitOptions& opt)
    : impl_(std::make_unique<Impl>()) {
  opt.validate();
  Impl& p = *impl_;
  p.known = known;
  p.lookups.resize(known.size());
  for (size_t i = 0; i < known.size(); ++i) add_layout(d, known[i], p.M, p.terms, p.lookups[i]);
  p.A = Eigen::MatrixXd::Zero(p.M, p.M);
  p.rhs = Eigen::MatrixXd::Zero(p.M, 3);
  std::vector<const std::array<Lookups, 2>*> lp;
  for (const auto& l : p.lookups) lp.push_back(&l);
  residual_targets(d, fixed_values, p.r);
  const std::array<const double*, 3> r = {p.r[0].data(), p.r[1].data(), p.r[2].data()};
  weighted_square_sums(d, r, p.sum_wr2);
  assemble_dense(d, r, p.terms, lp, 0, p.A, p.rhs);
}

JointPrefix::~JointPrefix() = default;
size_t JointPrefix::terms() const { return impl_->known.size(); }

JointSolution solve_joint(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermSpec>& joint, const FitOptions& opt,
                          bool exact_error, const JointPrefix* prefix) {
  check_cancel();  // every fit and every search evaluation is a joint solve
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  const size_t N = d.size();

  // Layout: the prefix's terms (if any), then the others.
  size_t K = 0;  // terms taken from the prefix
  std::vector<TermLayout> terms;
  // The new terms' lookups: the thread's workspace (capacity kept across fits).
  std::vector<std::array<Lookups, 2>>& own = workspace().own;
  own.resize(joint.size());
  std::vector<const std::array<Lookups, 2>*> lookups;
  terms.reserve(joint.size());
  int M = 0;
  if (prefix) {
    const JointPrefix::Impl& p = prefix->impl();
    K = p.known.size();
    if (K >= joint.size())
      throw std::invalid_argument("fit: a prefix of " + std::to_string(K) + " terms for " +
                                  std::to_string(joint.size()) + " joint terms (expected fewer)");
    for (size_t i = 0; i < K; ++i)
      if (joint[i].proj.P != p.known[i].proj.P || joint[i].proj.res != p.known[i].proj.res ||
          joint[i].proj.param != p.known[i].proj.param || joint[i].reciprocal != p.known[i].reciprocal)
        throw std::invalid_argument("fit: joint term " + std::to_string(i + 1) +
                                    " differs from the prefix's term it should equal");
    terms = p.terms;
    for (size_t i = 0; i < K; ++i) lookups.push_back(&p.lookups[i]);
    M = p.M;
  }
  for (size_t i = K; i < joint.size(); ++i) {
    add_layout(d, joint[i], M, terms, own[i]);
    lookups.push_back(&own[i]);
  }
  // Per-sample stencils: up to 8 entries per term.
  const int maxL = 8 * static_cast<int>(terms.size());
  auto stencil = [&](size_t k, int* idx, double* val) {
    int L = 0;
    for (size_t ti = 0; ti < terms.size(); ++ti) {
      const TermLayout& t = terms[ti];
      const int R = t.proj.res;
      for (int h = 0; h < (t.reciprocal ? 2 : 1); ++h) {
        const Lookups& lk = (*lookups[ti])[h];
        const int c = lk.cell[k];
        const double a = lk.fa[k], b = lk.fb[k];
        idx[L] = t.unk[c];
        val[L++] = (1 - a) * (1 - b);
        idx[L] = t.unk[c + 1];
        val[L++] = a * (1 - b);
        idx[L] = t.unk[c + R];
        val[L++] = (1 - a) * b;
        idx[L] = t.unk[c + R + 1];
        val[L++] = a * b;
      }
    }
    return L;
  };

  const double mu = opt.smoothing * d.W / std::max(M, 1);
  const Prior prior = extrapolation_prior(d, fixed_values, terms, lookups, M, opt);
  Eigen::MatrixXd Y(M, 3);  // solution, one column per channel
  double quad_rel_mse = -1;  // set by the dense and sparse paths when !exact_error
  std::vector<int> idx(maxL);
  std::vector<double> val(maxL);

  FitOptions::Solver solver = opt.solver;
  // Auto: dense up to 1,650 unknowns, or up to 2,200 with 500,000 samples or
  // more (the sparse assembly costs more per sample); measured crossovers of
  // the staircase dense Cholesky and the pair-ordered sparse path (docs/speed.md,
  // "Dense against sparse, round 3"): 43,264 samples at about 1,640 unknowns
  // (dense faster at 1,540, equal at 1,640, slower at 1,736), 1M samples
  // between 2,046 and 2,516 (about 2,220 interpolated).
  if (solver == FitOptions::Solver::Auto)
    solver = M <= (N >= 500000 ? 2200 : 1650) ? FitOptions::Solver::Dense : FitOptions::Solver::Sparse;

  // Residual targets g - fixed (a prefix holds them) and, for the objective
  // read off the normal equations, sum w r^2 per channel: both assembled paths.
  std::array<const double*, 3> r{};
  double sum_wr2[3] = {0, 0, 0};
  if (solver != FitOptions::Solver::ReferenceQR) {
    if (K > 0) {
      for (int c = 0; c < 3; ++c) r[c] = prefix->impl().r[c].data();
      std::copy_n(prefix->impl().sum_wr2, 3, sum_wr2);
    } else {
      if (all_zero(fixed_values)) {  // r = g, sum w r^2 = FitData::wg2
        for (int c = 0; c < 3; ++c) {
          r[c] = d.g[c].data();
          sum_wr2[c] = d.wg2[c];
        }
      } else {
        residual_targets(d, fixed_values, workspace().r);
        for (int c = 0; c < 3; ++c) r[c] = workspace().r[c].data();
        if (!exact_error) weighted_square_sums(d, r, sum_wr2);
      }
    }
  }

  if (solver == FitOptions::Solver::Sparse) {
    Csc& A = csc_workspace().A;
    Eigen::MatrixXd rhs;
    assemble_sparse_csc(d, r, terms, lookups, mu, prior, M, A, rhs);
    // Each column's diagonal entry is its last (assemble_sparse_csc).
    const auto diag = [&A](int i) -> double& { return A.x[A.p[i + 1] - 1]; };
    double mean_diag = 0;
    for (int i = 0; i < M; ++i) mean_diag += diag(i);
    mean_diag /= std::max(M, 1);
    // Gauge as a soft constraint on each later term's texel mean would make the
    // matrix dense in that block; in the sparse path we pin one texel of each
    // later joint term instead (same effect: removes the constant freedom).
    for (size_t t = 1; t < terms.size(); ++t) diag(terms[t].first) += mean_diag;
    const double reg_diag = 1e-12 * mean_diag + std::numeric_limits<double>::min();
    for (int i = 0; i < M; ++i) diag(i) += reg_diag;
#ifdef BF_FACTOR_CHOLMOD
    // SuiteSparse's supernodal Cholesky (dense BLAS blocks on the supernodes),
    // AMD ordering, CHOLMOD's OpenMP regions serial (cholmod_solve_upper).
    std::vector<int>& group = csc_workspace().group;
    const int ngroups = texel_pairs(terms, M, group);
    cholmod_solve_upper(A, M, rhs, Y, group, ngroups);
#else
    const Eigen::Map<const SparseUpper> Am(M, M, static_cast<int>(A.x.size()), A.p.data(), A.i.data(),
                                           A.x.data());
    Eigen::SimplicialLLT<SparseUpper, Eigen::Upper, Eigen::AMDOrdering<int>> llt(Am);
    if (llt.info() != Eigen::Success)
      throw std::runtime_error("fit: the normal matrix is not positive definite (" +
                               std::to_string(M) + " unknowns)");
    Y = llt.solve(rhs);
#endif
    if (!exact_error) {
      // As the dense path: at the solution A y = rhs, so the data residual is
      // sum w r^2 - y.rhs - (regularization quadratic form at y); the gauge
      // here is the pinned texels' mean_diag y_i0^2.
      quad_rel_mse = objective_from_solution(d, terms, prior, Y, rhs, sum_wr2, mu, reg_diag, [&](int c, double& reg) {
        for (size_t t = 1; t < terms.size(); ++t)  // the pinned texels' mean_diag y_i0^2
          reg += mean_diag * Y(terms[t].first, c) * Y(terms[t].first, c);
      });
    }
  } else if (solver == FitOptions::Solver::Dense) {
    // The normal matrix lives in the thread's workspace (no allocation once it
    // has grown); only its lower triangle is cleared, filled and factored.
    Workspace& ws = workspace();
    ws.A.resize(size_t(M) * M);
    Eigen::Map<Eigen::MatrixXd> A(ws.A.data(), M, M);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(M, 3);
    const int pM = K > 0 ? prefix->impl().M : 0;
    for (int j = 0; j < M; ++j) {
      if (j < pM) {  // the prefix's data block
        A.col(j).segment(j, pM - j) = prefix->impl().A.col(j).segment(j, pM - j);
        A.col(j).tail(M - pM).setZero();
      } else {
        A.col(j).tail(M - j).setZero();
      }
    }
    for (size_t ti = K; ti < terms.size(); ++ti)  // assembly writes their upper triangle too
      if (terms[ti].reciprocal)
        A.block(terms[ti].first, terms[ti].first, terms[ti].count, terms[ti].count)
            .triangularView<Eigen::StrictlyUpper>()
            .setZero();
    if (K > 0) rhs.topRows(pM) = prefix->impl().rhs;
    assemble_dense(d, r, terms, lookups, K, A, rhs);
    double reg_diag = 0;  // Laplacian, gauge and ridge go into A; remember them for the objective
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        for (int a2 = 0; a2 < n; ++a2)
          for (int b2 = 0; b2 < n; ++b2)
            if (li[a2] >= li[b2]) A(li[a2], li[b2]) += mu * lv[a2] * lv[b2];
      });
    const double mean_diag = A.diagonal().sum() / std::max(M, 1);
    for (size_t t = 1; t < terms.size(); ++t) {
      const double gamma = mean_diag / terms[t].count;
      A.block(terms[t].first, terms[t].first, terms[t].count, terms[t].count)
          .triangularView<Eigen::Lower>() += Eigen::MatrixXd::Constant(terms[t].count, terms[t].count, gamma);
    }
    add_prior_dense(prior, A, &rhs);
    reg_diag = 1e-12 * mean_diag + std::numeric_limits<double>::min();
    A.diagonal().array() += reg_diag;
    // In place, one factorization for the 3 channels; the CPU's widest
    // instruction set (factor/dense_kernels.h).
    Y = rhs;
    // The first joint term's own block is banded (a sample couples the 4
    // corners of its cell, the Laplacian texels two rows apart) unless the
    // term is reciprocal (its conjugate lookups couple distant texels) or the
    // extrapolation prior's level rows couple a term's unreached texels. (A
    // single term is all head: a banded solve.)
    const bool banded_head = !terms[0].reciprocal && !prior.on();
    const bool pd = banded_head ? kernels::llt_solve_banded_head(A.data(), M, terms[0].count, Y.data(), 3)
                                : kernels::llt_solve(A.data(), M, Y.data(), 3);
    ws.trim();
    if (!pd)
      throw std::runtime_error("fit: the normal matrix is not positive definite (" +
                               std::to_string(M) + " unknowns)");
    if (!exact_error) {
      // At the solution A y = rhs, so the data residual is
      // sum w r^2 - y.rhs - (regularization quadratic form at y).
      quad_rel_mse = objective_from_solution(d, terms, prior, Y, rhs, sum_wr2, mu, reg_diag, [&](int c, double& reg) {
        for (size_t t = 1; t < terms.size(); ++t) {  // gamma (sum of the term's texels)^2
          const double sum = Y.col(c).segment(terms[t].first, terms[t].count).sum();
          reg += mean_diag / terms[t].count * sum * sum;
        }
      });
    }
  } else {
    // Reference path: form B (data rows, Laplacian rows, gauge rows) densely and
    // solve the least-squares problem by Householder QR, without normal equations.
    int lap_rows = 0;
    for (const TermLayout& t : terms) laplacian_rows(t, [&](const int*, const double*, int) { ++lap_rows; });
    int level_rows = 0;
    for (const Prior::Level& lv : prior.levels) level_rows += static_cast<int>(lv.idx.size());
    const int rows = static_cast<int>(N) + lap_rows + static_cast<int>(terms.size()) - 1 +
                     static_cast<int>(prior.rows()) + level_rows;
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(rows, M);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(rows, 3);
    for (size_t k = 0; k < N; ++k) {
      const int L = stencil(k, idx.data(), val.data());
      const double sw = std::sqrt(d.w[k]);
      for (int a = 0; a < L; ++a) B(k, idx[a]) += sw * val[a];
      for (int c = 0; c < 3; ++c) r(k, c) = sw * (d.g[c][k] - fixed_values[c][k]);
    }
    int row = static_cast<int>(N);
    const double smu = std::sqrt(mu);
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        for (int a = 0; a < n; ++a) B(row, li[a]) += smu * lv[a];
        ++row;
      });
    const double mean_diag = B.colwise().squaredNorm().sum() / std::max(M, 1);
    for (size_t t = 1; t < terms.size(); ++t) {
      const double sg = std::sqrt(mean_diag / terms[t].count);
      for (int i = 0; i < terms[t].count; ++i) B(row, terms[t].first + i) = sg;
      ++row;
    }
    for (size_t pr = 0; pr < prior.rows(); ++pr, ++row) {
      const double sl = std::sqrt(prior.w[pr]);
      for (int e = prior.start[pr]; e < prior.start[pr + 1]; ++e) B(row, prior.idx[e]) += sl * prior.val[e];
      for (int c = 0; c < 3; ++c) r(row, c) = sl * prior.target[pr][c];
    }
    for (const Prior::Level& lv : prior.levels)
      for (size_t a = 0; a < lv.idx.size(); ++a, ++row) {
        const double sw = std::sqrt(lv.w[a]);
        for (size_t b = 0; b < lv.idx.size(); ++b) B(row, lv.idx[b]) += sw * ((a == b ? 1.0 : 0.0) - lv.w[b] / lv.sum);
      }
    Y = B.colPivHouseholderQr().solve(r);
  }
  if (!Y.allFinite()) throw std::runtime_error("fit: the solution is not finite");

  // Residual: rel_mse of fixed + joint terms, with the reconstruction's clamping.
  JointSolution sol;
  sol.unknowns = static_cast<size_t>(M);
  sol.solver = solver;
  if (!exact_error && quad_rel_mse >= 0) {
    sol.rel_mse = quad_rel_mse;
  } else {
    double se = 0;
    for (size_t k = 0; k < N; ++k) {
      const int L = stencil(k, idx.data(), val.data());
      for (int c = 0; c < 3; ++c) {
        double s = fixed_values[c][k];
        for (int a = 0; a < L; ++a) s += val[a] * Y(idx[a], c);
        const double e =
            (exact_error ? model_log_value(d.clamp_log(c, s, opt), opt) : s) - d.g[c][k];
        se += d.w[k] * e * e;
      }
    }
    sol.rel_mse = se / (3.0 * d.W);
  }

  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    FactorTerm ft;
    ft.proj = joint[ti].proj;
    ft.reciprocal = joint[ti].reciprocal;
    ft.rotation = joint[ti].rotation;
    ft.mask = t.mask;
    for (int c = 0; c < 3; ++c) {
      ft.texels[c].assign(t.mask.size(), 0.0f);
      for (size_t i = 0; i < t.mask.size(); ++i)
        if (t.unk[i] >= 0) ft.texels[c][i] = static_cast<float>(Y(t.unk[i], c));
    }
    sol.terms.push_back(std::move(ft));
  }
  return sol;
}

std::shared_ptr<HomomorphicFactorization> fit_homomorphic(const FitData& d,
                                                          const std::vector<TermSpec>& terms,
                                                          const FitOptions& opt,
                                                          const std::string& method,
                                                          std::vector<double>* errors) {
  opt.validate();
  if (terms.empty()) throw std::invalid_argument("terms: expected at least 1 term, found 0");
  std::vector<FactorTerm> done;  // terms 1..j with texels (the last ones re-solved each step)
  for (size_t j = 1; j <= terms.size(); ++j) {
    const size_t first = j > static_cast<size_t>(opt.solve_last) ? j - opt.solve_last : 0;
    std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
    std::vector<TermSpec> joint(terms.begin() + first, terms.begin() + j);
    const JointSolution sol = solve_joint(d, fixed_sum(d, fixed), joint, opt);
    done = fixed;
    done.insert(done.end(), sol.terms.begin(), sol.terms.end());
    if (errors) errors->push_back(sol.rel_mse);
  }
  return std::make_shared<HomomorphicFactorization>(
      done, d.transform.A, opt.eps, opt.subtract_eps, method,
      opt.clamp_log_range ? std::optional<LogRange>(d.log_range) : std::nullopt);
}

std::vector<TermSpec> mccool_terms(int res) {
  TermSpec p{projection_first_pair(Parameterization::WiWo, res), true, std::nullopt};
  TermSpec q{projection_first_pair(Parameterization::HalfDiff, res), false, std::nullopt};
  return {p, q};
}

SparseNormal sparse_normal_equations(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt,
                                     bool reference) {
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  std::vector<TermLayout> terms;
  std::vector<std::array<Lookups, 2>> own(joint.size());
  std::vector<const std::array<Lookups, 2>*> lookups;
  int M = 0;
  for (size_t i = 0; i < joint.size(); ++i) {
    add_layout(d, joint[i], M, terms, own[i]);
    lookups.push_back(&own[i]);
  }
  const std::array<std::vector<double>, 3> no_fixed{std::vector<double>(d.size(), 0.0),
                                                    std::vector<double>(d.size(), 0.0),
                                                    std::vector<double>(d.size(), 0.0)};
  const Prior prior = extrapolation_prior(d, no_fixed, terms, lookups, M, opt);
  const double mu = opt.smoothing * d.W / std::max(M, 1);
  const std::array<const double*, 3> r = {d.g[0].data(), d.g[1].data(), d.g[2].data()};
  SparseNormal out;
  out.M = M;
  if (reference) {
    SparseUpper A;
    assemble_sparse(d, r, terms, lookups, mu, prior, M, A, out.rhs);
    A.makeCompressed();
    out.p.assign(A.outerIndexPtr(), A.outerIndexPtr() + M + 1);
    out.i.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    out.x.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
  } else {
    Csc A;
    assemble_sparse_csc(d, r, terms, lookups, mu, prior, M, A, out.rhs);
    out.p = std::move(A.p);
    out.i = std::move(A.i);
    out.x = std::move(A.x);
  }
  return out;
}

Eigen::MatrixXd joint_normal_matrix(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt,
                                    size_t max_unknowns, size_t* unknowns) {
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  std::vector<TermLayout> terms;
  std::vector<std::array<Lookups, 2>> own(joint.size());
  std::vector<const std::array<Lookups, 2>*> lookups;
  int M = 0;
  for (size_t i = 0; i < joint.size(); ++i) {
    add_layout(d, joint[i], M, terms, own[i]);
    lookups.push_back(&own[i]);
  }
  if (unknowns) *unknowns = static_cast<size_t>(M);
  if (static_cast<size_t>(M) > max_unknowns) return Eigen::MatrixXd();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(M, M), rhs = Eigen::MatrixXd::Zero(M, 3);
  assemble_dense(d, {d.g[0].data(), d.g[1].data(), d.g[2].data()}, terms, lookups, 0, A, rhs);
  const double mu = opt.smoothing * d.W / std::max(M, 1);
  for (const TermLayout& t : terms)
    laplacian_rows(t, [&](const int* li, const double* lv, int n) {
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
          if (li[a] >= li[b]) A(li[a], li[b]) += mu * lv[a] * lv[b];
    });
  const double mean_diag = A.diagonal().sum() / std::max(M, 1);
  for (size_t t = 1; t < terms.size(); ++t)
    A.block(terms[t].first, terms[t].first, terms[t].count, terms[t].count).triangularView<Eigen::Lower>() +=
        Eigen::MatrixXd::Constant(terms[t].count, terms[t].count, mean_diag / terms[t].count);
  if (opt.extrapolation_prior > 0.0) {
    const std::array<std::vector<double>, 3> no_fixed{std::vector<double>(d.size(), 0.0),
                                                      std::vector<double>(d.size(), 0.0),
                                                      std::vector<double>(d.size(), 0.0)};
    add_prior_dense(extrapolation_prior(d, no_fixed, terms, lookups, M, opt), A, nullptr);
  }
  return A.selfadjointView<Eigen::Lower>();
}

}  // namespace bf
