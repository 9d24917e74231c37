// McCool's homomorphic least-squares fit for given projections (thesis 3.2):
// log transform, bilinear weights, projection masks, Laplacian smoothing,
// optional reciprocity, the last n terms solved jointly with earlier ones
// fixed, one Cholesky factorization of the normal matrix for all three RGB
// channels.
//
// The linear system. For the n joint terms with unknown log texels y, every
// valid sample k gives one row b_k (bilinear weights of its projected positions,
// conjugate positions added for reciprocal terms) and target
// r_k = g_k - (sum of the fixed terms at k). We minimize
//   sum_k w_k (b_k . y - r_k)^2 + mu * sum_terms |L y_t|^2 + gauge
// through the normal equations (B^T W B + mu L^T L + G) y = B^T W r, assembled
// directly (B is never formed densely), solved by Cholesky (dense LLT for small
// systems, sparse LLT for large textures).
//  - L is the graph Laplacian of each term's mask (4-neighbours inside the
//    mask): its null space is the constants only.
//  - mu = smoothing * (sum of sample weights) / (number of unknowns): the
//    smoothing option is relative to the average sample weight per texel.
//  - Gauge: adding c to one joint term and subtracting it from another changes
//    nothing (bilinear weights sum to 1, L ignores constants), so the normal
//    matrix would be singular. We pin the freedom explicitly: for the 2nd..n-th
//    joint term the penalty gamma * (sum of its texels)^2 is added (dense and
//    QR paths; the sparse path penalizes that term's first texel instead, which
//    keeps the matrix sparse), which forces their texel sums (or first texel)
//    to 0 without changing the fitted function: the constant lands in the
//    first joint term. Paths agree on the function, not on the split. A ridge of 1e-12 * mean diagonal guards
//    against any remaining exact singularity (a texel nothing constrains).
//  - Bounded extrapolation (extrapolation_prior = rho > 0, docs/design.md
//    §3.2; default 0 = off): two gauge-blind additions. Prior points: the
//    centres of a 6^4 grid of equal-solid-angle cells over (wi, wo), each a
//    row like a sample with target the neutral sum c = weighted mean of the
//    targets r and weight rho * wbar * exp(-4 n) (n = sample weight in its
//    cell / wbar, wbar = W / N). Levels: per joint term, the texels no sample
//    reaches (weight rho * wbar * exp(-20 q_i), q_i = sample weight reaching
//    texel i through bilinear weights / wbar) are pulled toward their own
//    weighted mean (a free level), so they extrapolate flat instead of along
//    the Laplacian's linear ramps (exponentially in the BRDF).
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/homomorphic.h"
#include "factor/metrics.h"

namespace bf {

struct FitOptions {
  double eps = 1e-5;         // log-transform epsilon (docs/design.md §2), 0 < eps <= 1
  double smoothing = 1e-3;   // Laplacian weight relative to the mean sample weight per texel, in [0, kMaxWeight]
  bool subtract_eps = true;  // reconstruct A exp(s) - eps A (clamped at 0) instead of A exp(s)
  int solve_last = 2;        // n: the last n terms are solved jointly, >= 1
  // rho: weight (in mean sample weights) of the bounded-extrapolation prior
  // (header comment, docs/design.md §3.2); 0 = off (pure Laplacian
  // extrapolation, the earlier default). In [0, kMaxWeight].
  double extrapolation_prior = 0.0;
  // Log-range clamp (docs/design.md §3.2): the factorization clamps its summed
  // log value s_c to [min g_c, max g_c] over the valid training samples
  // (FitData::log_range) before exp. Every training target lies in that
  // interval, so the clamp never increases a training sample's error, and
  // f <= A exp(max g) ~ the largest training value everywhere. Default on.
  bool clamp_log_range = true;
  // Dense: normal matrix assembled densely, LLT. Sparse: normal matrix assembled
  // column by column in compressed columns, CHOLMOD supernodal LLT ordered by AMD on
  // pairs of texels (SimplicialLLT with AMD without CHOLMOD).
  // Auto: dense for small systems, sparse above (choose_linear_solver,
  // factor/solver_choice.h). ReferenceQR: the simple path (dense B,
  // Householder QR, no normal equations) for tests.
  enum class Solver { Auto, Dense, Sparse, ReferenceQR } solver = Solver::Auto;
  // Upper bound of smoothing and extrapolation_prior (in mean sample weights).
  // Far above it the Laplacian or the prior swamps the samples' rows of the
  // normal matrix below double precision (1e300 overflows it), and the solve
  // fails as "not positive definite" or returns textures the samples no
  // longer shape; 1e6 still leaves the samples nine digits.
  static constexpr double kMaxWeight = 1e6;
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

struct TermSpec {
  Projection proj;
  bool reciprocal = false;
  std::optional<std::array<double, 8>> rotation;  // quaternion pair, informational
};

// Per-sample data shared by every fit on the same samples: the valid samples
// only, their points in both parameterizations, log-space targets g (3
// channels) and weights.
class FitData {
 public:
  // Throws if s has no valid sample or a channel is all zero (see LogTransform::of).
  FitData(const SampleSet& s, double eps);
  // Empty; filled member by member by a subset of another FitData (search/subsample.h).
  FitData() = default;
  size_t size() const { return w.size(); }

