// The homomorphic fit's dense normal equations (factor/fit_internal.h).
#include <algorithm>

#include "factor/assembly_kernels.h"
#include "factor/fit_internal.h"
#include "factor/homomorphic_fit.h"

namespace bf::fit {

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

}  // namespace bf::fit

namespace bf {

using namespace fit;

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
