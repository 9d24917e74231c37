// Tests of the sparse solver path of the joint fit (FitOptions::Solver::Sparse:
// the normal matrix assembled directly in compressed columns, CHOLMOD or
// Eigen's SimplicialLLT): the same solution as the dense path and the
// reference QR path, with and without the extrapolation prior and with a
// JointPrefix, and a matrix that is not positive definite reported; the
// column-by-column assembly against the triplet assembly it replaced.
#include <cmath>
#include <random>

#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"
#include "factor/solver_choice.h"
#include "fit_helpers.h"
#include "sparse_reference.h"
#include "test_common.h"

using namespace bf;

namespace {

// Planted problem: p(wi) q(h) p(wo) is one reciprocal wiwo term plus one
// halfdiff term (mccool_terms), here under random rotations of both so that
// lookups of the two terms and of the reciprocal pair overlap irregularly.
std::vector<TermSpec> planted_terms(std::mt19937_64& rng, int res) {
  TermSpec p{bf_test::random_projection(rng, Parameterization::WiWo, res), true, std::nullopt};
  TermSpec q{bf_test::random_projection(rng, Parameterization::HalfDiff, res), false, std::nullopt};
  return {p, q};
}

// max over samples and channels of |sum of the joint terms' lookups| differences,
// in double from the float texels (the gauge may split constants differently).
double worst_function_difference(const FitData& d, const JointSolution& a, const JointSolution& b) {
  const auto fa = fixed_sum(d, a.terms);
  const auto fb = fixed_sum(d, b.terms);
  double worst = 0;
  for (int c = 0; c < 3; ++c)
    for (size_t k = 0; k < d.size(); ++k) worst = std::max(worst, std::abs(fa[c][k] - fb[c][k]));
  return worst;
}

// |a - b| / |b| (b != 0).
double rel_diff(double a, double b) {
  return std::abs(a - b) / std::abs(b);
}

}  // namespace

TEST_CASE("sparse fit: equals the dense and reference QR paths on a planted reciprocal problem") {
  const bf_test::McCoolFormBrdf brdf;
  const SampleSet s = sample_stratified(brdf, 2500, 29);
  std::mt19937_64 rng(31);
  // McCool's terms recover the planted function; randomly rotated ones do not,
  // but make the two terms' lookups and the reciprocal pair overlap irregularly.
  for (const bool planted : {true, false}) {
    const std::vector<TermSpec> joint = planted ? mccool_terms(9) : planted_terms(rng, 9);
    for (const double prior : {0.0, 0.5}) {
      FitOptions opt;
      opt.extrapolation_prior = prior;
      const FitData d(s, opt.eps);
      std::array<std::vector<double>, 3> zero;
      for (auto& z : zero) z.assign(d.size(), 0.0);
      JointSolution sol[3];
      const FitOptions::Solver solvers[3] = {FitOptions::Solver::Sparse, FitOptions::Solver::Dense,
                                             FitOptions::Solver::ReferenceQR};
      for (int i = 0; i < 3; ++i) {
        opt.solver = solvers[i];
        sol[i] = solve_joint(d, zero, joint, opt, /*exact_error=*/true);
        REQUIRE(sol[i].solver == solvers[i]);  // a forced path is the one taken
      }
      const double to_dense = worst_function_difference(d, sol[0], sol[1]);
      const double to_qr = worst_function_difference(d, sol[0], sol[2]);
      INFO((planted ? "McCool terms" : "rotated terms")
           << ", prior " << prior << ": rel_mse sparse " << sol[0].rel_mse
           << ", relative difference to dense " << rel_diff(sol[0].rel_mse, sol[1].rel_mse)
           << ", to QR " << rel_diff(sol[0].rel_mse, sol[2].rel_mse)
           << "; worst log difference to dense " << to_dense << ", to QR " << to_qr);
      REQUIRE(sol[0].unknowns == sol[1].unknowns);
      if (planted && prior == 0.0)
        CHECK(sol[0].rel_mse < 1e-3);  // bilinear interpolation error only
      // The same least-squares problem: equal residuals (the residual is
      // computed in double from the solution), and the same function up to
      // the float texels (about 1e-7 relative to log values of order 1).
      CHECK(rel_diff(sol[0].rel_mse, sol[1].rel_mse) < 1e-8);
      CHECK(rel_diff(sol[0].rel_mse, sol[2].rel_mse) < 1e-8);
      CHECK(to_dense < 2e-6);
      CHECK(to_qr < 2e-6);
      // The search's objective (exact_error = false), read off the normal
      // equations by both Cholesky paths, against the unclamped residual.
      opt.solver = FitOptions::Solver::Sparse;
      const double quad_sparse = solve_joint(d, zero, joint, opt, false).rel_mse;
      opt.solver = FitOptions::Solver::Dense;
      const double quad_dense = solve_joint(d, zero, joint, opt, false).rel_mse;
      double se = 0;
      const auto fit = fixed_sum(d, sol[2].terms);
      for (int c = 0; c < 3; ++c)
        for (size_t k = 0; k < d.size(); ++k)
          se += d.w[k] * (fit[c][k] - d.g[c][k]) * (fit[c][k] - d.g[c][k]);
      const double direct = se / (3.0 * d.W);
      INFO("objective: sparse " << quad_sparse << ", dense " << quad_dense
                                << ", direct (QR, float texels) " << direct);
      CHECK(rel_diff(quad_sparse, quad_dense) < 1e-7);
      CHECK(rel_diff(quad_sparse, direct) < 1e-4);
    }
  }
}

