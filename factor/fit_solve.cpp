// The homomorphic fit's solve paths (factor/fit_internal.h): dense, sparse
// (CHOLMOD or Eigen's SimplicialLLT) and the reference QR.
#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#ifdef BF_FACTOR_CHOLMOD
#include <cholmod.h>
#include <dlfcn.h>
#endif
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "factor/dense_kernels.h"
#include "factor/fit_internal.h"

namespace bf::fit {

namespace {

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

double solve_sparse(const FitData& d, const JointSystem& sys, const SolveInputs& in, Eigen::MatrixXd& Y) {
  const std::vector<TermLayout>& terms = sys.terms;
  const int M = sys.M;
  Csc& A = csc_workspace().A;
  Eigen::MatrixXd rhs;
  assemble_sparse_csc(d, in.r, terms, sys.lookups, in.mu, *in.prior, M, A, rhs);
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
  if (in.exact_error) return -1;
  // As the dense path: at the solution A y = rhs, so the data residual is
  // sum w r^2 - y.rhs - (regularization quadratic form at y); the gauge
  // here is the pinned texels' mean_diag y_i0^2.
  return objective_from_solution(d, terms, *in.prior, Y, rhs, in.sum_wr2, in.mu, reg_diag, [&](int c, double& reg) {
    for (size_t t = 1; t < terms.size(); ++t)  // the pinned texels' mean_diag y_i0^2
      reg += mean_diag * Y(terms[t].first, c) * Y(terms[t].first, c);
  });
}

double solve_dense(const FitData& d, const JointSystem& sys, const JointPrefix* prefix, const SolveInputs& in,
                   Eigen::MatrixXd& Y) {
  const std::vector<TermLayout>& terms = sys.terms;
  const int M = sys.M;
  const size_t K = sys.K;
  const Prior& prior = *in.prior;
  const double mu = in.mu;
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
  assemble_dense(d, in.r, terms, sys.lookups, K, A, rhs);
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
  if (in.exact_error) return -1;
  // At the solution A y = rhs, so the data residual is
  // sum w r^2 - y.rhs - (regularization quadratic form at y).
  return objective_from_solution(d, terms, prior, Y, rhs, in.sum_wr2, mu, reg_diag, [&](int c, double& reg) {
    for (size_t t = 1; t < terms.size(); ++t) {  // gamma (sum of the term's texels)^2
      const double sum = Y.col(c).segment(terms[t].first, terms[t].count).sum();
      reg += mean_diag / terms[t].count * sum * sum;
    }
  });
}

void solve_reference_qr(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                        const JointSystem& sys, const SolveInputs& in, Eigen::MatrixXd& Y) {
  const std::vector<TermLayout>& terms = sys.terms;
  const int M = sys.M;
  const size_t N = d.size();
  const Prior& prior = *in.prior;
  std::vector<int> idx(8 * terms.size());
  std::vector<double> val(8 * terms.size());
  // Form B (data rows, Laplacian rows, gauge rows) densely and solve the
  // least-squares problem by Householder QR, without normal equations.
  int lap_rows = 0;
  for (const TermLayout& t : terms) laplacian_rows(t, [&](const int*, const double*, int) { ++lap_rows; });
  int level_rows = 0;
  for (const Prior::Level& lv : prior.levels) level_rows += static_cast<int>(lv.idx.size());
  const int rows = static_cast<int>(N) + lap_rows + static_cast<int>(terms.size()) - 1 +
                   static_cast<int>(prior.rows()) + level_rows;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(rows, M);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(rows, 3);
  for (size_t k = 0; k < N; ++k) {
    const int L = stencil(sys, k, idx.data(), val.data());
    const double sw = std::sqrt(d.w[k]);
    for (int a = 0; a < L; ++a) B(k, idx[a]) += sw * val[a];
    for (int c = 0; c < 3; ++c) r(k, c) = sw * (d.g[c][k] - fixed_values[c][k]);
  }
  int row = static_cast<int>(N);
  const double smu = std::sqrt(in.mu);
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

}  // namespace bf::fit
