// The structured projection search (see structured_search.h).
#include "search/structured_search.h"
#include "solvers/parallel.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "search/structure.h"

namespace bf {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// Searches of up to this many terms (per-term parameterization, final_joint)
// re-read their terms under the joint objective (Structured::reseed). Its
// subsets grow as J^2 and each round polishes up to J + 1 configurations, so
// larger searches (W1's 5 terms) skip it. Searches of 2 terms run only its
// one-term moves and the mixed pair's random restarts (kReseedRoundsTerms:
// its rounds and second start from 3).
constexpr int kReseedTerms = 4;
constexpr int kReseedRoundsTerms = 3;
// Re-seeding's pair restarts: random frames per parameterization, and how far
// above the current objective a pair's replacement may start to get them.
constexpr int kPairRestarts = 8;
constexpr double kPairRestartWithin = 3;
// The mixed pair's restarts (2 terms) run their Powell at half the search's
// texture, not below this (nor above the search's): they look for a basin,
// and the one kept is read and polished at the search's texture. W1: 22,678
// -> 19,278 fits and 0.64x the wall time, the same answer.
constexpr int kPairRestartMinTexture = 8;

struct Term {
  Rotation4 R;
  Parameterization p = Parameterization::WiWo;
};

struct Start {
  Term t;
  double value = kInf;  // objective at the start (screening)
  int index = 0;        // position in the start list (TermRecord::best_start)
};

int pidx(Parameterization p) { return p == Parameterization::WiWo ? 0 : 1; }

// 2 - |P_a P_b^T|_F^2: 0 for the same plane, 2 for orthogonal planes.
double plane_distance(const Rotation4& a, const Rotation4& b) {
  const Eigen::Matrix4d A = a.matrix(), B = b.matrix();
  return 2 - (A.leftCols<2>().transpose() * B.leftCols<2>()).squaredNorm();
}

// The same frame with its two planes exchanged (columns (0 2)(1 3): det +1).
Rotation4 swapped(const Rotation4& R) {
  const Eigen::Matrix4d Q = R.matrix();
  Eigen::Matrix4d S;
  S << Q.col(2), Q.col(3), Q.col(0), Q.col(1);
  return Rotation4::from_matrix(S);
}

// Runs fn(i) for i in [0, n) on the option's threads (solvers/parallel.h
// parallel_for_each); results by index, so independent of scheduling.
template <class Fn>
void parallel_for(size_t n, int threads, Fn fn) {
  parallel_for_each(static_cast<int64_t>(n), [&](int64_t i) { fn(static_cast<size_t>(i)); }, threads);
}

bool same_terms(const std::vector<Term>& a, const std::vector<Term>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].p != b[i].p || a[i].R.packed() != b[i].R.packed()) return false;
  return true;
}

// How many terms of a configuration read the wiwo point (its mix of parameterizations).
int wiwo_count(const std::vector<Term>& t) {
  int c = 0;
  for (const Term& x : t) c += x.p == Parameterization::WiWo;
  return c;
}

class Structured {
 public:
  Structured(const FitData& d, const SearchOptions& opt)
      : d_(d), opt_(opt), sres_(opt.search_texture_size > 0 ? opt.search_texture_size : opt.texture_size) {
    popt_[0] = opt;
    popt_[0].param = Parameterization::WiWo;
    popt_[1] = opt;
    popt_[1].param = Parameterization::HalfDiff;
    if (opt.term_param == "fixed") params_ = {opt.param};
    else params_ = {Parameterization::WiWo, Parameterization::HalfDiff};
    StructureOptions so;
    so.seed = opt_.seed;
    so.radius = structure_radius(d_.size());
    for (Parameterization p : params_) hessians_[pidx(p)] = std::make_unique<LocalHessians>(d_.points(p), d_.w, so);
  }

  SearchResult run();