  LogTransform transform;
  std::vector<Vec4> x_wiwo, x_halfdiff;  // per valid sample
  std::vector<double> w;                 // weight per valid sample
  double W = 0;                          // sum of w
  std::array<std::vector<double>, 3> g;  // log-space target per channel
  // Per channel sum of w g_c^2 (like W, set by the constructor): the fit's
  // objective with no fixed term starts from it.
  std::array<double, 3> wg2{};
  // Per channel [min g_c, max g_c] over the valid samples (the log-range clamp).
  LogRange log_range{};
  // clamp(s, log_range[c]) if opt.clamp_log_range, else s.
  double clamp_log(int c, double s, const FitOptions& opt) const {
    return opt.clamp_log_range ? std::clamp(s, log_range[c][0], log_range[c][1]) : s;
  }
  // Prior points of the bounded-extrapolation prior (FitOptions::
  // extrapolation_prior): the centres of a kPriorGrid^4 grid of equal-solid-
  // angle cells over (wi, wo), each weighted wbar * exp(-4 n) with n the sample
  // weight falling in its cell / wbar (wbar = W / size()); cells that hold
  // samples (weight below 1e-12 wbar) are left out.
  static constexpr int kPriorGrid = 6;
  std::vector<Vec4> prior_wiwo, prior_halfdiff;
  std::vector<double> prior_w;
  const std::vector<Vec4>& points(Parameterization p) const {
    return p == Parameterization::WiWo ? x_wiwo : x_halfdiff;
  }
};

struct JointSolution {
  std::vector<FactorTerm> terms;  // the joint terms with texels and masks
  // rel_mse of fixed + joint terms on the fit data. With exact_error (default)
  // it is computed sample by sample with the reconstruction's clamping, as the
  // metrics see it; otherwise it is the least-squares objective itself
  // (unclamped), read off the normal equations in O(unknowns) (search loop).
  double rel_mse = 0;
  size_t unknowns = 0;            // texels solved for (all joint terms)
  // The path that solved it: FitOptions::solver, or Auto's choice (Dense or Sparse).
  FitOptions::Solver solver = FitOptions::Solver::Dense;
};

// Sum of the given (fixed) terms' log values at every sample, per channel.
std::array<std::vector<double>, 3> fixed_sum(const FitData& d, const std::vector<FactorTerm>& fixed);

// What solve_joint computes for the first joint terms alone: their texel
// layout, per-sample bilinear lookups and their block of B^T W B and B^T W r
// (before smoothing, gauge and ridge, which depend on the whole system). A
// search that changes only the last joint term (TermObjective) builds it once
// and passes it to every solve. Valid only with the same FitData and
// fixed_values it was built from (the caller's contract; the specs are checked).
class JointPrefix {
 public:
  JointPrefix(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
              const std::vector<TermSpec>& known, const FitOptions& opt);
  ~JointPrefix();
  JointPrefix(const JointPrefix&) = delete;
  JointPrefix& operator=(const JointPrefix&) = delete;
  size_t terms() const;
  // The content, defined in factor/fit_internal.h (the fit's own files only).
  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Solves `joint` with `fixed_values` (from fixed_sum) held. Throws
// std::invalid_argument for invalid projections, std::runtime_error if the
// normal matrix is not positive definite. With `prefix` (built from the same
// data and fixed_values for joint's first prefix->terms() terms, else
// std::invalid_argument), the dense path reuses its lookups and normal-matrix
// block; the result equals the one without it up to summation order.
JointSolution solve_joint(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermSpec>& joint, const FitOptions& opt,
                          bool exact_error = true, const JointPrefix* prefix = nullptr);

// rel_mse of a log-space model value s against target g (both per sample and
// channel), with the reconstruction's clamping applied exactly as the metrics
// see it: g_approx = max(s, log eps) if subtract_eps, else log(exp(s) + eps).
double model_log_value(double s, const FitOptions& opt);

// The full schedule of thesis 3.2.2 for given projections: for j = 1..J, terms
// max(1, j-n+1)..j are solved jointly with earlier terms fixed at their values.
// `errors_after_term`, if given, receives the rel_mse after each j.
std::shared_ptr<HomomorphicFactorization> fit_homomorphic(
    const FitData& d, const std::vector<TermSpec>& terms, const FitOptions& opt,
    const std::string& method = "fit", std::vector<double>* errors_after_term = nullptr);

// The normal matrix solve_joint's dense path factors for `joint` alone (no
// fixed terms): the data block B^T W B, mu L^T L and the gauge penalties, in
// its unknown layout (each term's mask extended by every texel a sample
// touches; terms in order), full symmetric, M x M. Without the 1e-12 ridge
// solve_joint adds. For diagnostics (factor/stress.h: its condition number).
// *unknowns receives M; above max_unknowns an empty matrix is returned
// (nothing assembled). Throws std::invalid_argument as solve_joint does.
Eigen::MatrixXd joint_normal_matrix(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt,
                                    size_t max_unknowns, size_t* unknowns = nullptr);

// The sparse path's normal equations for `joint` alone (no fixed terms, the
// targets d.g), before its gauge and ridge: A = B^T W B + mu L^T L + the
// prior's rows, rhs = B^T W g + the prior's targets, A's upper triangle in
// compressed columns (p: M + 1 column starts, i: rows, x: values; rows
// sorted, every diagonal entry stored, hence last in its column) and rhs
// (M x 3), in solve_joint's unknown layout. Throws std::invalid_argument as
// solve_joint does.
struct SparseNormal {
  int M = 0;
  std::vector<int> p, i;
  std::vector<double> x;
  Eigen::MatrixXd rhs;
};
SparseNormal sparse_normal_equations(const FitData& d, const std::vector<TermSpec>& joint, const FitOptions& opt);

// McCool's fixed projections (thesis 2.1.1): p(wi) and p(wo) share one texture
// (a reciprocal wiwo term), q(h) has its own (halfdiff, first pair; h through
// the parabolic map). Two textures of size res.
std::vector<TermSpec> mccool_terms(int res);

}  // namespace bf
