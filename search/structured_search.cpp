// The structured projection search (see structured_search.h).
#include "search/structured_search.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "search/structure.h"

namespace bf {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr double kInf = std::numeric_limits<double>::infinity();

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

size_t first_joint(size_t step, int n) {
  return step + 1 > static_cast<size_t>(n) ? step + 1 - n : 0;
}

// Runs fn(i) for i in [0, n) on the option's threads; results by index, so
// independent of scheduling.
template <class Fn>
void parallel_for(size_t n, int threads, Fn fn) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const unsigned nthreads = std::min<unsigned>(threads > 0 ? threads : hw, n);
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < nthreads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
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
  // The fit schedule at the search resolution: its error, and the texels.
  double schedule(const std::vector<Term>& ts, std::vector<FactorTerm>* done) const;
  // Mean over channels of g minus the given terms' values (the residual log BRDF).
  std::vector<double> residual(const std::vector<FactorTerm>& done) const;
  // Seed plane pairs of a residual, one per allowed parameterization.
  std::vector<std::pair<Parameterization, PlaneSplit>> seeds(const std::vector<double>& y) const;
  // Searches the term after ts (texels `done`): screened starts, Powell from the best.
  Term next_term(const std::vector<Term>& ts, const std::vector<FactorTerm>& done,
                 const std::vector<std::pair<Parameterization, PlaneSplit>>& sd, TermRecord* rec);
  // Jacobi sweeps over terms [from, J): each re-searched with the others held.
  void polish(std::vector<Term>& ts, double& value, size_t from, int sweeps, TermRecord* rec);

  const FitData& d_;
  const SearchOptions& opt_;
  int sres_;
  SearchOptions popt_[2];
  std::vector<Parameterization> params_;
  int evaluations_ = 0;
};