 private:
  TermSpec spec(const Term& t, int res) const {
    return TermSpec{t.R.projection(t.p, res), opt_.reciprocity, t.R.packed()};
  }
  std::vector<TermSpec> specs(const std::vector<Term>& ts, int res) const {
    std::vector<TermSpec> out;
    for (const Term& t : ts) out.push_back(spec(t, res));
    return out;
  }
  // The fit schedule at the search resolution (res > 0: at res instead): its
  // error, and the texels. n: terms solved jointly (0 = the option's solve_last).
  double schedule(const std::vector<Term>& ts, std::vector<FactorTerm>* done, int n = 0, int res = 0) const;
  // n fits more, in the search's count and the term's record.
  void count_fits(int n, TermRecord* rec) {
    evaluations_ += n;
    rec->evaluations += n;
  }
  // Mean over channels of g minus the given terms' values (the residual log BRDF).
  std::vector<double> residual(const std::vector<FactorTerm>& done) const;
  // Seed plane pairs of a residual, one per allowed parameterization.
  // only: that parameterization's seed alone (if allowed).
  std::vector<std::pair<Parameterization, PlaneSplit>> seeds(const std::vector<double>& y,
                                                             const Parameterization* only = nullptr) const;
  struct Config {
    std::vector<Term> ts;
    std::vector<FactorTerm> done;  // the schedule's texels at the search resolution
    double value = kInf;
    int start = 0;                 // index of the start of the last term
  };
  // Removes the configs whose schedule failed (infinite value), keeping the order.
  static void drop_failed(std::vector<Config>& cs) {
    cs.erase(std::remove_if(cs.begin(), cs.end(), [](const Config& c) { return !std::isfinite(c.value); }),
             cs.end());
  }
  // One beam step: the configs after adding term j to each of `beam`.
  // n: terms solved jointly in this step's objective.
  // side: the previous k-term answer, extended greedily besides the beam (its
  // random starts in every allowed parameterization, Powell from its `keep` best
  // screened starts, at least one per parameterization); those extensions go to
  // side_out, not into the beam.
  std::vector<Config> step(const std::vector<Config>& beam, int j, int n, TermRecord* rec,
                           const Config* side = nullptr, std::vector<Config>* side_out = nullptr);
  // The pieces of step. A screened start: the config (index into the step's
  // parents) it extends, the start (term, value at the start), and whether it
  // was read off the residual's Hessians or guessed (not a random start).
  struct Cand {
    size_t b;
    Start s;
    bool seed;
    bool greedy = false;  // one of the greedy search's starts (a random start or a configured guess)
  };
  using Objectives = std::vector<std::array<std::unique_ptr<TermObjective>, 2>>;
  static bool distinct(const std::vector<Cand>& cands, const std::vector<size_t>& chosen, size_t i);
  // Every parent (beam, then the side config at index S) extended by every
  // start, each evaluated once; obj receives the parents' objectives.
  std::vector<Cand> screen(const std::vector<Config>& beam, size_t S, int j, int n, Objectives& obj,
                           TermRecord* rec);
  // The side config's starts to refine (order: candidates by value).
  std::vector<size_t> side_starts(const std::vector<Cand>& cands, const std::vector<size_t>& order,
                                  const std::vector<size_t>& refine, const std::vector<Config>& beam, size_t S,
                                  const Config& side) const;
  // The new beam from the refined starts (res, in refine's order) and the
  // unrefined candidates, each config's schedule run.
  std::vector<Config> next_beam(const std::vector<Config>& beam, size_t S, const std::vector<Cand>& cands,
                                const std::vector<size_t>& order, const std::vector<size_t>& refine,
                                const std::vector<PowellResult>& res, int n, TermRecord* rec);
  // Jacobi sweeps over terms [from, J): each re-searched with the others held.
  // The objective is the schedule with n terms solved jointly.
  // po: Powell's options for the re-searches.
  void polish(std::vector<Term>& ts, double& value, size_t from, int sweeps, int n, TermRecord* rec,
              const PowellOptions& po);
  // The terms re-read from the data under the joint objective (all terms
  // solved together): for every term and every pair of terms, the others'
  // textures (of the joint fit) are removed from g and that residual's seed
  // planes, in each parameterization, replace the term or the pair; the
  // replacement is read again from its own joint fit (alternating seeds and
  // fits, in that parameterization) while that lowers the objective. The best
  // replacement (and each other mix's best within 2x) is polished and the
  // lowest kept if the joint objective falls; rounds until nothing moves (at
  // most 4). The first round, and a round after one that changed a term's
  // parameterization, also restarts pairs (reseed_pair_restarts).
  // value: the joint objective of ts on return.
  void reseed(std::vector<Term>& ts, double& value, TermRecord* rec);
  // One candidate of reseed: its terms, joint objective and fits spent.
  struct Reseeded {
    std::vector<Term> ts;
    double value = kInf;
    int fits = 0;
    // false: a subset's replacement in a parameterization whose other
    // replacement is lower (reseed_keep reads it only for a mix that no
    // primary candidate has).
    bool primary = true;
  };
  // reseed's replacements of each subset (a term or a pair) of ts, whose joint
  // fit is `done` at `value`, one per subset and allowed parameterization
  // (element si * params_.size() + the parameterization's position; the
  // lower of a subset's replacements is its primary one; each
  // chain reads its own parameterization's seeds only: keeping the lower of
  // the two per subset hid every replacement that changes the mix, e.g.
  // planted mixed member 8, 3 terms, wiwo, seed 1, stayed w w w at 19.4x the
  // joint floor while its term 0 read as halfdiff, within 2x, polishes to
  // the true planes); pair_read[si][p]: the joint objective of pair si's
  // first replacement in parameterization p.
  std::vector<Reseeded> reseed_replacements(const std::vector<Term>& ts, const std::vector<FactorTerm>& done,
                                            double value, const std::vector<std::vector<size_t>>& subsets, int n,
                                            std::vector<std::array<double, 2>>& pair_read);
  // reseed's pair restarts (the first round, and a round after one that
  // changed the terms' parameterizations; see there), appended to found;
  // `round` varies the random frames.
  void reseed_pair_restarts(const std::vector<Term>& ts, double value, int round,
                            const std::vector<std::vector<size_t>>& subsets,
                            const std::vector<std::array<double, 2>>& pair_read, int n,
                            std::vector<Reseeded>& found);
  // reseed's choice among found (sorted by `order`): the candidates polished
  // and the one kept; true (ts, value updated) when the joint objective fell.
  bool reseed_keep(std::vector<Term>& ts, double& value, std::vector<Reseeded>& found,
                   const std::vector<size_t>& order, int n, const PowellOptions& fine, TermRecord* rec);
  // The full polish of a re-seeding candidate (coarse, then fine); true, and
  // ts and value set to it, if it ends below value.
  bool keep_if_lower(Reseeded& f, std::vector<Term>& ts, double& value, int n, const PowellOptions& fine,
                     TermRecord* rec);
  // After reseed's rounds (ts's joint fit is done): every term moved alone,
  // by Powell on that term under the joint objective with the others held.
  // refit = false: to the other parameterization, from the joint fit's
  // residual's seed there (both planes of its split read, the lower kept);
  // one run per term. refit = true: from the residual of the others refit
  // without the term, every plane of its split in both parameterizations;
  // four runs per term. The lowest, if below now (by 1% when refit), gets
  // the full polish and is kept if it stays lower; true (ts, value updated)
  // then.
  // A term in the wrong parameterization on a wrong plane reads far above
  // now at its seed, before its plane settles (planted mixed member 7, 3
  // terms, halfdiff, seed 1: the wrong halfdiff term read as wiwo seeds at
  // 0.027-0.030, 5x now, so reseed_keep's within-2x rule never polished it,
  // and Powell from that seed reaches the true wiwo plane at 0.0013). The
  // joint fit's residual still carries the wrong term's textures' partners
  // (the others adapted to it); with the others refit without it, a seed
  // the lowest one is not reaches the true plane (member 7, halfdiff, seed 3:
  // the other plane of that split, 12.4x -> 0.61x; member 5, wiwo, seed 2,
  // the halfdiff term in halfdiff: 12.0x -> 0.67x).
  bool reseed_switch(std::vector<Term>& ts, const std::vector<FactorTerm>& done, double& value, int n,
                     const PowellOptions& fine, TermRecord* rec, bool refit);
  // Two terms, after the one-term moves: kPairRestarts random pairs of
  // rotations, the first term in wiwo and the second in halfdiff, and as
  // many in the answer's own mix when its two terms share a
  // parameterization; each searched by Powell on both rotations at once
  // (powell_minimize_joint) under the joint objective at a coarser texture
  // (kPairRestartMinTexture). The lowest, read at the search's texture, if
  // below value, gets the full polish and is kept if it stays lower; true
  // (ts, value updated) then.
  // A one-term move cannot leave an answer whose two planes are both wrong:
  // planted mixed pair member 1 (halfdiff first, 16^4 grid) ended at w w,
  // 55-64x the joint floor, at search seeds 1-3, and member 6 (wiwo first,
  // seed 2) at w h on two wrong planes, 21x; 3 and 5 of the 8 random pairs
  // reach the true planes (0.80x and 0.81x). The answer's own mix: Cole's
  // Cook-Torrance as a MERL table (2 terms, searched on 100,000 of its
  // 2,967,974 samples) ended at h h 0.0802 at search seeds 1-3, where the
  // search on every sample found h h 0.0580; 8 random h h pairs reach 0.0582.
  bool reseed_mixed_pair(std::vector<Term>& ts, double& value, int n, const PowellOptions& fine, TermRecord* rec);
  // reseed() of the polished answer ts and, again, of the best beam
  // configuration other than polish_start (the configuration the polish
  // started from); ts becomes the one whose refit at texture_size is
  // lower, and value its objective under n terms solved jointly when it moved.
  void reseed_answer(std::vector<Term>& ts, double& value, int n, const std::vector<Config>& beam,
                     const std::vector<Term>& polish_start, TermRecord* rec);
  // A k-term answer: its terms, their refit at texture_size and its error.
  struct Answer {
    std::vector<Term> ts;
    std::shared_ptr<HomomorphicFactorization> f;
    double error = kInf;
  };
  // The joint refit at texture_size: every term solved together (the
  // schedule's solution is one point of that problem, so its least-squares
  // error is never higher); errors after each term to *errors.
  std::shared_ptr<HomomorphicFactorization> refit(const std::vector<Term>& ts, std::vector<double>* errors) const;
  // refit() as an Answer (f null and error infinite when the solve fails).
  Answer answer_of(const std::vector<Term>& ts) const;
  // The k-term answers of out (k = 1..J) from the final configuration ts and
  // each stage's best; returns the J-term answer's terms.
  std::vector<Term> fill_answers(const std::vector<Term>& ts, const std::vector<Answer>& stage_best,
                                 SearchResult& out);

  const FitData& d_;
  const SearchOptions& opt_;
  int sres_;
  SearchOptions popt_[2];
  std::vector<Parameterization> params_;
  // The Hessian estimator of each allowed parameterization's points (seeds()).
  std::array<std::unique_ptr<LocalHessians>, 2> hessians_;
  int evaluations_ = 0;
  const int polish_sweeps_ = effective_polish_sweeps(opt_);
  const int beam_width_ = effective_beam_width(opt_);
};

