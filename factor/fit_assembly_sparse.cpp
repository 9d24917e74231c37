// The homomorphic fit's sparse normal equations, assembled column by column
// in compressed storage (factor/fit_internal.h).
#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "factor/assembly_kernels.h"
#include "factor/fit_internal.h"
#include "factor/homomorphic_fit.h"

namespace bf::fit {

CscWorkspace& csc_workspace() {
  thread_local CscWorkspace ws;
  return ws;
}
namespace {

// One lookup (a term's projection, or a reciprocal term's conjugate) in the
// column-by-column assembly.
struct Sub {
  int term;
  const Lookups* lk;
  size_t cells;             // offset into ws.cells
  std::vector<int> others;  // lookups of earlier terms and this term's other lookup
  size_t start = 0, rec = 0, rec_cell = 0;  // offsets, while its term is assembled
  std::vector<size_t> pairs;                // per other lookup: offset into ws.pair_start
};

// The lookups in order, each with its per-cell sums (kernels::cell_sums) in
// ws.cells and the lookups it has cross products with.
std::vector<Sub> lookup_subs(const FitData& d, const std::array<const double*, 3>& r,
                             const std::vector<TermLayout>& terms,
                             const std::vector<const std::array<Lookups, 2>*>& lookups, CscWorkspace& ws) {
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
    kernels::cell_sums(d.size(), s.lk->cell.data(), s.lk->fa.data(), s.lk->fb.data(), d.w.data(), r[0], r[1],
                       r[2], ws.cells.data() + s.cells);
  return subs;
}

// The prior per unknown: its entries in the prior's rows (ws.prior_start,
// prior_entry, prior_row) and its level (ws.level_of).
void index_prior(const Prior& prior, int M, CscWorkspace& ws) {
  if (prior.rows() > 0) {
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
  if (!prior.levels.empty()) {
    ws.level_of.assign(M, -1);
    for (size_t l = 0; l < prior.levels.size(); ++l)
      for (const int u : prior.levels[l].idx) ws.level_of[u] = static_cast<int>(l);
  }
}

// Buckets the samples by the cell of each of term ti's lookups that has
// others (counting sort, sample order kept), with the other lookups' cells
// and fractions.
void bucket_term_samples(const FitData& d, size_t ti, int R, std::vector<Sub>& subs, CscWorkspace& ws) {
  const size_t N = d.size();
  const double* w = d.w.data();
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
}

// Per cell of each of term ti's lookups and per other lookup, the samples'
// cross products summed per cell of the other lookup (a slot table over its
// cells): one 4 x 4 block per (cell, other cell) pair, in sample order.
void sum_pair_blocks(const std::vector<TermLayout>& terms, size_t ti, int R, std::vector<Sub>& subs,
                     CscWorkspace& ws) {
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
}

// The column being assembled: a dense accumulator by row with a bitset of
// the rows set.
struct Column {
  double* acc;
  uint64_t* bits;
  void add(int row, double v) const {
    acc[row] += v;
    bits[row >> 6] |= uint64_t(1) << (row & 63);
  }
};

// Column j (texel tex of term ti): the data entries from the cells having
// tex as a corner (self products from the per-cell sums, cross products from
// the pair blocks) and j's right-hand side.
void add_data_entries(const std::vector<TermLayout>& terms, size_t ti, int tex, int j,
                      const std::vector<Sub>& subs, const CscWorkspace& ws, const Column& col,
                      Eigen::MatrixXd& rhs) {
  const TermLayout& t = terms[ti];
  const int R = t.proj.res;
  const int* unk = t.unk.data();
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
      for (int a = 0; a <= k; ++a) col.add(id[a], cs[4 * a + k]);  // Q(k, a), rows id[a] <= j
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
            if (!same || io[q] <= j) col.add(io[q], bk[q]);
        }
      }
    }
  }
}

// The Laplacian's neighbours of a texel: texels of the mask, left, right, below, above.
inline int mask_neighbours(const int* unk, int R, int tex, int* out) {
  const int tx = tex % R, ty = tex / R;
  int n = 0;
  if (tx > 0 && unk[tex - 1] >= 0) out[n++] = tex - 1;
  if (tx < R - 1 && unk[tex + 1] >= 0) out[n++] = tex + 1;
  if (ty > 0 && unk[tex - R] >= 0) out[n++] = tex - R;
  if (ty < R - 1 && unk[tex + R] >= 0) out[n++] = tex + R;
  return n;
}