double Structured::schedule(const std::vector<Term>& ts, std::vector<FactorTerm>* done_out) const {
  const int n = opt_.fit.solve_last;
  const std::vector<TermSpec> sp = specs(ts, sres_);
  std::vector<FactorTerm> done;
  double value = kInf;
  for (size_t s = 0; s < sp.size(); ++s) {
    const size_t first = first_joint(s, n);
    std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
    std::vector<TermSpec> joint(sp.begin() + first, sp.begin() + s + 1);
    try {
      const JointSolution sol = solve_joint(d_, fixed_sum(d_, fixed), joint, opt_.fit, false);
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

std::vector<std::pair<Parameterization, PlaneSplit>> Structured::seeds(const std::vector<double>& y) const {
  std::vector<std::pair<Parameterization, PlaneSplit>> out;
  StructureOptions so;
  so.seed = opt_.seed;
  for (Parameterization p : params_) {
    const std::vector<Eigen::Matrix4d> hs = local_hessians(d_.points(p), y, d_.w, so);
    if (hs.empty()) continue;
    out.emplace_back(p, split_planes(hs));
  }
  return out;
}

Term Structured::next_term(const std::vector<Term>& ts, const std::vector<FactorTerm>& done,
                           const std::vector<std::pair<Parameterization, PlaneSplit>>& sd, TermRecord* rec) {
  const double t0 = now_seconds();
  const size_t j = ts.size();
  const size_t first = first_joint(j, opt_.fit.solve_last);
  const std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
  std::vector<TermSpec> known;
  for (size_t i = first; i < j; ++i) known.push_back(spec(ts[i], sres_));
  std::vector<std::unique_ptr<TermObjective>> obj(2);
  for (Parameterization p : params_)
    obj[pidx(p)] = std::make_unique<TermObjective>(d_, fixed, known, popt_[pidx(p)], sres_);

  // Starts: seeds, guesses (wi, wo and the configured ones), seeded random rotations.
  std::vector<Start> starts;
  auto add = [&](const Rotation4& R, Parameterization p) {
    starts.push_back(Start{Term{R, p}, kInf, static_cast<int>(starts.size())});
  };
  for (const auto& [p, s] : sd) {
    add(s.first, p);
    add(s.second, p);
  }
  std::vector<std::string> guesses = {"wi", "wo"};
  for (const std::string& g : opt_.guesses)
    if (std::find(guesses.begin(), guesses.end(), g) == guesses.end()) guesses.push_back(g);
  for (Parameterization p : params_)
    for (const std::string& g : guesses) add(guess_rotation(g), p);
  for (int r = 0; r < opt_.restarts; ++r) {
    std::mt19937_64 rng(opt_.seed * 1000003ull + j * 7919ull + r);
    add(Rotation4::random(rng), params_[r % params_.size()]);
  }
  parallel_for(starts.size(), opt_.threads, [&](size_t i) {
    starts[i].value = (*obj[pidx(starts[i].t.p)])(starts[i].t.R);
  });
  evaluations_ += static_cast<int>(starts.size());
  rec->evaluations += static_cast<int>(starts.size());

  // The `keep` best distinct starts (same parameterization and nearly the same plane = duplicate).
  std::vector<Start> sorted = starts;
  std::stable_sort(sorted.begin(), sorted.end(), [](const Start& a, const Start& b) { return a.value < b.value; });
  std::vector<Start> kept;
  for (const Start& s : sorted) {
    if (static_cast<int>(kept.size()) >= opt_.keep) break;
    if (!std::isfinite(s.value)) continue;
    bool dup = false;
    for (const Start& k : kept)
      dup = dup || (k.t.p == s.t.p && plane_distance(k.t.R, s.t.R) < 0.02);
    if (!dup) kept.push_back(s);
  }
  if (kept.empty()) kept.push_back(sorted.front());
  std::vector<PowellResult> res(kept.size());
  parallel_for(kept.size(), opt_.threads, [&](size_t i) {
    res[i] = powell_minimize(std::cref(*obj[pidx(kept[i].t.p)]), kept[i].t.R, opt_.powell);
  });
  size_t best = 0;
  for (size_t i = 0; i < res.size(); ++i) {
    evaluations_ += res[i].evaluations;
    rec->evaluations += res[i].evaluations;
    if (res[i].value < res[best].value) best = i;
  }
  rec->best_start = kept[best].index;
  rec->search_rel_mse = res[best].value;
  rec->seconds += now_seconds() - t0;
  return Term{res[best].best.normalized(), kept[best].t.p};
}

void Structured::polish(std::vector<Term>& ts, double& value, size_t from, int sweeps, TermRecord* rec) {
  const double t0 = now_seconds();
  const size_t J = ts.size();
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    // Each term re-searched from its rotation with the others held (in parallel).
    const std::vector<TermSpec> sp = specs(ts, sres_);
    std::vector<PowellResult> res(J);
    parallel_for(J - from, opt_.threads, [&](size_t k) {
      const size_t i = from + k;
      const ScheduleObjective objective(d_, sp, i, popt_[pidx(ts[i].p)], sres_);
      res[i] = powell_minimize(std::cref(objective), ts[i].R, opt_.powell);
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
      const double v = schedule(trial, nullptr);
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

SearchResult Structured::run() {
  const double t0 = now_seconds();
  SearchResult out;
  std::vector<Term> ts;
  std::vector<FactorTerm> done;
  std::vector<TermRecord> records;
  double value = kInf;
  // Seed pairs of the residual after terms 1..i, i = 0, 1, ... (kept for the pair move).
  std::vector<std::vector<std::pair<Parameterization, PlaneSplit>>> seed_at;
  std::shared_ptr<HomomorphicFactorization> f;
  std::vector<double> errors;
  const auto refit = [&] {
    errors.clear();
    f = fit_homomorphic(d_, specs(ts, opt_.texture_size), opt_.fit, "search", &errors);
  };
  for (int j = 0; j < opt_.terms; ++j) {
    seed_at.push_back(seeds(residual(done)));
    TermRecord rec;
    const Term t = next_term(ts, done, seed_at.back(), &rec);
    std::vector<Term> greedy = ts;
    greedy.push_back(t);
    std::vector<FactorTerm> greedy_done;
    double greedy_value = schedule(greedy, &greedy_done);
    ++evaluations_;
    if (j >= 1) {
      // Pair move: terms j-1 and j from the seed pair of the residual of terms 1..j-2.
      const std::vector<Term> base(ts.begin(), ts.end() - 1);
      std::vector<Term> best_pair;
      double best_pair_value = kInf;
      for (const auto& [p, s] : seed_at[j - 1]) {
        std::vector<Term> pair = base;
        pair.push_back(Term{s.first, p});
        pair.push_back(Term{s.second, p});
        const double v = schedule(pair, nullptr);
        ++evaluations_;
        if (v < best_pair_value) {
          best_pair_value = v;
          best_pair = pair;
        }
      }
      if (!best_pair.empty()) {
        polish(best_pair, best_pair_value, j - 1, opt_.polish_sweeps + 1, &rec);
        // Polish the greedy pair as much, so the comparison is fair.
        polish(greedy, greedy_value, j - 1, opt_.polish_sweeps + 1, &rec);
        if (best_pair_value < greedy_value) {
          greedy = best_pair;
          greedy_value = schedule(greedy, &greedy_done);
          ++evaluations_;
          records.back().rotation = greedy[j - 1].R.packed();
        } else {
          schedule(greedy, &greedy_done);
          ++evaluations_;
        }
      }
    }
    ts = std::move(greedy);
    done = std::move(greedy_done);
    value = greedy_value;
    rec.rotation = ts.back().R.packed();
    rec.search_rel_mse = value;
    records.push_back(rec);
    if (opt_.stop_after_term && j + 1 < opt_.terms) {
      refit();
      if (opt_.stop_after_term(*f)) break;
    }
  }
  if (ts.size() >= 2) {
    polish(ts, value, 0, opt_.polish_sweeps, &records.back());
    for (size_t i = 0; i < ts.size(); ++i) records[i].rotation = ts[i].R.packed();
    records.back().search_rel_mse = value;
  }
  refit();
  out.factorization = f;
  out.rel_mse_after_term = errors;
  out.terms = records;
  out.search_rel_mse = value;
  out.beam_rel_mse = {errors.back()};
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