double Structured::schedule(const std::vector<Term>& ts, std::vector<FactorTerm>* done_out, int n, int res) const {
  FitOptions fo = opt_.fit;
  if (n > 0) fo.solve_last = n;
  n = fo.solve_last;
  const std::vector<TermSpec> sp = specs(ts, res > 0 ? res : sres_);
  std::vector<FactorTerm> done;
  double value = kInf;
  // With every term solved jointly the last step re-solves all of them, so
  // the earlier steps (whose texels it replaces) are skipped.
  const size_t s0 = static_cast<size_t>(n) >= sp.size() && !sp.empty() ? sp.size() - 1 : 0;
  for (size_t s = s0; s < sp.size(); ++s) {
    const size_t first = first_joint(s, n);
    std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
    std::vector<TermSpec> joint(sp.begin() + first, sp.begin() + s + 1);
    try {
      const JointSolution sol = solve_joint(d_, fixed_sum(d_, fixed), joint, fo, false);
      done = fixed;
      done.insert(done.end(), sol.terms.begin(), sol.terms.end());
      value = sol.rel_mse;
    } catch (const std::runtime_error&) {
      if (done_out) done_out->clear();
      return kInf;
    }
  }
  if (done_out) *done_out = std::move(done);
  return value;
}

std::vector<double> Structured::residual(const std::vector<FactorTerm>& done) const {
  const auto f = fixed_sum(d_, done);
  std::vector<double> y(d_.size());
  for (size_t k = 0; k < y.size(); ++k)
    y[k] = ((d_.g[0][k] - f[0][k]) + (d_.g[1][k] - f[1][k]) + (d_.g[2][k] - f[2][k])) / 3;
  return y;
}

std::vector<std::pair<Parameterization, PlaneSplit>> Structured::seeds(const std::vector<double>& y,
                                                                       const Parameterization* only) const {
  std::vector<std::pair<Parameterization, PlaneSplit>> out;
  for (Parameterization p : params_) {
    if (only && p != *only) continue;
    const std::vector<Eigen::Matrix4d> hs = (*hessians_[pidx(p)])(y);
    if (hs.empty()) continue;
    out.emplace_back(p, split_planes(hs));
  }
  return out;
}

// Whether candidate i is finite and not within 0.02 (plane distance) of a
// chosen candidate extending the same config in the same parameterization.
bool Structured::distinct(const std::vector<Cand>& cands, const std::vector<size_t>& chosen, size_t i) {
  for (size_t k : chosen)
    if (cands[k].b == cands[i].b && cands[k].s.t.p == cands[i].s.t.p &&
        plane_distance(cands[k].s.t.R, cands[i].s.t.R) < 0.02)
      return false;
  return std::isfinite(cands[i].s.value);
}

std::vector<Structured::Cand> Structured::screen(const std::vector<Config>& beam, size_t S, int j, int n,
                                                 Objectives& obj, TermRecord* rec) {
  std::vector<Cand> cands;
  // The configs' seed planes, in parallel (independent; results by index).
  std::vector<std::vector<std::pair<Parameterization, PlaneSplit>>> seed_of(beam.size());
  parallel_for(beam.size(), opt_.threads, [&](size_t b) { seed_of[b] = seeds(residual(beam[b].done)); });
  // Each parent's objectives (its fixed terms' sum and prefix), in parallel.
  parallel_for(beam.size() * params_.size(), opt_.threads, [&](size_t k) {
    const size_t b = k / params_.size();
    const Parameterization p = params_[k % params_.size()];
    const Config& c = beam[b];
    const size_t first = first_joint(j, n);
    const std::vector<FactorTerm> fixed(c.done.begin(), c.done.begin() + first);
    std::vector<TermSpec> known;
    for (size_t i = first; i < static_cast<size_t>(j); ++i) known.push_back(spec(c.ts[i], sres_));
    obj[b][pidx(p)] = std::make_unique<TermObjective>(d_, fixed, known, popt_[pidx(p)], sres_);
  });
  for (size_t b = 0; b < beam.size(); ++b) {
    int index = 0;
    auto add = [&](const Rotation4& R, Parameterization p, bool seed, bool greedy = false) {
      cands.push_back(Cand{b, Start{Term{R, p}, kInf, index++}, seed, greedy});
    };
    for (const auto& [p, sp] : seed_of[b]) {
      add(sp.first, p, true);
      add(sp.second, p, true);
    }
    std::vector<std::string> guesses = {"wi", "wo"};
    for (const std::string& g : opt_.guesses)
      if (std::find(guesses.begin(), guesses.end(), g) == guesses.end()) guesses.push_back(g);
    for (Parameterization p : params_)
      for (const std::string& g : guesses)
        add(guess_rotation(g), p, true,
            std::find(opt_.guesses.begin(), opt_.guesses.end(), g) != opt_.guesses.end());
    for (int r = 0; r < opt_.restarts; ++r) {
      std::mt19937_64 rng(opt_.seed * 1000003ull + j * 7919ull + r);
      const Rotation4 R = Rotation4::random(rng);
      if (b < S) add(R, params_[r % params_.size()], false, true);
      else
        for (Parameterization p : params_) add(R, p, false, true);  // the greedy search's starts, in each parameterization
    }
  }
  parallel_for(cands.size(), opt_.threads, [&](size_t i) {
    Cand& c = cands[i];
    c.s.value = (*obj[c.b][pidx(c.s.t.p)])(c.s.t.R);
  });
  count_fits(static_cast<int>(cands.size()), rec);
  return cands;
}

std::vector<size_t> Structured::side_starts(const std::vector<Cand>& cands, const std::vector<size_t>& order,
                                            const std::vector<size_t>& refine, const std::vector<Config>& beam,
                                            size_t S, const Config& side) const {
  // The side's `keep` Powell runs: the best screened start of each
  // parameterization, then the best others. A start the beam already refines
  // from the same configuration counts as run (its result is in the beam).
  std::vector<size_t> side_refine;
  size_t twin = S;
  for (size_t b = 0; b < S && twin == S; ++b) {
    bool same = beam[b].ts.size() == side.ts.size();
    for (size_t i = 0; same && i < side.ts.size(); ++i)
      same = beam[b].ts[i].p == side.ts[i].p && plane_distance(beam[b].ts[i].R, side.ts[i].R) < 1e-9;
    if (same) twin = b;
  }
  std::vector<size_t> covered;  // side starts chosen, run or not
  const auto choose = [&](size_t i) {
    if (!distinct(cands, covered, i)) return;
    covered.push_back(i);
    for (size_t k : refine)
      if (cands[k].b == twin && cands[k].s.t.p == cands[i].s.t.p &&
          plane_distance(cands[k].s.t.R, cands[i].s.t.R) < 0.02)
        return;
    side_refine.push_back(i);
  };
  // The first term: Powell from every one of the greedy search's own starts
  // (its random starts and configured guesses, in its parameterization), so
  // the 1-term answer is never worse than the greedy search's with the same
  // seed, restarts and parameterization (one-term searches are cheap).
  if (side.ts.empty())
    for (size_t i : order)
      if (cands[i].b == S && cands[i].greedy && cands[i].s.t.p == opt_.param) choose(i);
  for (Parameterization p : params_)
    for (size_t i : order)
      if (cands[i].b == S && cands[i].s.t.p == p && distinct(cands, covered, i)) {
        choose(i);
        break;
      }
  for (size_t i : order)
    if (cands[i].b == S && static_cast<int>(covered.size()) < opt_.keep) choose(i);
  return side_refine;
}