// Column j's regularization: mu L^T L (row j of L: deg j at j, -1 at its
// neighbours; and the rows of its neighbours n: deg n at n, -1 at n's
// neighbours, j among them), the prior's rows through j and j's level.
void add_regularization_entries(const TermLayout& t, int tex, int j, double mu, const Prior& prior,
                                const CscWorkspace& ws, const Column& col) {
  const int R = t.proj.res;
  const int* unk = t.unk.data();
  int nj[4];
  const int degj = mask_neighbours(unk, R, tex, nj);
  if (degj > 0) {
    col.add(j, mu * degj * degj);
    for (int a = 0; a < degj; ++a) {
      if (unk[nj[a]] < j) col.add(unk[nj[a]], -mu * degj);
      int nn[4];
      const int degn = mask_neighbours(unk, R, nj[a], nn);
      if (unk[nj[a]] < j) col.add(unk[nj[a]], -mu * degn);
      for (int b = 0; b < degn; ++b)
        if (unk[nn[b]] <= j) col.add(unk[nn[b]], mu);
    }
  }
  if (prior.rows() > 0)
    for (int at = ws.prior_start[j]; at < ws.prior_start[j + 1]; ++at) {
      const int ea = ws.prior_entry[at], pr = ws.prior_row[at];
      const double va = prior.w[pr] * prior.val[ea];
      for (int eb = prior.start[pr]; eb < prior.start[pr + 1]; ++eb)
        if (prior.idx[eb] <= j) col.add(prior.idx[eb], va * prior.val[eb]);
    }
  if (!prior.levels.empty() && ws.level_of[j] >= 0) {
    const Prior::Level& lv = prior.levels[ws.level_of[j]];
    const size_t a = static_cast<size_t>(std::lower_bound(lv.idx.begin(), lv.idx.end(), j) - lv.idx.begin());
    for (size_t b = 0; b <= a; ++b) col.add(lv.idx[b], (a == b ? lv.w[a] : 0.0) - lv.w[a] * lv.w[b] / lv.sum);
  }
}

// Reads column j back in row order into A (the diagonal, always stored,
// comes last) and clears the accumulator.
void flush_column(int j, const Column& col, Csc& A) {
  double* acc = col.acc;
  uint64_t* bits = col.bits;
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

}  // namespace

void assemble_sparse_csc(const FitData& d, const std::array<const double*, 3>& r,
                         const std::vector<TermLayout>& terms,
                         const std::vector<const std::array<Lookups, 2>*>& lookups, double mu,
                         const Prior& prior, int M, Csc& A, Eigen::MatrixXd& rhs) {
  CscWorkspace& ws = csc_workspace();
  rhs.setZero(M, 3);
  std::vector<Sub> subs = lookup_subs(d, r, terms, lookups, ws);
  index_prior(prior, M, ws);
  ws.acc.assign(M, 0.0);
  ws.bits.assign((size_t(M) + 63) / 64, 0);
  const Column col{ws.acc.data(), ws.bits.data()};
  A.p.resize(size_t(M) + 1);
  A.i.clear();
  A.x.clear();
  A.p[0] = 0;
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    const int R = t.proj.res;
    bucket_term_samples(d, ti, R, subs, ws);
    sum_pair_blocks(terms, ti, R, subs, ws);
    for (int tex = 0; tex < R * R; ++tex) {
      const int j = t.unk[tex];
      if (j < 0) continue;
      add_data_entries(terms, ti, tex, j, subs, ws, col, rhs);
      add_regularization_entries(t, tex, j, mu, prior, ws, col);
      flush_column(j, col, A);
    }
  }
  // The prior's right-hand side (as add_prior_dense).
  for (size_t pr = 0; pr < prior.rows(); ++pr)
    for (int a = prior.start[pr]; a < prior.start[pr + 1]; ++a)
      for (int c = 0; c < 3; ++c) rhs(prior.idx[a], c) += prior.w[pr] * prior.val[a] * prior.target[pr][c];
}

void standalone_system(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt,
                       StandaloneSystem& sys) {
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  sys.own.resize(joint.size());
  for (size_t i = 0; i < joint.size(); ++i) {
    add_layout(d, joint[i], sys.M, sys.terms, sys.own[i]);
    sys.lookups.push_back(&sys.own[i]);
  }
  const std::array<std::vector<double>, 3> no_fixed{std::vector<double>(d.size(), 0.0),
                                                    std::vector<double>(d.size(), 0.0),
                                                    std::vector<double>(d.size(), 0.0)};
  sys.prior = extrapolation_prior(d, no_fixed, sys.terms, sys.lookups, sys.M, opt);
  sys.mu = opt.smoothing * d.W / std::max(sys.M, 1);
  sys.r = {d.g[0].data(), d.g[1].data(), d.g[2].data()};
}

}  // namespace bf::fit

namespace bf {

using namespace fit;

SparseNormal sparse_normal_equations(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt) {
  StandaloneSystem sys;
  standalone_system(d, joint, opt, sys);
  SparseNormal out;
  out.M = sys.M;
  Csc A;
  assemble_sparse_csc(d, sys.r, sys.terms, sys.lookups, sys.mu, sys.prior, sys.M, A, out.rhs);
  out.p = std::move(A.p);
  out.i = std::move(A.i);
  out.x = std::move(A.x);
  return out;
}

}  // namespace bf
