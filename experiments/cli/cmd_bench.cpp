// Subcommand `bench fit`: times the inner-loop fit (docs/design.md §5) and prints
// one JSON object per line.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <ctime>
#include <thread>

#include "brdfs/catalogue.h"
#include "brdfs/measured.h"
#include "factor/metrics.h"
#include "brdfs/sampleset.h"
#include "experiments/cli/commands.h"
#include "factor/dense_kernels.h"
#include "factor/homomorphic_fit.h"
#include "search/powell.h"
#include "search/rotation4.h"
#include "search/planted.h"
#include "search/term_search.h"
#include "solvers/parallel.h"

namespace bf {

namespace {
// CPU time of the calling thread in milliseconds: on a shared, loaded machine
// it is far steadier than wall time (both are reported).
double thread_cpu_ms() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct BenchFitArgs {
  std::string brdf = "bluepaint";
  int grid = 16;
  long long samples = 0;
  int texture = 16;
  int terms = 2;
  int solve_last = 2;
  std::string param = "wiwo";
  bool reciprocity = false;
  int repeats = 15;
  unsigned long long seed = 1;
  std::string solver = "auto";
  double smoothing = FitOptions{}.smoothing;
  bool exact_error = false;
  std::string dump_input;  // --dump-input: the joint solve's input as JSON (write_fit_input)
};

// The joint solve's input and result as one JSON object, for an outside
// implementation of the same fit (scripts/bench-peer.py, docs/speed.md "The
// scipy peer"): the valid samples as the fit sees them (points x in the
// terms' parameterization, N x 4 row-major; weights w; targets r = g - fixed
// terms, 3 x N), the joint terms (P 2 x 4 row-major, res, reciprocal, the
// projection mask res x res, 1 = texel in the mask, index j * res + i), the
// options, and the fit's unknowns and rel_mse (exact_error as timed).
void write_fit_input(std::ofstream& f, const std::string& path, const BenchFitArgs& a, const FitData& d, const FitOptions& opt,
                     const std::array<std::vector<double>, 3>& fixed_values, const std::vector<TermSpec>& joint,
                     const JointSolution& sol) {
  nlohmann::json j;
  j["format"] = "brdf-factor bench-fit input 1";
  j["brdf"] = a.brdf;
  j["grid"] = a.samples > 0 ? 0 : a.grid;
  j["stratified_samples"] = a.samples;
  j["parameterization"] = a.param;
  j["smoothing"] = opt.smoothing;
  j["extrapolation_prior"] = opt.extrapolation_prior;
  j["solver"] = a.solver;
  j["exact_error"] = a.exact_error;
  j["samples"] = d.size();
  j["W"] = d.W;
  const std::vector<Vec4>& x = d.points(parse_parameterization(a.param));
  std::vector<double> xs;
  xs.reserve(4 * x.size());
  for (const Vec4& p : x)
    for (int c = 0; c < 4; ++c) xs.push_back(p[c]);
  j["x"] = xs;
  j["w"] = d.w;
  nlohmann::json r = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) {
    std::vector<double> rc(d.size());
    for (size_t k = 0; k < d.size(); ++k) rc[k] = d.g[c][k] - fixed_values[c][k];
    r.push_back(rc);
  }
  j["r"] = r;
  nlohmann::json terms = nlohmann::json::array();
  for (const TermSpec& t : joint) {
    std::vector<double> P;
    for (int row = 0; row < 2; ++row)
      for (int col = 0; col < 4; ++col) P.push_back(t.proj.P(row, col));
    const std::vector<uint8_t> m = projection_mask(t.proj);
    terms.push_back({{"P", P}, {"res", t.proj.res}, {"reciprocal", t.reciprocal},
                     {"mask", std::vector<int>(m.begin(), m.end())}});
  }
  j["terms"] = terms;
  j["unknowns"] = sol.unknowns;
  j["rel_mse"] = sol.rel_mse;
  f << j.dump() << "\n";
  if (!f.flush()) throw std::runtime_error("--dump-input: writing '" + path + "' failed");
}

void run_bench_fit(const BenchFitArgs& a) {
  if (a.repeats < 1) throw std::invalid_argument("--repeats: expected >= 1, found " + std::to_string(a.repeats));
  if (a.terms < 1 || a.terms > 1024)
    throw std::invalid_argument("--terms: expected 1..1024, found " + std::to_string(a.terms));
  if (a.texture < 2 || a.texture > 1024)
    throw std::invalid_argument("--texture: expected 2..1024, found " + std::to_string(a.texture));
  if (uint64_t(a.terms) * uint64_t(a.texture) * uint64_t(a.texture) > kMaxTotalTexels)
    throw std::invalid_argument("--terms x --texture^2: expected at most " + std::to_string(kMaxTotalTexels) +
                                " texels, found " + std::to_string(a.terms) + " x " + std::to_string(a.texture) +
                                "^2");
  if (a.samples < 0 || uint64_t(a.samples) > kMaxStratifiedCount)
    throw std::invalid_argument("--samples: expected 0.." + std::to_string(kMaxStratifiedCount) + ", found " +
                                std::to_string(a.samples));
  const BrdfPtr brdf = Catalogue::builtin().make(a.brdf);
  const SampleSet s = a.samples > 0 ? sample_stratified(*brdf, static_cast<size_t>(a.samples), a.seed)
                                    : sample_grid(*brdf, a.grid);
  FitOptions opt;
  opt.solve_last = a.solve_last;
  opt.smoothing = a.smoothing;
  if (a.solver == "auto") opt.solver = FitOptions::Solver::Auto;
  else if (a.solver == "dense") opt.solver = FitOptions::Solver::Dense;
  else if (a.solver == "sparse") opt.solver = FitOptions::Solver::Sparse;
  else if (a.solver == "qr") opt.solver = FitOptions::Solver::ReferenceQR;
  else throw std::invalid_argument("--solver: expected auto, dense, sparse or qr, found '" + a.solver + "'");
  const Parameterization param = parse_parameterization(a.param);
  const FitData d(s, opt.eps);
  std::ofstream dump;  // opened before the work, so that a bad path fails at once
  if (!a.dump_input.empty()) {
    dump.open(a.dump_input);
    if (!dump) throw std::runtime_error("--dump-input: cannot open '" + a.dump_input + "' for writing");
  }

  // Projections from seeded random rotations (what a search evaluates); the
  // terms before the joint block are fitted once, untimed.
  std::mt19937_64 rng(a.seed);
  std::vector<TermSpec> specs;
  for (int j = 0; j < a.terms; ++j) {
    const Rotation4 r = Rotation4::random(rng);
    specs.push_back({r.projection(param, a.texture), a.reciprocity, r.packed()});
  }
  const int first = std::max(0, a.terms - a.solve_last);
  std::vector<FactorTerm> fixed;
  if (first > 0) {
    const auto pre = fit_homomorphic(d, std::vector<TermSpec>(specs.begin(), specs.begin() + first), opt);
    fixed = pre->terms();
  }
  const std::vector<TermSpec> joint(specs.begin() + first, specs.end());
  const auto fixed_values = fixed_sum(d, fixed);
  std::vector<double> ms, cpu, cpu_prefix;
  JointSolution sol;
  // With more than one joint term, the search's case is timed too: the first
  // joint terms held (their lookups and normal-matrix block built once, a
  // JointPrefix, untimed), the last one new. Interleaved with the plain solves
  // so that both see the same machine load.
  std::unique_ptr<JointPrefix> prefix;
  if (joint.size() > 1)
    prefix = std::make_unique<JointPrefix>(d, fixed_values, std::vector<TermSpec>(joint.begin(), joint.end() - 1), opt);
  double prefix_diff = 0;
  for (int r = 0; r < a.repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    // exact_error = false: the search's objective, read off the normal equations.
    sol = solve_joint(d, fixed_values, joint, opt, a.exact_error);
    cpu.push_back(thread_cpu_ms() - c0);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (prefix) {
      const double c1 = thread_cpu_ms();
      const JointSolution ps = solve_joint(d, fixed_values, joint, opt, a.exact_error, prefix.get());
      cpu_prefix.push_back(thread_cpu_ms() - c1);
      prefix_diff = std::max(prefix_diff, std::abs(ps.rel_mse - sol.rel_mse));
    }
  }
  const double median = median_of(ms);
  nlohmann::json j;
  j["bench"] = "fit";
  j["brdf"] = a.brdf;
  j["parameterization"] = a.param;
  j["samples"] = d.size();
  j["texture"] = a.texture;
  j["terms"] = a.terms;
  j["solve_last"] = a.solve_last;
  j["reciprocity"] = a.reciprocity;
  j["solver"] = a.solver;
  j["solver_used"] = sol.solver == FitOptions::Solver::Sparse        ? "sparse"
                     : sol.solver == FitOptions::Solver::ReferenceQR ? "qr"
                                                                      : "dense";
  j["unknowns"] = sol.unknowns;
  j["ms_median"] = median;
  j["ms_min"] = *std::min_element(ms.begin(), ms.end());
  j["cpu_ms_median"] = median_of(cpu);
  j["cpu_ms_min"] = *std::min_element(cpu.begin(), cpu.end());
  if (prefix) {
    j["cpu_ms_median_prefix"] = median_of(cpu_prefix);  // last joint term new, the others cached
    j["prefix_rel_mse_diff"] = prefix_diff;
  }
  j["exact_error"] = a.exact_error;
  j["repeats"] = a.repeats;
  j["rel_mse"] = sol.rel_mse;
  j["threads"] = 1;
  j["kernel"] = kernels::active_variant();  // dense Cholesky variant (factor/dense_kernels.h)
  std::cout << j.dump() << std::endl;
  if (!a.dump_input.empty()) write_fit_input(dump, a.dump_input, a, d, opt, fixed_values, joint, sol);
}
struct BenchSearchArgs {
  std::string brdf = "bluepaint";
  int grid = 16;
  std::string sampling = "grid";  // or "measured" (the BRDF's own samples)
  int texture = 16;
  int search_texture = 0;
  int terms = 5;
  int restarts = 6;
  int solve_last = 2;
  std::string param = "wiwo";
  bool reciprocity = false;
  // auto (on when the BRDF is reciprocal, as a config's default), on or off.
  std::string final_reciprocity = "auto";
  bool brdf_reciprocal = false;  // filled from the BRDF (run_bench_search)
  unsigned long long seed = 1;
  std::string optimizer = "powell";
  int threads = 0;
  double ftol = PowellOptions{}.ftol;
  double line_tol = PowellOptions{}.line_tol;
  std::string line_search = to_string(PowellOptions{}.line_search);
  double smoothing = FitOptions{}.smoothing;
  std::vector<std::string> guesses;
  int beam = 1;
  int backfit_sweeps = 0;
  int backfit_restarts = 0;
  std::string strategy = "structured";  // or "greedy", or "both" (side by side)
  std::string term_param = SearchOptions{}.term_param;
  int keep = SearchOptions{}.keep;
  int polish_sweeps = SearchOptions{}.polish_sweeps;
  int beam_width = SearchOptions{}.beam_width;
  double perturb = 0;  // relative perturbation of every sample value (rounding robustness)
};

SearchOptions bench_search_options(const BenchSearchArgs& a, const std::string& strategy) {
  SearchOptions opt;
  opt.strategy = strategy;
  opt.term_param = a.term_param;
  opt.keep = a.keep;
  opt.polish_sweeps = a.polish_sweeps;
  opt.beam_width = a.beam_width;
  opt.terms = a.terms;
  opt.param = parse_parameterization(a.param);
  opt.texture_size = a.texture;
  opt.search_texture_size = a.search_texture;
  opt.restarts = a.restarts;
  opt.guesses = a.guesses;
  opt.reciprocity = a.reciprocity;
  opt.final_reciprocity =
      a.final_reciprocity == "on" || (a.final_reciprocity == "auto" && a.brdf_reciprocal);
  opt.fit.solve_last = a.solve_last;
  opt.fit.smoothing = a.smoothing;
  opt.seed = a.seed;
  opt.optimizer = a.optimizer;
  opt.threads = a.threads;
  opt.powell.ftol = a.ftol;
  opt.powell.line_tol = a.line_tol;
  opt.powell.line_search = parse_line_search(a.line_search);
  opt.beam = a.beam;
  opt.backfit_sweeps = a.backfit_sweeps;
  opt.backfit_restarts = a.backfit_restarts;
  return opt;
}

// One search, as a JSON line; returns the line's object.
nlohmann::json bench_one_search(const BenchSearchArgs& a, const FitData& d, const std::string& strategy) {
  const SearchOptions opt = bench_search_options(a, strategy);
  const std::clock_t c0 = std::clock();
  const SearchResult r = search_factorization(d, opt);
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  nlohmann::json j;
  j["bench"] = "search";
  j["strategy"] = strategy;
  j["brdf"] = a.brdf;
  j["parameterization"] = a.param;
  j["term_param"] = a.term_param;
  j["search_strategy"] = r.strategy;
  j["reciprocity"] = a.reciprocity;
  j["final_reciprocity"] = opt.final_reciprocity;
  j["reciprocal_answers"] = r.reciprocal_answers;
  j["sampling"] = a.sampling;
  j["samples"] = d.size();
  j["texture"] = a.texture;
  j["search_texture"] = a.search_texture > 0 ? a.search_texture : a.texture;
  j["terms"] = a.terms;
  j["restarts"] = a.restarts;
  j["optimizer"] = a.optimizer;
  j["line_search"] = a.line_search;
  j["threads"] = hardware_threads(a.threads);
  j["beam"] = a.beam;
  j["backfit_sweeps"] = a.backfit_sweeps;
  j["backfit_restarts"] = a.backfit_restarts;
  if (a.perturb != 0) j["perturb"] = a.perturb;
  j["seconds"] = r.seconds;
  j["cpu_seconds"] = cpu;  // process CPU time, all threads
  j["evaluations"] = r.evaluations;
  j["ms_per_evaluation_wall"] = 1e3 * r.seconds / std::max(1, r.evaluations);
  j["rel_mse_after_term"] = r.rel_mse_after_term;
  j["search_rel_mse"] = r.search_rel_mse;
  if (r.beam_rel_mse.size() > 1) {
    j["beam_rel_mse"] = r.beam_rel_mse;
    j["best_branch"] = r.best_branch;
  }
  nlohmann::json per = nlohmann::json::array();
  for (const TermRecord& t : r.terms)
    per.push_back({{"evaluations", t.evaluations}, {"seconds", t.seconds},
                   {"search_rel_mse", t.search_rel_mse}, {"best_start", t.best_start},
                   {"backfit_evaluations", t.backfit_evaluations}, {"backfit_moves", t.backfit_moves}});
  j["per_term"] = per;
  nlohmann::json params = nlohmann::json::array();
  for (const FactorTerm& t : r.factorization->terms()) params.push_back(to_string(t.proj.param));
  j["term_parameterizations"] = params;
  std::cout << j.dump() << std::endl;
  return j;
}

void run_bench_search(const BenchSearchArgs& args) {
  const BrdfPtr brdf = Catalogue::builtin().make(args.brdf);
  BenchSearchArgs a = args;
  a.brdf_reciprocal = brdf->reciprocal();
  SampleSet s = a.sampling == "measured" ? measured_samples(*brdf) : sample_grid(*brdf, a.grid);
  if (a.perturb != 0) {
    // Every value times 1 + perturb * u, u uniform in [-1, 1] from a fixed seed:
    // the same data up to rounding-level noise.
    std::mt19937_64 rng(0x9e77u);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (Rgb& v : s.value)
      for (int c = 0; c < 3; ++c) v[c] *= 1.0 + a.perturb * U(rng);
  }
  const FitData d(s, FitOptions{}.eps);
  if (a.strategy != "both") {
    bench_one_search(a, d, a.strategy);
    return;
  }
  const nlohmann::json o = bench_one_search(a, d, "greedy");
  const nlohmann::json n = bench_one_search(a, d, "structured");
  // Side by side (stderr; stdout keeps the JSON lines).
  std::fprintf(stderr, "%-5s | %10s %9s %10s | %10s %9s %10s\n", "term", "greedy fits", "seconds",
               "rel_mse", "struct fits", "seconds", "rel_mse");
  for (size_t t = 0; t < o["per_term"].size() && t < n["per_term"].size(); ++t) {
    const auto& po = o["per_term"][t];
    const auto& pn = n["per_term"][t];
    std::fprintf(stderr, "%-5zu | %10d %9.2f %10.4g | %10d %9.2f %10.4g\n", t + 1,
                 po["evaluations"].get<int>() + po["backfit_evaluations"].get<int>(),
                 po["seconds"].get<double>(), o["rel_mse_after_term"][t].get<double>(),
                 pn["evaluations"].get<int>() + pn["backfit_evaluations"].get<int>(),
                 pn["seconds"].get<double>(), n["rel_mse_after_term"][t].get<double>());
  }
  std::fprintf(stderr, "%-5s | %10d %9.2f %10.4g | %10d %9.2f %10.4g\n", "all", o["evaluations"].get<int>(),
               o["seconds"].get<double>(), o["rel_mse_after_term"].back().get<double>(),
               n["evaluations"].get<int>(), n["seconds"].get<double>(),
               n["rel_mse_after_term"].back().get<double>());
}
// The line searches side by side on the first term's objective (the
// search's objective for term 1 at the search texture): from `starts` seeded
// random rotations (after `presweeps` golden Powell sweeps when > 0, i.e.
// nearer a minimum, as in the search's later lines), each of Cole's six
// directions is minimized by the golden section and by Brent from the same
// point. Counts the evaluations of each and compares the values they reach,
// line by line: no chaos of the search's path, the per-line quality.
struct BenchLinesArgs : BenchSearchArgs {
  int starts = 10;
  int presweeps = 0;
};

void run_bench_lines(const BenchLinesArgs& a) {
  if (a.starts < 1 || a.starts > 10000)
    throw std::invalid_argument("--starts: expected 1..10000, found " + std::to_string(a.starts));
  if (a.presweeps < 0 || a.presweeps > 30)
    throw std::invalid_argument("--presweeps: expected 0..30, found " + std::to_string(a.presweeps));
  const BrdfPtr brdf = Catalogue::builtin().make(a.brdf);
  const SampleSet s = a.sampling == "measured" ? measured_samples(*brdf) : sample_grid(*brdf, a.grid);
  const FitData d(s, FitOptions{}.eps);
  const SearchOptions opt = bench_search_options(a, "greedy");
  opt.validate();  // texture, line_tol, ... named as for bench search
  const int res = a.search_texture > 0 ? a.search_texture : a.texture;
  const TermObjective f(d, {}, {}, opt, res);
  PowellOptions gold = opt.powell, brent = opt.powell;
  gold.line_search = PowellOptions::LineSearch::Golden;
  brent.line_search = PowellOptions::LineSearch::Brent;
  int lines = 0, eval_gold = 0, eval_brent = 0, lower = 0, equal = 0, higher = 0;
  double worst = 0, gain_gold = 0, gain_brent = 0;
  std::vector<double> rel;
  for (int k = 0; k < a.starts; ++k) {
    std::mt19937_64 rng(a.seed * 1000003ull + static_cast<uint64_t>(k));
    Rotation4 start = Rotation4::random(rng);
    if (a.presweeps > 0) {
      PowellOptions p = gold;
      p.max_sweeps = a.presweeps;
      start = powell_minimize(f, start, p).best;
    }
    const double f0 = f(start);
    for (const Rotation4& D : cole_basis_directions()) {
      const LineDirection dir = LineDirection::from(D);
      double tg, tb;
      const double vg = line_minimize(f, start, f0, dir, gold, &tg, &eval_gold);
      const double vb = line_minimize(f, start, f0, dir, brent, &tb, &eval_brent);
      ++lines;
      if (vb < vg) ++lower;
      else if (vb == vg) ++equal;
      else ++higher;
      const double r = (vb - vg) / std::max(std::abs(vg), 1e-300);
      rel.push_back(r);
      worst = std::max(worst, r);
      gain_gold += f0 - vg;
      gain_brent += f0 - vb;
    }
  }
  std::sort(rel.begin(), rel.end());
  nlohmann::json j;
  j["bench"] = "lines";
  j["brdf"] = a.brdf;
  j["sampling"] = a.sampling;
  j["samples"] = d.size();
  j["parameterization"] = a.param;
  j["search_texture"] = res;
  j["line_tol"] = a.line_tol;
  j["presweeps"] = a.presweeps;
  j["lines"] = lines;
  j["golden_evaluations"] = eval_gold;
  j["brent_evaluations"] = eval_brent;
  j["brent_lower"] = lower;
  j["equal"] = equal;
  j["brent_higher"] = higher;
  j["median_rel_difference"] = rel[rel.size() / 2];  // (brent - golden) / golden
  j["max_rel_higher"] = worst;
  j["improvement_ratio"] = gain_gold > 0 ? gain_brent / gain_gold : 0.0;  // sum of (f0 - v), brent / golden
  std::cout << j.dump() << std::endl;
}

// --beam-width of bench search and bench planted (SearchOptions::beam_width's
// default 0 picks the width by the search's size, effective_beam_width).
std::string beam_width_help() {
  return "structured: configurations kept per step (0: " + by_search_size(kSmallSearchBeamWidth, kLargeSearchBeamWidth) +
         ")";
}

struct BenchPlantedArgs {
  std::string family = "rotation";  // or "mccool", "mixed"
  std::string floor = "schedule";   // or "joint" (the mixed family's)
  int count = 8;
  int first = 0;
  int terms = 2;
  std::string param = "wiwo";
  int grid = 16;
  int texture = 16;
  int restarts = 6;
  int threads = 0;
  int solve_last = 2;
  int beam_width = SearchOptions{}.beam_width;
  int keep = SearchOptions{}.keep;
  uint64_t seed = SearchOptions{}.seed;
  std::string strategy = "both";
  // Mixed family: the variants run (--terms / --parameterization given:
  // only that term count / main parameterization; default both of each).
  bool mixed_terms_given = false, mixed_param_given = false;
};

// The planted family: per member, McCool's error, the greedy and the
// structured search, and the floor (fit at the true projections, best order).
void run_bench_planted(const BenchPlantedArgs& a) {
  // The members: (index, terms, parameterization); McCool's form has 3 terms;
  // the mixed family is every index at 2, 3 and 4 terms, main (2 terms:
  // first) parameterization wiwo and halfdiff.
  struct Member {
    int index, terms;
    Parameterization param;
  };
  std::vector<Member> members;
  for (int i = a.first; i < a.first + a.count; ++i) {
    if (a.family != "mixed") members.push_back({i, a.family == "mccool" ? 3 : a.terms, parse_parameterization(a.param)});
    else
      for (int t : {2, 3, 4})
        for (const char* p : {"wiwo", "halfdiff"})
          if ((!a.mixed_terms_given || t == a.terms) && (!a.mixed_param_given || a.param == p))
            members.push_back({i, t, parse_parameterization(p)});
  }
  const char* names[2] = {"greedy", "structured"};
  // The search options of member m's strategy k (0 greedy, 1 structured).
  const auto search_options = [&](const Member& m, int k) {
    SearchOptions opt;
    opt.strategy = names[k];
    // The greedy search reads the planted parameterization (its best case);
    // the structured one chooses per term.
    if (a.family != "mccool") opt.param = m.param;
    opt.terms = m.terms;
    opt.fit.solve_last = a.solve_last;
    if (k == 1) {
      opt.beam_width = a.beam_width;
      opt.keep = a.keep;
    }
    opt.texture_size = a.texture;
    opt.restarts = a.restarts;
    opt.threads = a.threads;
    opt.seed = a.seed;
    return opt;
  };
  // Every search's options are checked before the table's header and the
  // first floor fit, not when that member's search starts.
  for (const Member& m : members)
    for (int k = 0; k < 2; ++k)
      if (a.strategy == "both" || a.strategy == names[k]) search_options(m, k).validate();
  std::fprintf(stderr, "| member | McCool | greedy | structured | floor | greedy/floor | structured/floor | fits greedy | fits structured | s greedy | s structured |\n");
  std::fprintf(stderr, "|---|---|---|---|---|---|---|---|---|---|---|\n");
  const bool joint_floor = a.floor == "joint" || a.family == "mixed";
  for (const Member& m : members) {
    const int i = m.index;
    const PlantedProductBrdf b = a.family == "mccool"                    ? planted_mccool_brdf(i)
                                 : a.family == "mixed" && m.terms == 2 ? planted_mixed_pair_brdf(i, m.param)
                                                                       : planted_rotation_brdf(i, m.terms, m.param);
    const SampleSet s = sample_grid(b, a.grid);
    FitOptions fo;
    fo.solve_last = a.solve_last;
    const FitData d(s, fo.eps);
    const int terms = m.terms;
    // The floor: fit at the true projections, either every term solved
    // jointly (solve_last = terms) or the schedule's (n = solve_last) in the
    // best term order.
    FitOptions ffo = fo;
    if (joint_floor) ffo.solve_last = std::max(fo.solve_last, terms);
    std::vector<TermSpec> truth = b.specs(a.texture);
    std::sort(truth.begin(), truth.end(), [](const TermSpec& x, const TermSpec& y) {
      return std::lexicographical_compare(x.proj.P.data(), x.proj.P.data() + 8, y.proj.P.data(), y.proj.P.data() + 8);
    });
    double floor = std::numeric_limits<double>::infinity();
    do {
      std::vector<double> e;
      fit_homomorphic(d, truth, ffo, "fit", &e);
      floor = std::min(floor, e.back());
    } while (!joint_floor && std::next_permutation(truth.begin(), truth.end(), [](const TermSpec& x, const TermSpec& y) {
      return std::lexicographical_compare(x.proj.P.data(), x.proj.P.data() + 8, y.proj.P.data(), y.proj.P.data() + 8);
    }));
    std::vector<double> em;
    fit_homomorphic(d, mccool_terms(a.texture), fo, "mccool", &em);
    nlohmann::json j;
    j["bench"] = "planted";
    j["brdf"] = b.to_string();
    j["samples"] = d.size();
    j["texture"] = a.texture;
    j["terms"] = terms;
    j["mccool"] = em.back();
    j["floor"] = floor;
    j["floor_kind"] = joint_floor ? "joint" : "schedule";
    double err[2] = {NAN, NAN}, secs[2] = {NAN, NAN};
    int fits[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      if (a.strategy != "both" && a.strategy != names[k]) continue;
      const SearchResult r = search_factorization(d, search_options(m, k));
      err[k] = r.rel_mse_after_term.back();
      secs[k] = r.seconds;
      fits[k] = r.evaluations;
      // Per found term: its parameterization and the distance of its plane to
      // the nearest true plane of that parameterization (2 - |P P_true^T|^2, 0 = same plane).
      nlohmann::json found = nlohmann::json::array();
      for (const FactorTerm& t : r.factorization->terms())
        found.push_back({{"parameterization", to_string(t.proj.param)},
                         {"plane_distance", b.nearest_plane_distance(t.proj.param, t.proj.P)}});
      j[names[k]] = {{"rel_mse", err[k]},  {"evaluations", r.evaluations}, {"seconds", r.seconds},
                     {"terms", found}, {"rel_mse_after_term", r.rel_mse_after_term}};
    }
    std::cout << j.dump() << std::endl;
    // A strategy not run (--strategy greedy or structured) prints "-", not nan.
    auto cell = [](double v, const char* fmt) {
      if (!std::isfinite(v)) return std::string("-");
      char buf[64];
      std::snprintf(buf, sizeof buf, fmt, v);
      return std::string(buf);
    };
    std::fprintf(stderr, "| %s | %.4g | %s | %s | %.4g | %s | %s | %s | %s | %s | %s |\n", b.to_string().c_str(),
                 em.back(), cell(err[0], "%.4g").c_str(), cell(err[1], "%.4g").c_str(), floor,
                 cell(err[0] / floor, "%.1fx").c_str(), cell(err[1] / floor, "%.2fx").c_str(),
                 cell(fits[0] > 0 ? fits[0] : NAN, "%.0f").c_str(), cell(fits[1] > 0 ? fits[1] : NAN, "%.0f").c_str(),
                 cell(secs[0], "%.1f").c_str(), cell(secs[1], "%.1f").c_str());
  }
}

struct BenchExtrapolationArgs {
  std::vector<std::string> brdfs = {"krylon-blue", "garnet-red", "cayman", "acryl-blue", "mystique"};
  int texture = 16;
  int restarts = 6;
  int grid = 12;
  int threads = 0;
  std::vector<double> priors = {0.0, 1.0};  // off (the default) and on
};

// The whole-domain check of bounded extrapolation (docs/results.md): each BRDF
// fitted on its raw measured samples (McCool; greedy search in wiwo and in
// halfdiff, 3 terms, whose refit after 2 terms is the 2-texture row) for each
// extrapolation_prior (each fit scored with the log-range clamp off and on,
// FitOptions::clamp_log_range: the same texels), then scored over a grid^4 set of direction pairs at
// cell centres in (cos theta_i, phi_i, cos theta_o, phi_o): max_ratio = the
// largest approx_c / max_k f_c(k) (channel c, max over the valid raw samples),
// over_100x = the fraction of pairs where some channel exceeds 100 x the
// BRDF's own value there (its interpolant) plus 1e-3 x that channel's maximum.
// rel_mse: the fit on all samples, scored on them; held_rel_mse: the same
// method fitted on 4/5 of the valid samples, scored on the other fifth (every
// 5th valid sample).
void run_bench_extrapolation(const BenchExtrapolationArgs& a) {
  if (a.grid < 1 || a.grid > 64) throw std::invalid_argument("--grid: expected 1..64, found " + std::to_string(a.grid));
  if (a.texture < 2 || a.texture > 256)
    throw std::invalid_argument("--texture: expected 2..256, found " + std::to_string(a.texture));
  if (a.priors.empty()) throw std::invalid_argument("--priors: expected at least one value, found none");
  std::vector<Vec3> dirs;
  for (int t = 0; t < a.grid; ++t)
    for (int p = 0; p < a.grid; ++p) {
      const double ct = (t + 0.5) / a.grid, st = std::sqrt(1 - ct * ct), ph = 2 * M_PI * (p + 0.5) / a.grid;
      dirs.emplace_back(st * std::cos(ph), st * std::sin(ph), ct);
    }
  std::fprintf(stderr, "| BRDF | method | textures | prior | log-range clamp | rel_mse (training) | rel_mse (held out) | max approx/max(original) | pairs > 100x |\n");
  std::fprintf(stderr, "|---|---|---:|---:|---|---:|---:|---:|---:|\n");
  for (const std::string& name : a.brdfs) {
    const BrdfPtr brdf = Catalogue::builtin().make(name);
    const SampleSet s = measured_samples(*brdf);
    Rgb fmax(0, 0, 0);
    for (size_t k = 0; k < s.size(); ++k)
      if (s.valid[k])
        for (int c = 0; c < 3; ++c) fmax[c] = std::max(fmax[c], s.value[k][c]);
    std::vector<Rgb> orig;
    orig.reserve(dirs.size() * dirs.size());
    for (const Vec3& wi : dirs)
      for (const Vec3& wo : dirs) orig.push_back(brdf->eval(wi, wo));
    // Held out: every 5th valid sample (the fit on the other 4/5 is scored on it).
    SampleSet train, held;
    for (size_t k = 0, v = 0; k < s.size(); ++k) {
      if (!s.valid[k]) continue;
      SampleSet& t = (v++ % 5 == 4) ? held : train;
      t.wi.push_back(s.wi[k]);
      t.wo.push_back(s.wo[k]);
      t.value.push_back(s.value[k]);
      t.valid.push_back(1);
      if (!s.weight.empty()) t.weight.push_back(s.weight[k]);
    }
    const LogTransform lt = LogTransform::of(s, FitOptions{}.eps);
    // Every factorization of the bench for one sample set, in a fixed order.
    const auto fit_all = [&](const SampleSet& fs, double prior) {
      std::vector<std::pair<std::string, std::shared_ptr<const HomomorphicFactorization>>> out;
      FitOptions fo;
      fo.extrapolation_prior = prior;
      const FitData d(fs, fo.eps);
      out.emplace_back("mccool", fit_homomorphic(d, mccool_terms(a.texture), fo, "mccool"));
      for (const Parameterization param : {Parameterization::WiWo, Parameterization::HalfDiff}) {
        SearchOptions so;
        so.strategy = "greedy";
        so.terms = 3;
        so.param = param;
        so.texture_size = a.texture;
        so.restarts = a.restarts;
        so.threads = a.threads;
        so.fit = fo;
        std::shared_ptr<HomomorphicFactorization> two;
        so.stop_after_term = [&](const HomomorphicFactorization& f) {
          if (f.terms().size() == 2) two = std::make_shared<HomomorphicFactorization>(f);
          return false;
        };
        const SearchResult r = search_factorization(d, so);
        const std::string method = "search " + to_string(param);
        if (two) out.emplace_back(method, two);
        out.emplace_back(method, r.factorization);
      }
      return out;
    };
    for (double prior : a.priors) {
      const auto all = fit_all(s, prior);
      const auto part = fit_all(train, prior);
      for (size_t m = 0; m < all.size(); ++m)
       for (const bool clamp : {false, true}) {
        // The clamp does not change the solve (same texels, and the searches rank by the
        // unclamped least-squares objective): the unclamped row is the same fit without its log range.
        const auto unclamped = [](const HomomorphicFactorization& h) {
          return std::make_shared<HomomorphicFactorization>(h.terms(), h.A(), h.eps(), h.subtract_eps(),
                                                            h.method());
        };
        const auto fp = clamp ? all[m].second : unclamped(*all[m].second);
        const auto hp = clamp ? part[m].second : unclamped(*part[m].second);
        const Factorization& f = *fp;
        const int textures = static_cast<int>(all[m].second->terms().size());
        double max_ratio = 0;
        size_t over = 0, i = 0;
        for (const Vec3& wi : dirs)
          for (const Vec3& wo : dirs) {
            const Rgb v = f.eval(wi, wo);
            bool big = false;
            for (int c = 0; c < 3; ++c) {
              max_ratio = std::max(max_ratio, v[c] / fmax[c]);
              big = big || v[c] > 100 * orig[i][c] + 1e-3 * fmax[c];
            }
            over += big;
            ++i;
          }
        const Metrics mt = evaluate_metrics(f, s, lt);
        const Metrics mh = evaluate_metrics(*hp, held, lt);
        nlohmann::json j;
        j["bench"] = "extrapolation";
        j["brdf"] = name;
        j["samples"] = mt.samples;
        j["method"] = all[m].first;
        j["textures"] = textures;
        j["texture_size"] = a.texture;
        j["restarts"] = a.restarts;
        j["extrapolation_prior"] = prior;
        j["clamp_log_range"] = clamp;
        j["rel_mse"] = mt.rel_mse;
        j["held_rel_mse"] = mh.rel_mse;
        j["held_samples"] = mh.samples;
        j["max_ratio"] = max_ratio;
        j["over_100x"] = double(over) / double(i);
        j["grid"] = a.grid;
        std::cout << j.dump() << std::endl;
        std::fprintf(stderr, "| %s | %s | %d | %g | %s | %.4g | %.4g | %.3g | %.1f%% |\n", name.c_str(),
                     all[m].first.c_str(), textures, prior, clamp ? "on" : "off", mt.rel_mse, mh.rel_mse, max_ratio,
                     100.0 * double(over) / double(i));
      }
    }
  }
}
// "bench fit": one homomorphic fit, timed.
void add_bench_fit(CLI::App* bench) {
  auto* fit = bench->add_subcommand("fit", "Time the inner-loop homomorphic fit (one core)");
  auto a = std::make_shared<BenchFitArgs>();
  fit->add_option("--brdf", a->brdf, "catalogue name or measured file")->capture_default_str();
  fit->add_option("--grid", a->grid, "regular res^4 parabolic grid")->capture_default_str();
  fit->add_option("--samples", a->samples, "stratified random pairs instead of the grid (0 = grid)")
      ->capture_default_str();
  fit->add_option("--texture", a->texture, "texture resolution")->capture_default_str();
  fit->add_option("--terms", a->terms, "number of terms (textures)")->capture_default_str();
  fit->add_option("--solve-last", a->solve_last, "terms solved jointly (n)")->capture_default_str();
  fit->add_option("--parameterization", a->param, "wiwo or halfdiff")->capture_default_str();
  fit->add_flag("--reciprocity", a->reciprocity, "read each texture through the conjugate too");
  fit->add_option("--repeats", a->repeats, "timed repetitions")->capture_default_str();
  fit->add_option("--seed", a->seed, "seed of the random projections")
      ->check(non_negative_integer())
      ->capture_default_str();
  fit->add_option("--solver", a->solver, "auto, dense, sparse or qr")->capture_default_str();
  fit->add_option("--smoothing", a->smoothing, "Laplacian weight")->capture_default_str();
  fit->add_flag("--exact-error", a->exact_error,
                "score by a pass over the samples with the reconstruction's clamping (default: "
                "the least-squares objective from the normal equations, as the search does)");
  fit->add_option("--dump-input", a->dump_input,
                  "also write the joint solve's input (samples, projections, masks) and its rel_mse as JSON "
                  "to this file (scripts/bench-peer.py reads it)");
  fit->callback([a] { run_bench_fit(*a); });
}

// "bench search": the projection search (greedy, structured or both), timed.
void add_bench_search(CLI::App* bench) {
  auto* search = bench->add_subcommand("search", "Time the greedy projection search (all cores)");
  auto b = std::make_shared<BenchSearchArgs>();
  search->add_option("--brdf", b->brdf, "catalogue name or measured file")->capture_default_str();
  search->add_option("--grid", b->grid, "regular res^4 parabolic grid")->capture_default_str();
  search->add_option("--sampling", b->sampling, "grid (--grid) or measured (a measured BRDF's own samples: the "
                      "records alone, no orbit, weights or fill, as the thesis fitted "
                      "them; `run` adds them)")
      ->check(CLI::IsMember({"grid", "measured"}))
      ->capture_default_str();
  search->add_option("--texture", b->texture, "final texture resolution")->capture_default_str();
  search->add_option("--search-texture", b->search_texture, "texture during the search (0 = final)")
      ->capture_default_str();
  search->add_option("--terms", b->terms, "textures to build")->capture_default_str();
  search->add_option("--restarts", b->restarts, "random starts per term")->capture_default_str();
  search->add_option("--guesses", b->guesses, "extra starts: wi, wo, wi+wo");
  search->add_option("--solve-last", b->solve_last, "terms solved jointly (n)")->capture_default_str();
  search->add_option("--parameterization", b->param, "wiwo or halfdiff")->capture_default_str();
  search->add_flag("--reciprocity", b->reciprocity, "read each texture through the conjugate too");
  search->add_option("--final-reciprocity", b->final_reciprocity,
                     "structured: refit each answer with its terms reciprocal and keep it when lower; auto = "
                     "when the BRDF is reciprocal (the config default)")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  search->add_option("--seed", b->seed, "seed of the random starts")
      ->check(non_negative_integer())
      ->capture_default_str();
  search->add_option("--optimizer", b->optimizer, "powell, praxis, bobyqa, neldermead, sbplx, direct, crs")
      ->capture_default_str();
  search->add_option("--threads", b->threads, "threads for the restarts (0 = all cores)")->capture_default_str();
  search->add_option("--ftol", b->ftol, "relative improvement per sweep to go on")->capture_default_str();
  search->add_option("--line-tol", b->line_tol, "golden-section bracket width (t)")->capture_default_str();
  search->add_option("--line-search", b->line_search, "line refinement: golden or brent")->capture_default_str();
  search->add_option("--smoothing", b->smoothing, "Laplacian weight")->capture_default_str();
  search->add_option("--beam", b->beam, "first-term candidates continued (1 = greedy)")->capture_default_str();
  search->add_option("--backfit-sweeps", b->backfit_sweeps, "cyclic re-search sweeps after each term")
      ->capture_default_str();
  search->add_option("--backfit-restarts", b->backfit_restarts, "random starts per re-search")
      ->capture_default_str();
  search->add_option("--strategy", b->strategy,
                     "structured (default), greedy (Cole's, the thesis's) or both (side by side on stderr)")
      ->check(CLI::IsMember({"structured", "greedy", "both"}))
      ->capture_default_str();
  search->add_option("--term-param", b->term_param,
                     "structured: either (each term picks wiwo or halfdiff) or fixed (--parameterization); "
                     "default fixed when --parameterization is given, else either")
      ->check(CLI::IsMember({"either", "fixed"}))
      ->capture_default_str();
  search->add_option("--keep", b->keep, "structured: Powell runs per term (best screened starts)")
      ->capture_default_str();
  search->add_option("--beam-width", b->beam_width, beam_width_help())->capture_default_str();
  search->add_option("--polish-sweeps", b->polish_sweeps,
                     "structured: joint re-search sweeps at the end (-1: " +
                         by_search_size(kSmallSearchPolishSweeps, kLargeSearchPolishSweeps) + ")")
      ->capture_default_str();
  search->add_option("--perturb", b->perturb,
                     "multiply every sample value by 1 + p u, u uniform in [-1, 1] (fixed seed): "
                     "does the search end in the same place under rounding-level changes?")
      ->check(CLI::Range(0.0, 0.1))
      ->capture_default_str();
  search->callback([b, search] {
    // As in a config: an explicit --parameterization is every term's (fixed),
    // and --term-param either with it is a contradiction, not an override.
    const bool param_given = search->get_option("--parameterization")->count() > 0;
    const bool term_param_given = search->get_option("--term-param")->count() > 0;
    if (param_given && term_param_given && b->term_param == "either")
      throw std::invalid_argument("--term-param: either lets the search choose each term's parameterization, which "
                                  "contradicts --parameterization " + b->param +
                                  "; expected --term-param fixed or no --term-param (every term reads "
                                  "--parameterization), or no --parameterization (the search chooses per term)");
    if (param_given && !term_param_given) b->term_param = "fixed";
    run_bench_search(*b);
  });
}

// "bench lines": golden section against Brent on the search objective.
void add_bench_lines(CLI::App* bench) {
  auto* lines = bench->add_subcommand(
      "lines", "Golden section against Brent, line by line, on the first term's search objective");
  auto la = std::make_shared<BenchLinesArgs>();
  lines->add_option("--brdf", la->brdf, "catalogue name or measured file")->capture_default_str();
  lines->add_option("--grid", la->grid, "regular res^4 parabolic grid")->capture_default_str();
  lines->add_option("--sampling", la->sampling, "grid (--grid) or measured (a measured BRDF's own samples: the "
                      "records alone, no orbit, weights or fill, as the thesis fitted "
                      "them; `run` adds them)")
      ->check(CLI::IsMember({"grid", "measured"}))
      ->capture_default_str();
  lines->add_option("--texture", la->texture, "texture resolution of the objective")->capture_default_str();
  lines->add_option("--parameterization", la->param, "wiwo or halfdiff")->capture_default_str();
  lines->add_option("--seed", la->seed, "seed of the random starts")
      ->check(non_negative_integer())
      ->capture_default_str();
  lines->add_option("--line-tol", la->line_tol, "golden-section bracket width (t)")->capture_default_str();
  lines->add_option("--starts", la->starts, "random starting rotations (6 lines each)")->capture_default_str();
  lines->add_option("--presweeps", la->presweeps, "golden Powell sweeps from each start before the lines")
      ->capture_default_str();
  lines->callback([la] { run_bench_lines(*la); });
}

// "bench planted": searches on planted product BRDFs.
void add_bench_planted(CLI::App* bench) {
  auto* planted = bench->add_subcommand(
      "planted", "Planted product BRDFs: McCool, greedy and structured search, floor (fit at the true projections)");
  auto pa = std::make_shared<BenchPlantedArgs>();
  planted->add_option("--family", pa->family,
                      "rotation (random rotation planes), mccool (p(wi) q(h) p(wo), 3 terms) or mixed (each member "
                      "at 2, 3 and 4 terms, main parameterization wiwo and halfdiff (2 terms: one plane in each), joint floor)")
      ->check(CLI::IsMember({"rotation", "mccool", "mixed"}))
      ->capture_default_str();
  planted->add_option("--floor", pa->floor,
                      "schedule (fit at the true projections, n = solve_last, best order) or joint (every term "
                      "solved jointly; the mixed family's)")
      ->check(CLI::IsMember({"schedule", "joint"}))
      ->capture_default_str();
  planted->add_option("--count", pa->count, "members")->capture_default_str();
  planted->add_option("--first", pa->first, "index of the first member")->capture_default_str();
  planted->add_option("--terms", pa->terms, "rotation family: 2, 3 or 4 terms; mixed family: run only 2, 3 or 4")
      ->capture_default_str();
  planted->add_option("--parameterization", pa->param,
                      "rotation family: wiwo or halfdiff; mixed family: run only this main parameterization")
      ->check(CLI::IsMember({"wiwo", "halfdiff"}))
      ->capture_default_str();
  planted->add_option("--grid", pa->grid, "regular res^4 parabolic grid")->capture_default_str();
  planted->add_option("--texture", pa->texture, "texture resolution (search and floor)")->capture_default_str();
  planted->add_option("--restarts", pa->restarts, "random starts per term")->capture_default_str();
  planted->add_option("--solve-last", pa->solve_last, "terms solved jointly (n), search and floor")->capture_default_str();
  planted->add_option("--beam-width", pa->beam_width, beam_width_help())->capture_default_str();
  planted->add_option("--keep", pa->keep, "structured: Powell runs per step")->capture_default_str();
  planted->add_option("--seed", pa->seed, "seed of the searches' random starts")
      ->check(non_negative_integer())
      ->capture_default_str();
  planted->add_option("--threads", pa->threads, "threads (0 = all cores)")->capture_default_str();
  planted->add_option("--strategy", pa->strategy, "greedy, structured or both")
      ->check(CLI::IsMember({"structured", "greedy", "both"}))
      ->capture_default_str();
  planted->callback([pa, planted] {
    // Checked before the table's header is printed, by the option's name.
    if (pa->first < 0)
      throw std::invalid_argument("--first: expected a member index >= 0, found " + std::to_string(pa->first));
    if (pa->count < 1 || pa->count > std::numeric_limits<int>::max() - pa->first)
      throw std::invalid_argument("--count: expected >= 1 (and --first + --count within an int), found " +
                                  std::to_string(pa->count));
    if (pa->grid < 2 || pa->grid > kMaxSampleGridResolution)
      throw std::invalid_argument("--grid: expected 2.." + std::to_string(kMaxSampleGridResolution) + ", found " +
                                  std::to_string(pa->grid));
    if (pa->texture < 2 || pa->texture > 1024)
      throw std::invalid_argument("--texture: expected 2..1024, found " + std::to_string(pa->texture));
    if (pa->family == "mixed") {
      pa->mixed_terms_given = planted->get_option("--terms")->count() > 0;
      pa->mixed_param_given = planted->get_option("--parameterization")->count() > 0;
      if (pa->mixed_terms_given && (pa->terms < 2 || pa->terms > 4))
        throw std::invalid_argument("--terms: the mixed family has members of 2, 3 and 4 terms; found " +
                                    std::to_string(pa->terms));
    }
    run_bench_planted(*pa);
  });
}

// "bench extrapolation": bounded extrapolation of measured BRDFs.
void add_bench_extrapolation(CLI::App* bench) {
  auto* extrap = bench->add_subcommand(
      "extrapolation",
      "Measured BRDFs fitted on their raw samples (McCool, greedy search wiwo and halfdiff, 2 and 3 textures) "
      "for each extrapolation_prior, log-range clamp off and on: training rel_mse and the largest approx / max(original) over a grid^4 set "
      "of direction pairs");
  auto ea = std::make_shared<BenchExtrapolationArgs>();
  extrap->add_option("--brdf", ea->brdfs, "measured BRDFs (catalogue names or files)")->capture_default_str();
  extrap->add_option("--texture", ea->texture, "texture resolution")->capture_default_str();
  extrap->add_option("--restarts", ea->restarts, "random starts per term of the searches")->capture_default_str();
  extrap->add_option("--grid", ea->grid, "grid^4 direction pairs (cell centres in cos theta and phi)")
      ->capture_default_str();
  extrap->add_option("--threads", ea->threads, "threads for the restarts (0 = all cores)")->capture_default_str();
  extrap->add_option("--priors", ea->priors, "extrapolation_prior values to compare (0 = off)")
      ->capture_default_str();
  extrap->callback([ea] { run_bench_extrapolation(*ea); });
}

}  // namespace

void add_cmd_bench(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Benchmarks that print JSON lines");
  bench->require_subcommand(1);
  add_bench_fit(bench);
  add_bench_search(bench);
  add_bench_lines(bench);
  add_bench_planted(bench);
  add_bench_extrapolation(bench);
}

}  // namespace bf