std::vector<Structured::Config> Structured::next_beam(const std::vector<Config>& beam, size_t S,
                                                      const std::vector<Cand>& cands,
                                                      const std::vector<size_t>& order,
                                                      const std::vector<size_t>& refine,
                                                      const std::vector<PowellResult>& res, int n, TermRecord* rec) {
  // New beam: refined configs first (best ceil(B/2)), then unrefined seed
  // configs (the planes read off the data, kept even when a single term
  // refined elsewhere fits better: the trap of the greedy search), then
  // anything else, by value.
  struct Next {
    size_t b;
    Term t;
    double value;
    int start;
  };
  std::vector<Next> refined, seeds_next, others;
  for (size_t k = 0; k < refine.size(); ++k)
    refined.push_back({cands[refine[k]].b, Term{res[k].best.normalized(), cands[refine[k]].s.t.p}, res[k].value,
                       cands[refine[k]].s.index});
  std::stable_sort(refined.begin(), refined.end(), [](const Next& a, const Next& b) { return a.value < b.value; });
  std::vector<size_t> taken_seeds;
  for (size_t i : order) {
    if (cands[i].b >= S || !distinct(cands, taken_seeds, i)) continue;
    taken_seeds.push_back(i);
    (cands[i].seed ? seeds_next : others).push_back({cands[i].b, cands[i].s.t, cands[i].s.value, cands[i].s.index});
  }
  const size_t B = static_cast<size_t>(beam_width_);
  std::vector<Next> chosen;
  // A configuration already chosen (same parameterizations, same planes in
  // order, whatever start or parent it came from) is not taken twice.
  const auto same = [&](const Next& x, const Next& y) {
    const std::vector<Term>&tx = beam[x.b].ts, &ty = beam[y.b].ts;
    if (x.t.p != y.t.p || plane_distance(x.t.R, y.t.R) >= 0.02) return false;
    for (size_t i = 0; i < tx.size(); ++i)
      if (tx[i].p != ty[i].p || plane_distance(tx[i].R, ty[i].R) >= 0.02) return false;
    return true;
  };
  const auto take = [&](const Next& x, size_t limit) {
    if (chosen.size() >= limit) return;
    for (const Next& c : chosen)
      if (same(c, x)) return;
    chosen.push_back(x);
  };
  for (const Next& x : refined) take(x, (B + 1) / 2);
  // Every parent configuration (best first) keeps its best seed or guess
  // extension, so a good partial configuration is not crowded out by the
  // extensions of another one.
  for (size_t b = 0; b < S; ++b)
    for (const Next& x : seeds_next)
      if (x.b == b) {
        take(x, B);
        break;
      }
  for (const Next& x : seeds_next) take(x, B);
  for (const Next& x : refined) take(x, B);
  for (const Next& x : others) take(x, B);
  std::vector<Config> out(chosen.size());
  parallel_for(chosen.size(), opt_.threads, [&](size_t k) {
    Config& c = out[k];
    c.ts = beam[chosen[k].b].ts;
    c.ts.push_back(chosen[k].t);
    c.value = schedule(c.ts, &c.done, n);
    c.start = chosen[k].start;
  });
  count_fits(static_cast<int>(chosen.size()), rec);
  drop_failed(out);
  std::stable_sort(out.begin(), out.end(), [](const Config& a, const Config& b) { return a.value < b.value; });
  return out;
}

// One step of the beam: every config extended by every screened start; Powell
// from the `keep` best distinct (config, start) pairs; the new beam is the best
// refined configs plus the best unrefined seed configs (see the header).
std::vector<Structured::Config> Structured::step(const std::vector<Config>& beam_in, int j, int n, TermRecord* rec,
                                                 const Config* side, std::vector<Config>* side_out) {
  const double t0 = now_seconds();
  // The parents: the beam, then the side configuration (index S) if any.
  const size_t S = beam_in.size();
  std::vector<Config> beam = beam_in;
  if (side) beam.push_back(*side);
  // Objectives per (config, parameterization); built once, shared by threads.
  Objectives obj(beam.size());
  const std::vector<Cand> cands = screen(beam, S, j, n, obj, rec);

  std::vector<size_t> order(cands.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return cands[a].s.value < cands[b].s.value; });
  std::vector<size_t> refine, side_refine;
  for (size_t i : order)
    if (cands[i].b < S && static_cast<int>(refine.size()) < opt_.keep && distinct(cands, refine, i))
      refine.push_back(i);
  if (side) side_refine = side_starts(cands, order, refine, beam, S, *side);
  const size_t nb = refine.size();
  refine.insert(refine.end(), side_refine.begin(), side_refine.end());
  std::vector<PowellResult> res(refine.size());
  // The side's runs start first: they begin from random starts and guesses
  // and run longer than the beam's (W1, 5 terms: the longest run of each step
  // is a side run, up to 3x the beam's), so starting them last left one
  // thread idle for most of the longest one. Results by index: the order of
  // execution changes no answer.
  std::vector<size_t> run_order;
  for (size_t k = nb; k < refine.size(); ++k) run_order.push_back(k);
  for (size_t k = 0; k < nb; ++k) run_order.push_back(k);
  parallel_for(run_order.size(), opt_.threads, [&](size_t i) {
    const size_t k = run_order[i];
    const Cand& c = cands[refine[k]];
    res[k] = powell_minimize(std::cref(*obj[c.b][pidx(c.s.t.p)]), c.s.t.R, opt_.powell);
  });
  for (const PowellResult& r : res) count_fits(r.evaluations, rec);
  if (side_out) {
    side_out->assign(refine.size() - nb, Config{});
    parallel_for(refine.size() - nb, opt_.threads, [&](size_t i) {
      const size_t k = nb + i;
      Config& c = (*side_out)[i];
      c.ts = side->ts;
      c.ts.push_back(Term{res[k].best.normalized(), cands[refine[k]].s.t.p});
      c.value = schedule(c.ts, &c.done, n);
      c.start = cands[refine[k]].s.index;
    });
    count_fits(static_cast<int>(refine.size() - nb), rec);
    drop_failed(*side_out);
  }
  refine.resize(nb);
  res.resize(nb);
  std::vector<Config> out = next_beam(beam, S, cands, order, refine, res, n, rec);
  rec->seconds += now_seconds() - t0;
  return out;
}

void Structured::polish(std::vector<Term>& ts, double& value, size_t from, int sweeps, int n, TermRecord* rec,
                        const PowellOptions& powell) {
  const double t0 = now_seconds();
  const size_t J = ts.size();
  SearchOptions po[2] = {popt_[0], popt_[1]};
  po[0].fit.solve_last = po[1].fit.solve_last = n;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    // Each term re-searched from its rotation with the others held (in parallel).
    const std::vector<TermSpec> sp = specs(ts, sres_);
    std::vector<PowellResult> res(J);
    parallel_for(J - from, opt_.threads, [&](size_t k) {
      const size_t i = from + k;
      if (static_cast<size_t>(n) >= J) {
        // All terms joint: the objective is one solve with term i last, so the
        // other terms' part of the normal matrix is built once (TermObjective).
        std::vector<TermSpec> others;
        for (size_t k2 = 0; k2 < J; ++k2)
          if (k2 != i) others.push_back(sp[k2]);
        const TermObjective objective(d_, {}, others, po[pidx(ts[i].p)], sres_);
        res[i] = powell_minimize(std::cref(objective), ts[i].R, powell);
      } else {
        const ScheduleObjective objective(d_, sp, i, po[pidx(ts[i].p)], sres_);
        res[i] = powell_minimize(std::cref(objective), ts[i].R, powell);
      }
    });
    std::vector<size_t> order;
    for (size_t i = from; i < J; ++i) {
      evaluations_ += res[i].evaluations;
      rec->backfit_evaluations += res[i].evaluations;
      if (res[i].value < value * (1 - 1e-9)) order.push_back(i);
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return res[a].value < res[b].value; });
    bool moved = false;
    for (size_t i : order) {  // best move first; each checked on the current schedule
      std::vector<Term> trial = ts;
      trial[i].R = res[i].best.normalized();
      const double v = schedule(trial, nullptr, n);
      ++evaluations_;
      ++rec->backfit_evaluations;
      if (v < value * (1 - 1e-9)) {
        ts = std::move(trial);
        value = v;
        moved = true;
        ++rec->backfit_moves;
      }
    }
    if (!moved) break;
  }
  rec->seconds += now_seconds() - t0;
}

