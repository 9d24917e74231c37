// Tests of the nonlinear refinement: the analytic Jacobian against Ceres'
// GradientChecker, a planted solution, agreement with the log-space fit at
// blend weight 0, and the W1 (bluepaint) trade-off between lin_rmse and rel_mse.
#include <ceres/ceres.h>

#include <random>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"
#include "factor/metrics.h"
#include "factor/refine.h"
#include "factor/refine_internal.h"
#include "fit_helpers.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;

namespace {

std::vector<TermSpec> halfdiff_terms(int res) {
  return {{projection_first_pair(Parameterization::HalfDiff, res), false, std::nullopt},
          {projection_second_pair(Parameterization::HalfDiff, res), false, std::nullopt}};
}

std::string row(const char* tag, const Metrics& m) {
  std::ostringstream os;
  os << tag << ": rel_mse " << m.rel_mse << " lin_rmse " << m.lin_rmse << " cos_rmse "
     << m.cos_rmse << " lin_max " << m.lin_max;
  return os.str();
}

}  // namespace

TEST_CASE("refine: invalid options name the field, value and rule") {
  RefineOptions o;
  o.objective = "l2";
  REQUIRE_THROWS_WITH(o.validate(), Contains("objective") && Contains("'l2'"));
  o = RefineOptions{};
  o.blend_weight = -1;
  REQUIRE_THROWS_WITH(o.validate(), Contains("blend_weight") && Contains("[0, 1000000]") && Contains("found -1"));
  o = RefineOptions{};
  o.max_iterations = 0;
  REQUIRE_THROWS_WITH(o.validate(), Contains("max_iterations"));
  o = RefineOptions{};
  o.smoothing = std::nan("");
  REQUIRE_THROWS_WITH(o.validate(), Contains("smoothing"));
  o = RefineOptions{};
  o.threads = -2;
  REQUIRE_THROWS_WITH(o.validate(), Contains("threads"));
  o = RefineOptions{};
  o.function_tolerance = 0;
  REQUIRE_THROWS_WITH(o.validate(), Contains("function_tolerance"));
}

TEST_CASE("refine: the analytic Jacobian of a sample residual passes GradientChecker") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  using detail::RefineObjective;
  for (const RefineObjective objective : {RefineObjective::Linear, RefineObjective::Cosine, RefineObjective::Blend})
    for (bool subtract_eps : {true, false})
      for (int trial = 0; trial < 4; ++trial) {
        // A stencil of 4..12 distinct texels with positive weights.
        const int n = 4 + 4 * (trial % 3);
        std::vector<double> w(n);
        for (double& x : w) x = 0.05 + U(rng);
        std::vector<double> y(n);
        for (double& x : y) x = -2.5 + 3.0 * U(rng);
        const double f = trial == 3 ? 0.0 : 0.1 + 5.0 * U(rng);  // f = 0 happens (masked-out peaks)
        const double eps = trial == 2 ? 0.3 : 1e-5;               // large eps exercises log(e^s + eps)
        const auto cost = detail::make_refine_sample_cost(
            w, f, 0.01 + U(rng), 0.2 + 0.8 * U(rng), 0.5 + U(rng), 0.7, eps, subtract_eps,
            objective, 0.1 + U(rng));
        REQUIRE(cost->num_residuals() == (objective == RefineObjective::Blend ? 2 : 1));
        std::vector<const double*> params;
        for (double& x : y) params.push_back(&x);
        ceres::NumericDiffOptions nd;
        ceres::GradientChecker checker(cost.get(), static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), nd);
        // ProbeResults' matrices are allocated inside libceres (Eigen's 16-byte
        // world). In a -march=native build our Eigen frees with its AVX-aligned
        // offset allocator (CMakeLists.txt, BRDF_FACTOR_NATIVE), which would
        // free a wrong pointer: there the results are deliberately leaked.
        auto* res = new ceres::GradientChecker::ProbeResults;
        INFO("objective " << static_cast<int>(objective) << " subtract_eps=" << subtract_eps << " trial " << trial);
        const bool ok = checker.Probe(params.data(), 1e-6, res);
        INFO(res->error_log);
        CHECK(ok);
        CHECK(res->maximum_relative_error < 1e-6);
#ifndef BRDF_FACTOR_NATIVE_BUILD
        delete res;
