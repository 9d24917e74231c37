// The reference the sparse fit's column-by-column assembly
// (fit::assemble_sparse_csc) is compared with: the same normal equations by
// the simple triplet assembly, in the tests only.
#include "sparse_reference.h"

#include <Eigen/SparseCore>
#include <algorithm>

#include "factor/assembly_kernels.h"
#include "factor/fit_internal.h"

namespace bf_test {

using namespace bf;
using namespace bf::fit;

namespace {

using SparseUpper = Eigen::SparseMatrix<double>;  // column-major, int indices

// One sample's data for the cross products of two lookups p and q: p's and
// q's cell fractions, its weight and q's cell.
struct SampleRec {
  double pa, pb, qa, qb, w;
  int cq;
};

// Buffers of the triplet assembly.
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

// The sparse normal equations A y = rhs without the gauge and ridge, by the
// simple triplet assembly (Eigen's setFromTriplets): A (M x M, upper triangle
// only, compressed with sorted rows, every diagonal entry stored) =
// B^T W B of the sample rows + mu L^T L + the prior's rows, rhs = B^T W r + the
// prior's targets, with r the residual targets g - fixed per channel.
//  - each lookup's self-products are summed per bilinear cell (kernels::cell_sums, 10
//    sums and 4x3 right-hand side sums) and emitted once per cell;
//  - each pair of lookups (p earlier than q): samples bucketed by p's cell,
//    within a bucket the 4x4 products summed per q cell (a slot table over q's
//    cells), emitted once per (p cell, q cell) pair. A reciprocal term's
//    projection/conjugate pair lands in its own diagonal block: each product
//    goes to (min, max) and the diagonal takes it twice (b b^T holds
//    s_p s_q^T + s_q s_p^T).
void assemble_triplets(const FitData& d, const std::array<const double*, 3>& r,
                     const std::vector<TermLayout>& terms,
                     const std::vector<const std::array<Lookups, 2>*>& lookups, double mu,
                     const Prior& prior, int M, SparseUpper& A, Eigen::MatrixXd& rhs) {
  const size_t N = d.size();
  const double* w = d.w.data();
  SparseWorkspace ws;
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

}  // namespace

SparseNormal reference_sparse_normal_equations(const FitData& d, const std::vector<TermSpec>& joint,
                                               const FitOptions& opt) {
  StandaloneSystem sys;
  standalone_system(d, joint, opt, sys);
  SparseNormal out;
  out.M = sys.M;
  SparseUpper A;
  assemble_triplets(d, sys.r, sys.terms, sys.lookups, sys.mu, sys.prior, sys.M, A, out.rhs);
  A.makeCompressed();
  out.p.assign(A.outerIndexPtr(), A.outerIndexPtr() + sys.M + 1);
  out.i.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  out.x.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
  return out;
}

}  // namespace bf_test