std::vector<Structured::Reseeded> Structured::reseed_replacements(
    const std::vector<Term>& ts, const std::vector<FactorTerm>& done, double value,
    const std::vector<std::vector<size_t>>& subsets, int n, std::vector<std::array<double, 2>>& pair_read) {
  const size_t J = ts.size(), P = params_.size();
  std::vector<Reseeded> found(subsets.size() * P);
  pair_read.assign(subsets.size(), {kInf, kInf});
  parallel_for(found.size(), opt_.threads, [&](size_t q) {
    const size_t si = q / P;
    const Parameterization only = params_[q % P];
    const std::vector<size_t>& S = subsets[si];
    Reseeded& f = found[q];
    std::vector<Term> cur = ts;
    std::vector<FactorTerm> cdone = done;
    double cv = value;
    for (int it = 0; it < 3; ++it) {
      std::vector<FactorTerm> others;
      for (size_t i = 0; i < J; ++i)
        if (std::find(S.begin(), S.end(), i) == S.end()) others.push_back(cdone[i]);
      std::vector<Term> best_ts;
      std::vector<FactorTerm> best_done;
      double best = kInf;
      for (const auto& [p, sp] : seeds(residual(others), &only)) {
        std::vector<std::vector<Term>> trials;
        if (S.size() == 2) {
          trials.push_back(cur);
          trials.back()[S[0]] = Term{sp.first, p};
          trials.back()[S[1]] = Term{sp.second, p};
        } else {
          trials.push_back(cur);
          trials.back()[S[0]] = Term{sp.first, p};
          trials.push_back(cur);
          trials.back()[S[0]] = Term{sp.second, p};
        }
        for (std::vector<Term>& t : trials) {
          std::vector<FactorTerm> td;
          const double v = schedule(t, &td, n);
          ++f.fits;
          if (it == 0 && S.size() == 2) pair_read[si][pidx(p)] = v;
          if (v < best) {
            best = v;
            best_ts = std::move(t);
            best_done = std::move(td);
          }
        }
      }
      if (it > 0 && !(best < cv * (1 - 1e-6))) break;
      cur = std::move(best_ts);
      cdone = std::move(best_done);
      cv = best;
      if (!std::isfinite(cv)) break;
    }
    f.ts = cur;
    f.value = cv;
  });
  for (size_t si = 0; si < subsets.size(); ++si) {
    size_t low = si * P;
    for (size_t q = si * P + 1; q < (si + 1) * P; ++q)
      if (found[q].value < found[low].value) low = q;
    for (size_t q = si * P; q < (si + 1) * P; ++q) found[q].primary = q == low;
  }
  return found;
}

// Pair restarts (the first round, and every round after one that changed
// some term's parameterization): two terms of one parameterization may sit
// in a mixed local minimum (each plane part of both true planes) that no
// move of one term, and no Powell over their common frame from the
// current pair or from the residual's split, leaves (planted mixed member
// 1, halfdiff). In each parameterization p, the pair whose replacement by
// the residual's split in p is lowest (within kPairRestartWithin of now)
// is searched as one frame (plane A and its orthogonal complement) under
// the joint objective from kPairRestarts random frames; the results
// compete with the replacements below. The screened value of a random
// frame does not predict which one reaches the true pair (measured), so
// every start gets a Powell run.
void Structured::reseed_pair_restarts(const std::vector<Term>& ts, double value, int round,
                                      const std::vector<std::vector<size_t>>& subsets,
                                      const std::vector<std::array<double, 2>>& pair_read, int n,
                                      std::vector<Reseeded>& found) {
  const size_t J = ts.size();
  constexpr size_t kNone = std::numeric_limits<size_t>::max();
  struct PairStart {
    size_t i, k;
    Parameterization p;
    Rotation4 R;
    const std::vector<Term>* base;
  };
  // Powell from each start; the results join `found`.
  const auto run_pairs = [&](const std::vector<PairStart>& starts) {
    std::vector<Reseeded> pf(starts.size());
    parallel_for(starts.size(), opt_.threads, [&](size_t q) {
      const PairStart& st = starts[q];
      const auto with = [&](const Rotation4& R) {
        std::vector<Term> t = *st.base;
        t[st.i] = Term{R, st.p};
        t[st.k] = Term{swapped(R), st.p};
        return t;
      };
      const auto objective = [&](const Rotation4& R) { return schedule(with(R.normalized()), nullptr, n); };
      const PowellResult r = powell_minimize(objective, st.R, opt_.powell);
      pf[q].ts = with(r.best.normalized());
      pf[q].value = r.value;
      pf[q].fits = r.evaluations;
    });
    size_t best = kNone;
    for (const Reseeded& f : pf) {
      found.push_back(f);
      if (std::isfinite(f.value) && (best == kNone || f.value < found[best].value)) best = found.size() - 1;
    }
    return best;  // the lowest result's index in found (kNone if none)
  };
  std::vector<size_t> picks(2, subsets.size());
  std::vector<PairStart> starts;
  for (Parameterization p : params_) {
    size_t& pick = picks[pidx(p)];
    for (size_t si = 0; si < subsets.size(); ++si)
      if (subsets[si].size() == 2 && pair_read[si][pidx(p)] < kPairRestartWithin * value &&
          (pick == subsets.size() || pair_read[si][pidx(p)] < pair_read[pick][pidx(p)]))
        pick = si;
    if (pick == subsets.size()) continue;
    std::mt19937_64 rng(opt_.seed * 1000003ull + 0x9a17ull + pidx(p) + 0x100ull * round);
    for (int r = 0; r < kPairRestarts; ++r)
      starts.push_back({subsets[pick][0], subsets[pick][1], p, Rotation4::random(rng), &ts});
  }
  const size_t first = found.size();
  const size_t best = run_pairs(starts);
  // Four terms, two disjoint pairs (one per parameterization): when one
  // pair is wrong the other pair's restarts cannot reach its true planes
  // (their error is masked), so the other pair is restarted again on top
  // of the first stage's lowest result.
  if (J == 4 && best != kNone && picks[0] < subsets.size() && picks[1] < subsets.size()) {
    const std::vector<size_t>&A = subsets[picks[0]], &B = subsets[picks[1]];
    const bool disjoint = std::find(B.begin(), B.end(), A[0]) == B.end() &&
                          std::find(B.begin(), B.end(), A[1]) == B.end();
    if (disjoint) {
      // The stage-1 starts are in order (p0's, then p1's): which pair moved.
      const bool moved_p0 = best - first < static_cast<size_t>(kPairRestarts);
      const Parameterization q = moved_p0 ? params_[1] : params_[0];
      const std::vector<size_t>& other = moved_p0 ? B : A;
      const std::vector<Term> base = found[best].ts;
      std::mt19937_64 rng(opt_.seed * 1000003ull + 0x9a19ull + pidx(q) + 0x100ull * round);
      std::vector<PairStart> again;
      for (int r = 0; r < kPairRestarts; ++r) again.push_back({other[0], other[1], q, Rotation4::random(rng), &base});
      run_pairs(again);
    }
  }
}