#endif
      }
}

TEST_CASE("refine: a perturbed planted factorization is recovered under the linear objective") {
  // Truth: a 2-term factorization (wi, wo textures). Data: its own values on a
  // grid. Start: the truth with noisy texels and part of one mask removed (so
  // refine must add texels). With no smoothing the optimum is the truth.
  const bf_test::PlantedBrdf planted;
  const SampleSet fit_s = sample_grid(planted, 8);
  const FitData d(fit_s, 1e-5);
  const std::vector<TermSpec> specs = {
      {projection_first_pair(Parameterization::WiWo, 8), false, std::nullopt},
      {projection_second_pair(Parameterization::WiWo, 8), false, std::nullopt}};
  FitOptions unclamped;
  unclamped.clamp_log_range = false;  // the refinement's smooth model is the truth: no flat clamped parts
  const auto truth = fit_homomorphic(d, specs, unclamped);
  SampleSet s = fit_s;
  evaluate_into(*truth, s);

  std::vector<FactorTerm> noisy = truth->terms();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 0.15);
  for (FactorTerm& t : noisy)
    for (int c = 0; c < 3; ++c)
      for (size_t i = 0; i < t.texels[c].size(); ++i)
        if (t.mask[i]) t.texels[c][i] += static_cast<float>(N(rng));
  for (int i = 0; i < 8; ++i) {  // drop the first row of term 0 from its mask
    noisy[0].mask[i] = 0;
    for (int c = 0; c < 3; ++c) noisy[0].texels[c][i] = 0.0f;
  }
  const HomomorphicFactorization start(noisy, truth->A(), truth->eps(), truth->subtract_eps(),
                                       "planted");
  const LogTransform t = LogTransform::of(s, 1e-5);
  const Metrics m0 = evaluate_metrics(start, s, t);

  RefineOptions opt;
  opt.objective = "linear";
  opt.smoothing = 0;
  opt.function_tolerance = 1e-12;
  opt.max_iterations = 100;
  RefineReport rep;
  const auto out = refine(start, s, opt, &rep);
  const Metrics m1 = evaluate_metrics(*out, s, t);
  INFO(row("start", m0) << "\n" << row("refined", m1) << "\n" << rep.termination);
  CHECK(rep.texels_added > 0);
  CHECK(rep.final_cost < 1e-8 * rep.initial_cost);
  CHECK(m1.lin_rmse < 1e-3 * m0.lin_rmse);
  CHECK(m1.rel_mse < 1e-6);
  CHECK(out->method() == "planted+refine-linear");
  CHECK(out->storage_floats() > start.storage_floats());  // the added texels are stored
}

TEST_CASE("refine: blend weight 0 leaves the log-space fit where it is") {
  // The blend objective at weight 0 is the log fit's own objective (same data
  // term, same Laplacian weight): the fit is already its minimizer.
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 8);
  const FitData d(s, 1e-5);
  const auto start = fit_homomorphic(d, halfdiff_terms(8), FitOptions{}, "fit");
  RefineOptions opt;
  opt.objective = "blend";
  opt.blend_weight = 0;
  RefineReport rep;
  const auto out = refine(*start, s, opt, &rep);
  const Metrics m0 = evaluate_metrics(*start, s, d.transform);
  const Metrics m1 = evaluate_metrics(*out, s, d.transform);
  INFO(row("start", m0) << "\n" << row("refined", m1) << "\n" << rep.termination);
  CHECK(rep.final_cost <= rep.initial_cost);
  CHECK(rep.final_cost > (1 - 1e-5) * rep.initial_cost);  // only float rounding to undo
  CHECK(bf_test::near_rel(m1.rel_mse, m0.rel_mse, 1e-4));
  CHECK(bf_test::near_rel(m1.lin_rmse, m0.lin_rmse, 1e-3));
}