TEST_CASE(
    "sparse fit: a JointPrefix and residual targets give the same solution as a plain solve") {
  const bf_test::McCoolFormBrdf brdf;
  const SampleSet s = sample_stratified(brdf, 2000, 37);
  std::mt19937_64 rng(41);
  const std::vector<TermSpec> joint = planted_terms(rng, 8);
  FitOptions opt;
  opt.solver = FitOptions::Solver::Sparse;
  const FitData d(s, opt.eps);
  // Fixed values: a nonzero offset per sample, so r = g - fixed is exercised.
  std::array<std::vector<double>, 3> fixed;
  for (int c = 0; c < 3; ++c) {
    fixed[c].resize(d.size());
    for (size_t k = 0; k < d.size(); ++k) fixed[c][k] = 0.1 * c + 0.05 * std::sin(double(k));
  }
  const JointSolution plain = solve_joint(d, fixed, joint, opt);
  const JointPrefix prefix(d, fixed, {joint[0]}, opt);
  const JointSolution pre = solve_joint(d, fixed, joint, opt, true, &prefix);
  CHECK(rel_diff(pre.rel_mse, plain.rel_mse) < 1e-12);
  // The search's objective (exact_error = false) with the prefix's sum w r^2.
  const double quad_plain = solve_joint(d, fixed, joint, opt, false).rel_mse;
  const double quad_pre = solve_joint(d, fixed, joint, opt, false, &prefix).rel_mse;
  CHECK(rel_diff(quad_pre, quad_plain) < 1e-12);
  opt.solver = FitOptions::Solver::ReferenceQR;
  const JointSolution ref = solve_joint(d, fixed, joint, opt);
  CHECK(rel_diff(plain.rel_mse, ref.rel_mse) < 1e-8);
  CHECK(plain.solver == FitOptions::Solver::Sparse);
  CHECK(pre.solver == FitOptions::Solver::Sparse);
  CHECK(ref.solver == FitOptions::Solver::ReferenceQR);
}

TEST_CASE("sparse fit: Auto takes the dense path up to 1,650 unknowns and the sparse path above") {
  const bf_test::McCoolFormBrdf brdf;
  const SampleSet s = sample_stratified(brdf, 3000, 53);
  const FitData d(s, FitOptions{}.eps);
  std::array<std::vector<double>, 3> zero;
  for (auto& z : zero) z.assign(d.size(), 0.0);
  FitOptions opt;  // solver = Auto
  std::mt19937_64 rng(59);
  for (const int res : {8, 40}) {  // a few hundred unknowns; above 1,650 with two 40 x 40 textures
    const JointSolution sol = solve_joint(d, zero, planted_terms(rng, res), opt, false);
    INFO("texture " << res << ": " << sol.unknowns << " unknowns");
    CHECK(sol.solver == (sol.unknowns <= kDenseMaxUnknowns ? FitOptions::Solver::Dense : FitOptions::Solver::Sparse));
  }
}