bool Structured::reseed_keep(std::vector<Term>& ts, double& value, std::vector<Reseeded>& found,
                             const std::vector<size_t>& order, int n, const PowellOptions& fine,
                             TermRecord* rec) {
  // Which replacements are polished: the best one if it is already lower,
  // and, for every other mix of parameterizations (number of wiwo terms),
  // its best replacement if it is within 2x of now (a term moved to the
  // other parameterization starts higher before the others adapt). Each is
  // polished with one coarse sweep; the lowest, if below now, gets the full
  // polish (coarse, then fine) and is kept if it stays lower.
  std::vector<size_t> chosen;
  if (!order.empty() && found[order[0]].value < value * (1 - 1e-6)) chosen.push_back(order[0]);
  // Primary candidates first; a subset's other replacement only for a mix
  // that no primary candidate has (planted mixed member 8; reading every
  // replacement alike diverted member 1, 3 terms, wiwo, from the path that
  // reaches its planes: 0.61x became 30x).
  std::vector<int> seen = {wiwo_count(ts)};
  for (const bool primary : {true, false})
    for (size_t i : order) {
      const int c = wiwo_count(found[i].ts);
      if (found[i].primary != primary || std::find(seen.begin(), seen.end(), c) != seen.end()) continue;
      seen.push_back(c);
      if (found[i].value < 2 * value && std::find(chosen.begin(), chosen.end(), i) == chosen.end())
        chosen.push_back(i);
    }
  for (size_t i : chosen) polish(found[i].ts, found[i].value, 0, 1, n, rec, opt_.powell);
  size_t pick = found.size();
  for (size_t i : chosen)
    if (found[i].value < value * (1 - 1e-6) && (pick == found.size() || found[i].value < found[pick].value)) pick = i;
  return pick < found.size() && keep_if_lower(found[pick], ts, value, n, fine, rec);
}

bool Structured::keep_if_lower(Reseeded& f, std::vector<Term>& ts, double& value, int n, const PowellOptions& fine,
                               TermRecord* rec) {
  polish(f.ts, f.value, 0, polish_sweeps_, n, rec, opt_.powell);
  polish(f.ts, f.value, 0, polish_sweeps_, n, rec, fine);
  if (!(f.value < value * (1 - 1e-6))) return false;
  ts = f.ts;
  value = f.value;
  return true;
}

bool Structured::reseed_switch(std::vector<Term>& ts, const std::vector<FactorTerm>& done, double& value, int n,
                               const PowellOptions& fine, TermRecord* rec, bool refit) {
  const size_t J = ts.size();
  SearchOptions po[2] = {popt_[0], popt_[1]};
  po[0].fit.solve_last = po[1].fit.solve_last = n;
  // The starts: (term, its start; the start's value if it was read).
  struct Start {
    size_t i;
    Reseeded f;
  };
  std::vector<std::vector<Start>> per_term(J);
  parallel_for(J, opt_.threads, [&](size_t i) {
    std::vector<Start>& starts = per_term[i];
    if (refit) {  // seeds of the residual of the others refit without term i
      std::vector<Term> rest;
      for (size_t k = 0; k < J; ++k)
        if (k != i) rest.push_back(ts[k]);
      std::vector<FactorTerm> without;
      if (!std::isfinite(schedule(rest, &without, n - 1))) return;
      for (const auto& [sp_p, sp] : seeds(residual(without)))
        for (const Rotation4& R : {sp.first, sp.second}) {
          Start st{i, {ts, kInf, 0, true}};
          st.f.ts[i] = Term{R, sp_p};
          starts.push_back(std::move(st));
        }
      return;
    }
    // Seeds of the joint fit's residual without term i, in the other
    // parameterization only.
    std::vector<FactorTerm> others;
    for (size_t k = 0; k < J; ++k)
      if (k != i) others.push_back(done[k]);
    const Parameterization other = other_parameterization(ts[i].p);
    Start st{i, {}};
    for (const auto& [sp_p, sp] : seeds(residual(others), &other))
      for (const Rotation4& R : {sp.first, sp.second}) {
        std::vector<Term> t = ts;
        t[i] = Term{R, sp_p};
        const double v = schedule(t, nullptr, n);
        ++st.f.fits;
        if (v < st.f.value) {
          st.f.value = v;
          st.f.ts = std::move(t);
        }
      }
    if (std::isfinite(st.f.value)) starts.push_back(std::move(st));
  });
  std::vector<Start> runs;
  for (std::vector<Start>& st : per_term)
    for (Start& s : st) runs.push_back(std::move(s));
  // Powell from every start (in parallel): term i's plane, the others held.
  parallel_for(runs.size(), opt_.threads, [&](size_t q) {
    Reseeded& f = runs[q].f;
    const size_t i = runs[q].i;
    std::vector<TermSpec> other_specs;
    for (size_t k = 0; k < J; ++k)
      if (k != i) other_specs.push_back(spec(f.ts[k], sres_));
    const TermObjective objective(d_, {}, other_specs, po[pidx(f.ts[i].p)], sres_);
    const PowellResult r = powell_minimize(std::cref(objective), f.ts[i].R, opt_.powell);
    f.fits += r.evaluations;
    if (r.value < f.value) {
      f.ts[i].R = r.best.normalized();
      f.value = schedule(f.ts, nullptr, n);
      ++f.fits;
    }
  });
  // From the refit residuals a move must gain 1%: smaller ones are the
  // re-read of a right answer (planted mixed member 0, 3 terms, wiwo, seed
  // 2: 0.2%), whose polish and the next pass doubled the search's fits.
  const double below = value * (refit ? 0.99 : 1 - 1e-6);
  if (refit) {  // each term's refit without it
    evaluations_ += static_cast<int>(J);
    rec->backfit_evaluations += static_cast<int>(J);
  }
  size_t pick = runs.size();
  for (size_t q = 0; q < runs.size(); ++q) {
    evaluations_ += runs[q].f.fits;
    rec->backfit_evaluations += runs[q].f.fits;
    if (runs[q].f.value < below && (pick == runs.size() || runs[q].f.value < runs[pick].f.value)) pick = q;
  }
  return pick < runs.size() && keep_if_lower(runs[pick].f, ts, value, n, fine, rec);
}

