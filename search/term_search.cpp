// Greedy projection search (see term_search.h).
#include "search/term_search.h"

#include <nlopt.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace bf {

namespace {
const char* kOptimizers[] = {"powell", "praxis", "bobyqa", "neldermead", "sbplx", "direct", "crs"};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

void SearchOptions::validate() const {
  if (terms < 1) throw std::invalid_argument("terms: expected >= 1, found " + std::to_string(terms));
  if (texture_size < 2 || texture_size > 1024)
    throw std::invalid_argument("texture_size: expected 2..1024, found " +
                                std::to_string(texture_size));
  if (search_texture_size != 0 && (search_texture_size < 2 || search_texture_size > 1024))
    throw std::invalid_argument("search_texture_size: expected 0 (same as texture_size) or "
                                "2..1024, found " + std::to_string(search_texture_size));
  if (restarts < 0)
    throw std::invalid_argument("restarts: expected >= 0, found " + std::to_string(restarts));
  for (const auto& g : guesses) guess_rotation(g);  // throws for unknown names
  if (restarts == 0 && guesses.empty())
    throw std::invalid_argument("restarts: 0 restarts and no guesses leave nothing to search from");
  if (std::find(std::begin(kOptimizers), std::end(kOptimizers), optimizer) == std::end(kOptimizers))
    throw std::invalid_argument("optimizer: expected powell, praxis, bobyqa, neldermead, sbplx, "
                                "direct or crs, found \"" + optimizer + "\"");
  if (threads < 0)
    throw std::invalid_argument("threads: expected >= 0, found " + std::to_string(threads));
  fit.validate();
  powell.validate();
}

TermObjective::TermObjective(const FitData& data, const std::vector<FactorTerm>& fixed,
                             std::vector<TermSpec> joint_known, const SearchOptions& opt, int res)
    : data_(data), fixed_values_(fixed_sum(data, fixed)), joint_known_(std::move(joint_known)),
      opt_(opt), res_(res) {}

TermSpec TermObjective::spec(const Rotation4& r) const {
  return TermSpec{r.projection(opt_.param, res_), opt_.reciprocity, r.packed()};
}

double TermObjective::operator()(const Rotation4& r) const {
  std::vector<TermSpec> joint = joint_known_;
  joint.push_back(spec(r.normalized()));
  try {
    // The least-squares objective read off the normal equations (no pass over
    // the samples); the final refit reports the clamped metric.
    return solve_joint(data_, fixed_values_, joint, opt_.fit, /*exact_error=*/false).rel_mse;
  } catch (const std::runtime_error&) {
    return std::numeric_limits<double>::max();  // a failed solve is never chosen
  }
}

namespace {

struct StartResult {
  Rotation4 best;
  double value = std::numeric_limits<double>::infinity();
  int evaluations = 0;
};

// nlopt over the chart a -> (exp(a_0..2) S0, T0 exp(a_3..5)) around the start.
StartResult nlopt_minimize(const TermObjective& f, const Rotation4& start,
                           const SearchOptions& opt) {
  struct Ctx {
    const TermObjective* f;
    Rotation4 s;
    int evals = 0;
  } ctx{&f, start, 0};
  auto chart = [](const Rotation4& s, const double* a) {
    const Quat ls(0, a[0], a[1], a[2]), lt(0, a[3], a[4], a[5]);
    return Rotation4{qmul(qexp(ls), s.S), qmul(s.T, qexp(lt))}.normalized();
  };
  nlopt::algorithm alg = nlopt::LN_PRAXIS;
  const bool global = opt.optimizer == "direct" || opt.optimizer == "crs";
  if (opt.optimizer == "bobyqa") alg = nlopt::LN_BOBYQA;
  if (opt.optimizer == "neldermead") alg = nlopt::LN_NELDERMEAD;
  if (opt.optimizer == "sbplx") alg = nlopt::LN_SBPLX;
  if (opt.optimizer == "direct") alg = nlopt::GN_DIRECT_L;
  if (opt.optimizer == "crs") alg = nlopt::GN_CRS2_LM;
  nlopt::opt o(alg, 6);
  const double bound = global ? M_PI / 2 : M_PI;
  o.set_lower_bounds(std::vector<double>(6, -bound));
  o.set_upper_bounds(std::vector<double>(6, bound));
  o.set_ftol_rel(opt.powell.ftol);
  o.set_maxeval(opt.powell.max_evaluations);
  if (!global) o.set_initial_step(std::vector<double>(6, opt.powell.initial_step));
  o.set_min_objective(
      [](unsigned, const double* a, double*, void* data) {
        Ctx* c = static_cast<Ctx*>(data);
        ++c->evals;
        return (*c->f)(Rotation4{qmul(qexp(Quat(0, a[0], a[1], a[2])), c->s.S),
                                 qmul(c->s.T, qexp(Quat(0, a[3], a[4], a[5])))}
                           .normalized());
      },
      &ctx);
  std::vector<double> a(6, 0.0);
  double fv = std::numeric_limits<double>::infinity();
  try {
    o.optimize(a, fv);
  } catch (const nlopt::roundoff_limited&) {
  } catch (const nlopt::forced_stop&) {
  }
  StartResult r;
  r.best = chart(start, a.data());
  r.value = fv;
  r.evaluations = ctx.evals;
  if (!std::isfinite(r.value)) {
    r.value = f(r.best);
    ++r.evaluations;
  }
  return r;
}

}  // namespace

SearchResult search_factorization(const FitData& data, const SearchOptions& opt) {
  opt.validate();
  const double t0 = now_seconds();
  const int sres = opt.search_texture_size > 0 ? opt.search_texture_size : opt.texture_size;
  const int n = opt.fit.solve_last;
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const unsigned nthreads = opt.threads > 0 ? opt.threads : hw;

  SearchResult out;
  std::vector<FactorTerm> done;    // terms at the search resolution, with texels
  std::vector<TermSpec> found;     // projection specs found so far
  std::vector<Rotation4> rotations;
  for (int j = 0; j < opt.terms; ++j) {
    const double tj = now_seconds();
    const int first = std::max(0, j + 1 - n);  // terms first..j solved jointly
    std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
    std::vector<TermSpec> known(found.begin() + first, found.begin() + j);
    const TermObjective objective(data, fixed, known, opt, sres);

    // Starts: seeded random rotations, then guesses; each start has its own
    // RNG stream so results do not depend on thread scheduling.
    std::vector<Rotation4> starts;
    for (int r = 0; r < opt.restarts; ++r) {
      std::mt19937_64 rng(opt.seed * 1000003ull + static_cast<uint64_t>(j) * 7919ull + r);
      starts.push_back(Rotation4::random(rng));
    }
    for (const auto& g : opt.guesses) starts.push_back(guess_rotation(g));

    std::vector<StartResult> results(starts.size());
    std::atomic<size_t> next{0};
    auto worker = [&] {
      for (size_t i = next++; i < starts.size(); i = next++) {
        if (opt.optimizer == "powell") {
          const PowellResult p = powell_minimize(objective, starts[i], opt.powell);
          results[i] = {p.best, p.value, p.evaluations};
        } else {
          results[i] = nlopt_minimize(objective, starts[i], opt);
        }
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < std::min<unsigned>(nthreads, starts.size()); ++t) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();

    size_t best = 0;
    TermRecord rec;
    for (size_t i = 0; i < results.size(); ++i) {
      rec.evaluations += results[i].evaluations;
      if (results[i].value < results[best].value) best = i;
    }
    const Rotation4 R = results[best].best.normalized();
    rec.rotation = R.packed();
    rec.search_rel_mse = results[best].value;
    rec.best_start = static_cast<int>(best);
    std::vector<TermSpec> joint = known;
    joint.push_back(objective.spec(R));
    const JointSolution sol = solve_joint(data, objective.fixed_values(), joint, opt.fit);
    done = fixed;
    done.insert(done.end(), sol.terms.begin(), sol.terms.end());
    found.push_back(objective.spec(R));
    rotations.push_back(R);
    rec.seconds = now_seconds() - tj;
    out.evaluations += rec.evaluations;
    out.terms.push_back(rec);
  }

  // Refit the found projections at the final resolution (thesis 4.2).
  std::vector<TermSpec> final_specs;
  for (const Rotation4& R : rotations)
    final_specs.push_back(TermSpec{R.projection(opt.param, opt.texture_size), opt.reciprocity, R.packed()});
  out.factorization = fit_homomorphic(data, final_specs, opt.fit, "search", &out.rel_mse_after_term);
  out.seconds = now_seconds() - t0;
  return out;
}

}  // namespace bf
