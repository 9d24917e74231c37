// Nonlinear refinement of a homomorphic factorization (an optional stage after
// the log-space least-squares fit or the projection search): with Ceres,
// minimize an error measured in linear space over the factor texels, starting
// from the log-space solution, keeping the factors positive by optimizing the
// log texels the factorization stores.
//
// Model. Per RGB channel c and valid sample k, with s_c(k) = sum over terms of
// the bilinear lookups (conjugate lookups added for reciprocal terms) of the
// log texels y (homomorphic.h):
//   F_c(k) = A_c (exp(s_c(k)) - e),  e = eps if the start subtracts eps, else 0.
// Refinement uses F without the reconstruction's clamp at 0 (it is smooth); the
// clamp can only lower |F - f| for f >= 0, so evaluated errors are never worse
// than the optimized ones.
//
// Objectives (per sample k with weight w_k, W = sum of w_k, Abar = mean of A
// over the channels; linear residuals are in units of Abar, so channels weigh
// exactly as in lin_rmse and cos_rmse, and smoothing means the same for every
// objective):
//  - "linear": r_kc = sqrt(w_k / 3W) (F_c(k) - f_c(k)) / Abar.
//    2 * cost = lin_rmse^2 / Abar^2 (unclamped) + smoothing: its minimizer is
//    that of lin_rmse (docs/design.md §4) plus the smoothing term.
//  - "cosine": r_kc = sqrt(w_k / 3W) (F_c(k) - f_c(k)) cos(theta_i) / Abar:
//    the product function shading integrates (cos_rmse).
//  - "blend" (thesis 3.1.4: a mixture of relative and absolute error), two
//    residuals per sample and channel:
//      r_log = sqrt(w_k / 3W) (g_approx - g),   g = log((f + eps A_c) / A_c),
//      r_lin = sqrt(blend_weight) * (the "linear" residual),
//    so 2 * cost = rel_mse + blend_weight * lin_rmse^2 / Abar^2 + smoothing
//    (squared errors: least squares, where the thesis's example sums absolute
//    values). g_approx is the metrics' log value of the reconstruction (s if
//    eps is subtracted, log(exp(s) + eps) otherwise). The default weight 0.03
//    was chosen on W1 (bluepaint, grid 16, texture 16): there it trades a few
//    percent of rel_mse for a 5-25% lower lin_rmse (numbers in
//    tests/factor/refine_test.cpp); blend_weight = 0 leaves a log-space fit
//    (without its clamp) where it is.
// Smoothing: for every term and masked texel with masked 4-neighbours, the
// graph-Laplacian row (as in homomorphic_fit.h) on the log texels, per channel,
// weighted sqrt(smoothing / (3 M)) with M the number of refined texels: the same
// balance as FitOptions::smoothing in the log fit (relative to the mean sample
// weight per texel), with data residuals in the units above. It keeps texels
// that few or no samples touch defined.
//
// Unknowns: every masked texel of every term (all terms are refined jointly),
// plus any texel the given samples read that is outside the start's mask (the
// returned terms' masks include them). Channels are independent problems
// solved together: each texel and channel is one Ceres parameter block of one
// double; each sample and channel is one residual block of 1 (linear, cosine)
// or 2 (blend) residuals touching the distinct texels of its stencil (4 per
// term, 8 for reciprocal terms, duplicates merged, zero weights dropped). The
// Jacobian is analytic (checked with ceres::GradientChecker in
// tests/factor/refine_test.cpp).
// Solver: Levenberg-Marquardt, SPARSE_NORMAL_CHOLESKY with Eigen's sparse
// Cholesky when Ceres has EIGEN_SPARSE, else SuiteSparse, else CGNR. Cost per
// iteration is dominated by Ceres forming J^T J (W1 has 130k residual blocks
// of 1x12 Jacobians).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/homomorphic.h"

namespace bf {

struct RefineOptions {
  std::string objective = "blend";  // "linear" | "cosine" | "blend" (see above)
  // blend: weight of the linear-space residuals against the log-space ones, >= 0
  // (0 = pure log objective, i.e. the start's own objective without the clamp).
  double blend_weight = 0.03;
  int max_iterations = 50;    // Levenberg-Marquardt iterations, >= 1
  double smoothing = 1e-3;    // Laplacian weight, as FitOptions::smoothing, >= 0
  int threads = 0;            // Ceres threads; 0 = all hardware threads
  double function_tolerance = 1e-7;  // Ceres: stop when |d cost| / cost < this, > 0
  // Sparse linear solver: Auto = SPARSE_NORMAL_CHOLESKY with Eigen sparse if
  // available, else SuiteSparse, else CGNR; the others force one choice
  // (forcing an unavailable library throws).
  enum class LinearSolver { Auto, SuiteSparse, EigenSparse, CGNR } linear_solver = LinearSolver::Auto;
  // Upper bound of blend_weight and smoothing, as FitOptions::kMaxWeight: far
  // above it the weighted terms swamp the samples' residuals below double
  // precision (1e300 overflows the cost).
  static constexpr double kMaxWeight = 1e6;
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

struct RefineReport {
  std::string objective;          // as run
  std::string linear_solver;      // e.g. "SPARSE_NORMAL_CHOLESKY/EIGEN_SPARSE"
  int iterations = 0;             // Levenberg-Marquardt iterations (successful + rejected)
  double seconds = 0;             // wall time of refine(), setup included
  double initial_cost = 0;        // Ceres cost (half the sum of squared residuals) at the start
  double final_cost = 0;          // ... at the result
  std::string termination;        // Ceres termination type and message
  size_t parameters = 0;          // refined texels x 3 channels
  size_t residuals = 0;           // scalar residuals (data + smoothing)
  size_t texels_added = 0;        // texels outside the start's masks that samples read
};

// Refines every term's log texels under opt.objective on the valid samples of
// `samples` (A, eps and subtract_eps are the start's). Returns a new
// factorization with method "<start method>+refine-<objective>". Throws
// std::invalid_argument for invalid options, a start without terms or samples
// without a valid sample; std::runtime_error if Ceres fails to produce a finite
// solution (the start is then the best answer: callers may keep it).
std::shared_ptr<HomomorphicFactorization> refine(const HomomorphicFactorization& start,
                                                 const SampleSet& samples,
                                                 const RefineOptions& opt,
                                                 RefineReport* report = nullptr);

}  // namespace bf