bool Structured::reseed_mixed_pair(std::vector<Term>& ts, double& value, int n, const PowellOptions& fine,
                                   TermRecord* rec) {
  std::mt19937_64 rng(opt_.seed * 1000003ull + 0x9a21ull);
  // The mixes restarted: one term in each parameterization, and the
  // answer's own mix when both its terms share one.
  std::vector<std::array<Parameterization, 2>> mixes{{params_[0], params_[1]}};
  if (ts[0].p == ts[1].p) mixes.push_back({ts[0].p, ts[1].p});
  struct PairStart {
    std::array<Parameterization, 2> mix;
    std::vector<Rotation4> R;
  };
  std::vector<PairStart> starts;
  for (const auto& mix : mixes)
    for (int r = 0; r < kPairRestarts; ++r) starts.push_back({mix, {Rotation4::random(rng), Rotation4::random(rng)}});
  const auto with = [](const std::array<Parameterization, 2>& mix, const std::vector<Rotation4>& R) {
    return std::vector<Term>{Term{R[0].normalized(), mix[0]}, Term{R[1].normalized(), mix[1]}};
  };
  const int coarse = std::min(sres_, std::max(kPairRestartMinTexture, sres_ / 2));
  std::vector<Reseeded> runs(starts.size());
  parallel_for(starts.size(), opt_.threads, [&](size_t q) {
    const auto& mix = starts[q].mix;
    const JointPowellResult r = powell_minimize_joint(
        [&](const std::vector<Rotation4>& R) { return schedule(with(mix, R), nullptr, n, coarse); }, starts[q].R,
        opt_.powell);
    runs[q] = Reseeded{with(mix, r.best), r.value, r.evaluations};
    if (coarse != sres_) {  // its end read at the search's texture
      runs[q].value = schedule(runs[q].ts, nullptr, n);
      ++runs[q].fits;
    }
  });
  size_t pick = runs.size();
  for (size_t q = 0; q < runs.size(); ++q) {
    evaluations_ += runs[q].fits;
    rec->backfit_evaluations += runs[q].fits;
    if (runs[q].value < value * (1 - 1e-6) && (pick == runs.size() || runs[q].value < runs[pick].value)) pick = q;
  }
  return pick < runs.size() && keep_if_lower(runs[pick], ts, value, n, fine, rec);
}

void Structured::reseed(std::vector<Term>& ts, double& value, TermRecord* rec) {
  const double t0 = now_seconds();
  const size_t J = ts.size();
  const int n = static_cast<int>(J);
  std::vector<FactorTerm> done;
  // The joint fit of ts (its textures are read by the next replacements).
  const auto refit_done = [&] {
    value = schedule(ts, &done, n);
    ++evaluations_;
    ++rec->backfit_evaluations;
  };
  refit_done();
  if (!std::isfinite(value)) return;
  std::vector<std::vector<size_t>> subsets;
  for (size_t i = 0; i < J; ++i) subsets.push_back({i});
  for (size_t i = 0; i < J; ++i)
    for (size_t k = i + 1; k < J; ++k) subsets.push_back({i, k});
  PowellOptions fine = opt_.powell;
  fine.line_tol = 1e-3;
  fine.initial_step = 0.05;
  fine.ftol = 1e-6;
  bool restart_pairs = true;
  // 2 terms: no rounds (their one pair is the whole configuration, which the
  // beam searched); the one-term moves and the mixed pair's restarts below
  // change the mix.
  const int rounds = n >= kReseedRoundsTerms ? 4 : 0;
  for (int round = 0; round < rounds; ++round) {
    std::vector<std::array<double, 2>> pair_read;
    std::vector<Reseeded> found = reseed_replacements(ts, done, value, subsets, n, pair_read);
    if (restart_pairs) reseed_pair_restarts(ts, value, round, subsets, pair_read, n, found);
    std::vector<size_t> order(found.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return found[a].value < found[b].value; });
    for (const Reseeded& f : found) {
      evaluations_ += f.fits;
      rec->backfit_evaluations += f.fits;
    }
    std::vector<Parameterization> mix;
    for (const Term& t : ts) mix.push_back(t.p);
    if (!reseed_keep(ts, value, found, order, n, fine, rec)) break;
    // A new mix of parameterizations gives new pairs of one parameterization,
    // which may sit in the mixed local minimum the pair restarts leave
    // (planted mixed member 3, 4 terms: w w w h became h w w h on wrong planes).
    restart_pairs = false;
    for (size_t i = 0; i < ts.size(); ++i) restart_pairs = restart_pairs || ts[i].p != mix[i];
    refit_done();
  }
  // One term alone: from the joint fit's residual first, from the refit
  // residuals when that finds nothing (at most J moves).
  for (size_t k = 0; k < J && std::isfinite(value); ++k) {
    if (!reseed_switch(ts, done, value, n, fine, rec, false) && !reseed_switch(ts, done, value, n, fine, rec, true))
      break;
    refit_done();
  }
  // Two terms: random pairs with one term in each parameterization (and in
  // the answer's mix when its terms share one).
  if (J == 2 && params_.size() > 1 && std::isfinite(value) && reseed_mixed_pair(ts, value, n, fine, rec))
    refit_done();
  rec->seconds += now_seconds() - t0;
}

std::shared_ptr<HomomorphicFactorization> Structured::refit(const std::vector<Term>& ts,
                                                            std::vector<double>* errors) const {
  errors->clear();  // fit_homomorphic appends
  FitOptions fo = opt_.fit;
  if (opt_.final_joint) fo.solve_last = std::max(fo.solve_last, static_cast<int>(ts.size()));
  return fit_homomorphic(d_, specs(ts, opt_.texture_size), fo, "search", errors);
}

Structured::Answer Structured::answer_of(const std::vector<Term>& ts) const {
  Answer a;
  a.ts = ts;
  std::vector<double> errors;
  try {
    a.f = refit(ts, &errors);
    a.error = errors.back();
  } catch (const std::runtime_error&) {
    a.f = nullptr;
  }
  return a;
}

std::vector<Term> Structured::fill_answers(const std::vector<Term>& ts, const std::vector<Answer>& stage_best,
                                           SearchResult& out) {
  const int J = static_cast<int>(ts.size());
  // The k-term answers. k = J: the final (polished) configuration or stage J's
  // best, whichever fits better at texture_size. k < J: that answer's k-term
  // prefix, refit jointly, or stage k's best configuration, whichever fits
  // better. The joint refit's step k solves the first k terms together, so
  // errors[k-1] is the prefix's error.
  std::vector<double> errors;
  std::shared_ptr<HomomorphicFactorization> final_f = refit(ts, &errors);
  ++evaluations_;
  std::vector<Term> answer_ts = ts;
  if (stage_best[J - 1].error < errors.back()) {
    answer_ts = stage_best[J - 1].ts;
    final_f = refit(answer_ts, &errors);
    ++evaluations_;
  }
  out.answers.resize(J);
  out.rel_mse_after_term.resize(J);
  out.answers[J - 1] = final_f;
  out.rel_mse_after_term[J - 1] = errors[J - 1];
  // Each k < J: stage k's best, or the prefix refit (in parallel).
  std::vector<int> prefixes;
  for (int k = J - 1; k >= 1; --k) {
    const Answer& sb = stage_best[k - 1];
    if (sb.error < errors[k - 1]) {
      out.answers[k - 1] = sb.f;
      out.rel_mse_after_term[k - 1] = sb.error;
    } else {
      prefixes.push_back(k);
    }
  }
  parallel_for(prefixes.size(), opt_.threads, [&](size_t i) {
    const int k = prefixes[i];
    const Answer a = answer_of(std::vector<Term>(answer_ts.begin(), answer_ts.begin() + k));
    out.answers[k - 1] = a.f;
    out.rel_mse_after_term[k - 1] = a.error;
  });
  evaluations_ += static_cast<int>(prefixes.size());
  return answer_ts;
}

