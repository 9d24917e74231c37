// Subcommand `bench fit`: times the inner-loop fit (DESIGN.md §5) and prints
// one JSON object per line.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <ctime>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "experiments/commands.h"
#include "factor/homomorphic_fit.h"
#include "search/rotation4.h"

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
};

void run_bench_fit(const BenchFitArgs& a) {
  if (a.repeats < 1) throw std::invalid_argument("--repeats: expected >= 1, found " + std::to_string(a.repeats));
  if (a.terms < 1) throw std::invalid_argument("--terms: expected >= 1, found " + std::to_string(a.terms));
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
  std::vector<double> ms, cpu;
  JointSolution sol;
  for (int r = 0; r < a.repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    // exact_error = false: the search's objective, read off the normal equations.
    sol = solve_joint(d, fixed_values, joint, opt, a.exact_error);
    cpu.push_back(thread_cpu_ms() - c0);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
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
  j["unknowns"] = sol.unknowns;
  j["ms_median"] = median;
  j["ms_min"] = *std::min_element(ms.begin(), ms.end());
  j["cpu_ms_median"] = median_of(cpu);
  j["cpu_ms_min"] = *std::min_element(cpu.begin(), cpu.end());
  j["exact_error"] = a.exact_error;
  j["repeats"] = a.repeats;
  j["rel_mse"] = sol.rel_mse;
  j["threads"] = 1;
  std::cout << j.dump() << std::endl;
}
}  // namespace

void add_cmd_bench(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Benchmarks that print JSON lines");
  bench->require_subcommand(1);
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
  fit->add_option("--seed", a->seed, "seed of the random projections")->capture_default_str();
  fit->add_option("--solver", a->solver, "auto, dense, sparse or qr")->capture_default_str();
  fit->add_option("--smoothing", a->smoothing, "Laplacian weight")->capture_default_str();
  fit->add_flag("--exact-error", a->exact_error,
                "score by a pass over the samples with the reconstruction's clamping (default: "
                "the least-squares objective from the normal equations, as the search does)");
  fit->callback([a] { run_bench_fit(*a); });
}

}  // namespace bf