TEST_CASE("refine: each objective lowers its own metric (bluepaint, grid 8, texture 8)") {
  // Measured (Release): fixed halfdiff (h, d) projections, blend 0.01:
  // lin_rmse 0.255 -> 0.143 (-44%), rel_mse 0.0193 -> 0.0192; linear: lin
  // -74%; cosine: cos_rmse -33%.
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 8);
  const FitData d(s, 1e-5);
  const auto start = fit_homomorphic(d, halfdiff_terms(8), FitOptions{}, "fit");
  const Metrics m0 = evaluate_metrics(*start, s, d.transform);
  for (const char* objective : {"linear", "cosine", "blend"}) {
    RefineOptions opt;
    opt.objective = objective;
    opt.blend_weight = 0.01;
    RefineReport rep;
    const auto out = refine(*start, s, opt, &rep);
    const Metrics m1 = evaluate_metrics(*out, s, d.transform);
    INFO(objective << "\n" << row("start", m0) << "\n" << row("refined", m1) << "\n"
                   << rep.termination);
    CHECK(rep.final_cost < rep.initial_cost);
    CHECK(rep.iterations >= 1);
    CHECK(rep.parameters > 0);
    CHECK(std::string(objective) == rep.objective);
    if (std::string(objective) == "linear") CHECK(m1.lin_rmse < 0.5 * m0.lin_rmse);
    if (std::string(objective) == "cosine") CHECK(m1.cos_rmse < 0.8 * m0.cos_rmse);
    if (std::string(objective) == "blend") {
      CHECK(m1.lin_rmse < 0.8 * m0.lin_rmse);
      CHECK(m1.rel_mse < 1.1 * m0.rel_mse);
    }
  }
}

TEST_CASE("refine: W1 bluepaint, grid 16, texture 16: blend trades rel_mse for lin_rmse",
          "[slow]") {
  // Measured (Release, default options: blend, weight 0.03, smoothing 1e-3):
  //   fit (h, d): lin_rmse 0.159 -> 0.120 (-24%), rel_mse 0.0179 -> 0.0185 (+3%)
  //   mccool    : lin_rmse 0.312 -> 0.296 (-5%),  rel_mse 0.0759 -> 0.0800 (+5%)
  // McCool's two textures cannot follow bluepaint's retro-reflective lobe; on
  // it, a 20% lower lin_rmse costs about +45% rel_mse (weight 0.05), so the
  // issue's target (-20% lin, at most +10% rel) holds for the fixed halfdiff
  // projections only; this test asserts that and McCool's smaller gain.
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 16);
  const FitData d(s, 1e-5);
  struct Case {
    const char* name;
    std::vector<TermSpec> terms;
    double lin_factor, rel_factor;
  };
  const Case cases[] = {{"fit-hd", halfdiff_terms(16), 0.8, 1.1},
                        {"mccool", mccool_terms(16), 0.98, 1.1}};
  // The start without the log-range clamp (docs/design.md §3.2): on W1 the
  // clamp alone already lowers fit-hd's lin_rmse 0.159 -> 0.133 (it cuts the
  // overshoot of the lobe's peak), which this test does not measure.
  FitOptions fo;
  fo.clamp_log_range = false;
  for (const Case& c : cases) {
    const auto start = fit_homomorphic(d, c.terms, fo, c.name);
    RefineReport rep;
    const auto out = refine(*start, s, RefineOptions{}, &rep);
    const Metrics m0 = evaluate_metrics(*start, s, d.transform);
    const Metrics m1 = evaluate_metrics(*out, s, d.transform);
    INFO(c.name << "\n" << row("start", m0) << "\n" << row("refined", m1) << "\n"
                << rep.termination << " (" << rep.seconds << " s)");
    CHECK(m1.lin_rmse < c.lin_factor * m0.lin_rmse);
    CHECK(m1.rel_mse < c.rel_factor * m0.rel_mse);
  }
}

TEST_CASE("refine: bad input gives a clear error") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 6);
  const FitData d(s, 1e-5);
  const auto start = fit_homomorphic(d, halfdiff_terms(6), FitOptions{}, "fit");
  SampleSet none = s;
  std::fill(none.valid.begin(), none.valid.end(), 0);
  REQUIRE_THROWS_WITH(refine(*start, none, RefineOptions{}), Contains("no valid sample"));
  RefineOptions o;
  o.objective = "cos";
  REQUIRE_THROWS_WITH(refine(*start, s, o), Contains("objective"));
  const HomomorphicFactorization empty({}, Rgb::Ones(), 1e-5, true, "empty");
  REQUIRE_THROWS_WITH(refine(empty, s, RefineOptions{}), Contains("no terms"));
}