void Structured::reseed_answer(std::vector<Term>& ts, double& value, int n, const std::vector<Config>& beam,
                               const std::vector<Term>& polish_start, TermRecord* rec) {
  const size_t J = ts.size();
  const std::vector<Term> before = ts;
  double joint = kInf;
  reseed(ts, joint, rec);
  // Re-seeding again from the best beam configuration other than the one
  // polished before; the one whose refit at texture_size is lower is kept
  // (the joint objective can rank them the other way: on cayman's 12^4
  // grid, 3 terms, keeping the lower one raised rel_mse 0.5815 -> 0.5853).
  // Re-seeding moves one term or one pair at a time, and some answers have
  // every plane wrong with no such move out (planted mixed members 1 and 6,
  // 3 terms, wiwo, and member 7, 3 terms, halfdiff, all at seed 2: 18.5x,
  // 36.5x and 16.5x the joint floor); from the beam's next configuration
  // they end at 1.20x, 0.65x and 0.74x. It about doubles re-seeding's fits.
  // (Searches of 3 terms and more: at 2 terms the one-term moves suffice.)
  const auto next = std::find_if(beam.begin(), beam.end(),
                                 [&](const Config& c) { return !same_terms(c.ts, polish_start); });
  if (next != beam.end() && J >= static_cast<size_t>(kReseedRoundsTerms)) {
    std::vector<Term> alt = next->ts;
    double alt_joint = kInf;
    reseed(alt, alt_joint, rec);
    if (std::isfinite(alt_joint)) {
      const Answer a = answer_of(alt), m = answer_of(ts);
      evaluations_ += 2;
      if (a.error < m.error) {
        ts = std::move(alt);
        joint = alt_joint;
      }
    }
  }
  bool moved = false;
  for (size_t i = 0; i < J; ++i)
    moved = moved || ts[i].p != before[i].p || plane_distance(ts[i].R, before[i].R) > 0;
  if (moved) {
    value = static_cast<size_t>(n) >= J ? joint : schedule(ts, nullptr, n);
    ++evaluations_;
  }
}

SearchResult Structured::run() {
  const double t0 = now_seconds();
  SearchResult out;
  std::vector<Config> beam(1);
  beam[0].value = kInf;
  std::vector<TermRecord> records;
  // The best k-term configuration of stage k: every configuration of the beam
  // refit at texture_size (in parallel), the lowest error kept. The beam's order
  // is the search objective's (search resolution, schedule); its best need not
  // be the best refit, and the final answer's k-term prefix was chosen for the
  // final count, so each k has its own answer (out.answers).
  // Besides the beam, each k-term answer is extended greedily (step's side
  // configuration): the greedy search's own starts from it, so a k-term answer
  // the greedy search reaches by extending its (k-1)-term answer is in reach.
  std::vector<Answer> stage_best;
  std::vector<Config> side_next;
  Config side;  // the last answer at the search resolution (the schedule's texels); first the empty one
  const auto keep_stage_best = [&] {
    std::vector<const Config*> all;
    for (const Config& c : beam) all.push_back(&c);
    for (const Config& c : side_next) all.push_back(&c);
    std::vector<Answer> as(all.size());
    parallel_for(all.size(), opt_.threads, [&](size_t b) { as[b] = answer_of(all[b]->ts); });
    evaluations_ += static_cast<int>(all.size());
    size_t best = 0;
    for (size_t b = 1; b < as.size(); ++b)
      if (as[b].error < as[best].error) best = b;
    side = *all[best];
    stage_best.push_back(std::move(as[best]));
  };
  // Small searches are polished and refitted under the joint objective (all
  // terms solved together); their last term is searched under it too (the
  // schedule's n = 2 ranking need not be the joint one's, e.g. on McCool's form).
  const int n_final = opt_.final_joint && opt_.terms <= opt_.joint_polish_terms
                          ? std::max(opt_.terms, opt_.fit.solve_last)
                          : opt_.fit.solve_last;
  for (int j = 0; j < opt_.terms; ++j) {
    TermRecord rec;
    const int nj = j + 1 == opt_.terms ? n_final : opt_.fit.solve_last;
    std::vector<Config> next = step(beam, j, nj, &rec, &side, &side_next);
    if (next.empty()) throw std::runtime_error("structured search: every start of term " + std::to_string(j + 1) +
                                               " failed to solve");
    beam = std::move(next);
    rec.rotation = beam[0].ts.back().R.packed();
    rec.search_rel_mse = beam[0].value;
    rec.best_start = beam[0].start;
    const double t1 = now_seconds();
    keep_stage_best();
    rec.seconds += now_seconds() - t1;
    records.push_back(rec);
    if (opt_.stop_after_term && j + 1 < opt_.terms && stage_best.back().f &&
        opt_.stop_after_term(*stage_best.back().f))
      break;
  }
  std::vector<Term> ts = beam[0].ts;
  double value = beam[0].value;
  const int J = static_cast<int>(ts.size());
  // A stopping rule may end the search early: its configs were scored with solve_last.
  const int n = J == opt_.terms ? n_final : opt_.fit.solve_last;
  const bool polished = J >= 2 && polish_sweeps_ > 0;
  const bool reseeded = opt_.reseed && J >= 2 && J <= kReseedTerms && opt_.final_joint && params_.size() > 1;
  // The polish and re-seeding start from the lower (search objective) of the
  // beam's best and the last stage's best. The latter may be a side
  // configuration (the greedy extension) below every beam configuration;
  // polishing the beam's best instead left planted mixed member 5 (3 terms,
  // wiwo, seed 1) at 8.1x the joint floor: the beam's best polished and
  // re-seeded to 0.0044, the side configuration, unpolished, was 0.0035 and
  // became the answer, and polished from it the search ends at 0.66x.
  if ((polished || reseeded) && !same_terms(stage_best.back().ts, ts)) {
    const double v = schedule(stage_best.back().ts, nullptr, n);
    ++evaluations_;
    if (v < value) {
      ts = stage_best.back().ts;
      value = v;
    }
  }
  const std::vector<Term> polish_start = ts;
  if (polished) {
    // Under the schedule's objective, re-searching an early term re-solves every
    // later step; only the last solve's terms are polished there.
    const size_t from = n >= J ? 0 : static_cast<size_t>(J - n);
    polish(ts, value, from, polish_sweeps_, n, &records.back(), opt_.powell);
    // Searches solved jointly as a whole (up to joint_polish_terms terms): a
    // fine polish. Powell's line search stops at a bracket of 0.02 rad, which
    // left McCool-form BRDFs 0.0003-0.0014 (plane distance) off the true
    // planes and up to 9x McCool's error (planted McCool member 5); the
    // larger searches (W1) are not affected.
    if (n >= J) {
      PowellOptions fine = opt_.powell;
      fine.line_tol = 1e-3;
      fine.initial_step = 0.05;
      fine.ftol = 1e-6;
      polish(ts, value, 0, polish_sweeps_, n, &records.back(), fine);
    }
  }
  // Searches of 2..kReseedTerms terms with a parameterization per term: the
  // terms re-read under the joint objective (reseed), which finds planes the
  // beam misses when the terms do not share one parameterization (at 2 terms
  // a wiwo and a halfdiff plane: the beam ended at w w or h h, 30-43x the
  // joint floor, on 4 of 12 planted pairs; W1's 2-term answer went from
  // h h, 0.01676, to w h, 0.01400).
  if (reseeded) reseed_answer(ts, value, n, beam, polish_start, &records.back());
  const std::vector<Term> answer_ts = fill_answers(ts, stage_best, out);
  for (size_t i = 0; i < answer_ts.size(); ++i) records[i].rotation = answer_ts[i].R.packed();
  records.back().search_rel_mse = value;
  out.factorization = out.answers.back();
  out.terms = records;
  out.search_rel_mse = value;
  out.beam_rel_mse = {out.rel_mse_after_term.back()};
  out.evaluations = evaluations_;
  out.seconds = now_seconds() - t0;
  return out;
}

}  // namespace

SearchResult structured_search(const FitData& data, const SearchOptions& opt) {
  opt.validate();
  return Structured(data, opt).run();
}

}  // namespace bf