TEST_CASE("sparse fit: the column-by-column assembly equals the triplet assembly") {
  const bf_test::McCoolFormBrdf brdf;
  const SampleSet s = sample_stratified(brdf, 2000, 53);
  std::mt19937_64 rng(59);
  std::uniform_int_distribution<int> res_of(5, 11), count_of(1, 3), coin(0, 1);
  for (int layout = 0; layout < 12; ++layout) {
    // Random layouts: 1 to 3 terms, each wiwo or halfdiff, reciprocal (wiwo)
    // or not, of random resolutions; the prior on in every other layout.
    std::vector<TermSpec> joint;
    const int n = count_of(rng);
    for (int t = 0; t < n; ++t) {
      const bool wiwo = coin(rng) == 1;
      joint.push_back({bf_test::random_projection(rng, wiwo ? Parameterization::WiWo : Parameterization::HalfDiff,
                                                  res_of(rng)),
                       wiwo && coin(rng) == 1, std::nullopt});
    }
    FitOptions opt;
    opt.extrapolation_prior = layout % 2 == 1 ? 0.5 : 0.0;
    const FitData d(s, opt.eps);
    const SparseNormal ref = bf_test::reference_sparse_normal_equations(d, joint, opt);
    const SparseNormal col = sparse_normal_equations(d, joint, opt);
    INFO("layout " << layout << ": " << n << " terms, " << ref.M << " unknowns, prior "
                   << opt.extrapolation_prior);
    REQUIRE(col.M == ref.M);
    // The same pattern, rows sorted and every diagonal entry last in its column.
    REQUIRE(col.p == ref.p);
    REQUIRE(col.i == ref.i);
    for (int j = 0; j < col.M; ++j) {
      REQUIRE(col.p[j + 1] > col.p[j]);
      CHECK(col.i[col.p[j + 1] - 1] == j);
      for (int e = col.p[j]; e + 1 < col.p[j + 1]; ++e) CHECK(col.i[e] < col.i[e + 1]);
    }
    // The same values up to summation order.
    double scale = 0, worst = 0;
    for (size_t e = 0; e < ref.x.size(); ++e) {
      scale = std::max(scale, std::abs(ref.x[e]));
      worst = std::max(worst, std::abs(col.x[e] - ref.x[e]));
    }
    CHECK(worst <= 1e-12 * scale);
    const double rhs_scale = ref.rhs.cwiseAbs().maxCoeff();
    CHECK((col.rhs - ref.rhs).cwiseAbs().maxCoeff() <= 1e-12 * rhs_scale);
  }
}

TEST_CASE("sparse fit: a normal matrix that is not positive definite is reported") {
  const bf_test::McCoolFormBrdf brdf;
  const SampleSet s = sample_stratified(brdf, 1500, 43);
  std::mt19937_64 rng(47);
  const std::vector<TermSpec> joint = planted_terms(rng, 8);
  FitOptions opt;
  FitData d(s, opt.eps);
  std::array<std::vector<double>, 3> zero;
  for (auto& z : zero) z.assign(d.size(), 0.0);
  // One sample with a large negative weight: its row b adds -1e6 b b^T, so
  // b^T A b < 0 (FitData's constructor never makes one; the solver must still
  // refuse rather than return a solution).
  d.w[7] = -1e6 * d.W;
  for (const FitOptions::Solver solver : {FitOptions::Solver::Sparse, FitOptions::Solver::Dense}) {
    opt.solver = solver;
    REQUIRE_THROWS_WITH(solve_joint(d, zero, joint, opt),
                        Catch::Matchers::Contains("the normal matrix is not positive definite"));
  }
}
