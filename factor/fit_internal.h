// Internal to the homomorphic fit (factor/homomorphic_fit.h): the pieces the
// fit's files share. Not part of the library's public interface (tests may
// include it to check the pieces).
//
//  - fit_prepare.cpp: FitData, the term layouts and lookups, residual
//    targets, the extrapolation prior's rows.
//  - fit_assembly.cpp: the dense normal equations.
//  - fit_assembly_sparse.cpp: the sparse normal equations in compressed columns.
//  - fit_solve.cpp: one function per path (dense, sparse, reference QR).
//  - fit_objective.cpp: the rel_mse of a solution, sample by sample.
//  - homomorphic_fit.cpp: solve_joint (layout, choice of path, solution), the
//    schedule fit_homomorphic, JointPrefix.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "factor/assembly_kernels.h"
#include "factor/homomorphic_fit.h"

namespace bf::fit {

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
                std::array<Lookups, 2>& lk);

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

Workspace& workspace();

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
                      std::array<std::vector<double>, 3>& r);

// True when every fixed value is +-0 (no fixed term: the residual targets are
// g itself and need no copy). The bits below the sign are or-ed over blocks
// of 256 values (integer operations: vectorized), stopping at the first
// block with a nonzero.
bool all_zero(const std::array<std::vector<double>, 3>& fixed_values);

// sum_k w_k r_ck^2 per channel, in one pass: 4 interleaved partial sums per
// channel (sample k into k mod 4), added pairwise at the end.
void weighted_square_sums(const FitData& d, const std::array<const double*, 3>& r, double out[3]);

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
                    Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::MatrixXd> rhs);

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

// The prior's rows for the joint terms `terms` (none if
// opt.extrapolation_prior is 0).
Prior extrapolation_prior(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermLayout>& terms,
                          const std::vector<const std::array<Lookups, 2>*>& lookups, int M,
                          const FitOptions& opt);

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
void add_prior_dense(const Prior& p, Eigen::Ref<Eigen::MatrixXd> A, Eigen::MatrixXd* rhs);

using SparseUpper = Eigen::SparseMatrix<double>;  // column-major, int indices

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

CscWorkspace& csc_workspace();

// The sparse path's normal equations A y = rhs without the gauge and ridge:
// the same as the triplet assembly (B^T W B + mu L^T L + the prior's rows;
// the tests' reference) up to summation order, assembled column by
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
//    pair; column j adds row k of the blocks of each
//    cell it is corner k of (summing per sample instead, 4 visits of every
//    sample, cost 20% more a fit at 1M samples);
//  - mu L^T L (the Laplacian rows of j and of its neighbours), the prior's
//    rows through j and j's prior level.
// A column's rows are summed in a dense accumulator with a bitset of the rows
// set, read back in row order.
void assemble_sparse_csc(const FitData& d, const std::array<const double*, 3>& r,
                         const std::vector<TermLayout>& terms,
                         const std::vector<const std::array<Lookups, 2>*>& lookups, double mu,
                         const Prior& prior, int M, Csc& A, Eigen::MatrixXd& rhs);

// The system of `joint` alone (no fixed terms, the targets d.g): layouts,
// lookups (in own), prior rows and smoothing weight, as solve_joint builds
// them. Filled in place (lookups point into own). Throws
// std::invalid_argument as solve_joint does.
struct StandaloneSystem {
  std::vector<TermLayout> terms;
  std::vector<std::array<Lookups, 2>> own;
  std::vector<const std::array<Lookups, 2>*> lookups;
  int M = 0;
  Prior prior;
  double mu = 0;
  std::array<const double*, 3> r{};
};
void standalone_system(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt,
                       StandaloneSystem& sys);

// The joint system's layout: the terms in order (a JointPrefix's first, K of
// them), each term's lookups, M unknowns in all.
struct JointSystem {
  size_t K = 0;  // terms taken from the prefix
  std::vector<TermLayout> terms;
  std::vector<const std::array<Lookups, 2>*> lookups;
  int M = 0;
};

// Sample k's row of B: up to 8 (unknown, bilinear weight) entries per term
// (4 per lookup) into idx and val; returns their number.
inline int stencil(const JointSystem& sys, size_t k, int* idx, double* val) {
  int L = 0;
  for (size_t ti = 0; ti < sys.terms.size(); ++ti) {
    const TermLayout& t = sys.terms[ti];
    const int R = t.proj.res;
    for (int h = 0; h < (t.reciprocal ? 2 : 1); ++h) {
      const Lookups& lk = (*sys.lookups[ti])[h];
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
}

// What the solve paths read: the residual targets r = g - fixed per channel
// (views), sum w r^2 per channel (set when the objective is read off the
// normal equations), the smoothing weight mu and the prior's rows.
struct SolveInputs {
  std::array<const double*, 3> r{};
  double sum_wr2[3] = {0, 0, 0};
  double mu = 0;
  const Prior* prior = nullptr;
  bool exact_error = true;
};

// The paths (FitOptions::Solver). Each solves the joint system into Y (M x 3,
// one column per channel) and returns the least-squares objective read off
// the normal equations when !in.exact_error, else -1. Throw
// std::runtime_error if the normal matrix is not positive definite.
//  - Dense: the normal matrix in the thread's workspace, lower triangle, the
//    prefix's data block copied in (prefix may be null), in-place Cholesky.
double solve_dense(const FitData& d, const JointSystem& sys, const JointPrefix* prefix, const SolveInputs& in,
                   Eigen::MatrixXd& Y);
//  - Sparse: the upper triangle in compressed columns, the gauge as one pinned
//    texel per later term, CHOLMOD (or Eigen's SimplicialLLT).
double solve_sparse(const FitData& d, const JointSystem& sys, const SolveInputs& in, Eigen::MatrixXd& Y);
//  - ReferenceQR: B formed densely, Householder QR (no normal equations).
void solve_reference_qr(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                        const JointSystem& sys, const SolveInputs& in, Eigen::MatrixXd& Y);

// rel_mse of fixed + joint terms at the solution Y, sample by sample: with
// exact_error through the reconstruction's clamping (model_log_value,
// FitData::clamp_log), else the unclamped log-space residual.
double sample_rel_mse(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                      const JointSystem& sys, const Eigen::MatrixXd& Y, const FitOptions& opt, bool exact_error);

}  // namespace bf::fit

namespace bf {

// A JointPrefix's content: the known terms' layout and lookups, their block of
// the dense normal equations and the residual targets.
struct JointPrefix::Impl {
  std::vector<TermSpec> known;
  std::vector<fit::TermLayout> terms;
  std::vector<std::array<fit::Lookups, 2>> lookups;
  int M = 0;
  Eigen::MatrixXd A, rhs;  // data block of the known terms (lower triangle), M x M and M x 3
  std::array<std::vector<double>, 3> r;  // residual targets g - fixed_values, per channel
  double sum_wr2[3] = {0, 0, 0};         // sum of w r^2 per channel
};

}  // namespace bf
