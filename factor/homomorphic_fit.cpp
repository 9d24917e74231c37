// Homomorphic least-squares fit (see homomorphic_fit.h for the formulation):
// solve_joint (the joint system's layout, the path, the solution),
// fit_homomorphic and JointPrefix. The pieces live in the fit_*.cpp files
// (factor/fit_internal.h).
#include "factor/homomorphic_fit.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "factor/fit_internal.h"
#include "factor/solver_choice.h"
#include "solvers/cancel.h"

namespace bf {

using namespace fit;

JointPrefix::JointPrefix(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                         const std::vector<TermSpec>& known, const FitOptions& opt)
    : impl_(std::make_unique<Impl>()) {
  opt.validate();
  Impl& p = *impl_;
  p.known = known;
  p.lookups.resize(known.size());
  for (size_t i = 0; i < known.size(); ++i) add_layout(d, known[i], p.M, p.terms, p.lookups[i]);
  p.A = Eigen::MatrixXd::Zero(p.M, p.M);
  p.rhs = Eigen::MatrixXd::Zero(p.M, 3);
  std::vector<const std::array<Lookups, 2>*> lp;
  for (const auto& l : p.lookups) lp.push_back(&l);
  residual_targets(d, fixed_values, p.r);
  const std::array<const double*, 3> r = {p.r[0].data(), p.r[1].data(), p.r[2].data()};
  weighted_square_sums(d, r, p.sum_wr2);
  assemble_dense(d, r, p.terms, lp, 0, p.A, p.rhs);
}

JointPrefix::~JointPrefix() = default;
size_t JointPrefix::terms() const { return impl_->known.size(); }

namespace {

// The joint system's layout: a prefix's terms (checked against joint's first
// ones), then the others, their lookups in the thread's workspace (capacity
// kept across fits).
void layout_joint(const FitData& d, const std::vector<TermSpec>& joint, const JointPrefix* prefix,
                  JointSystem& sys) {
  std::vector<std::array<Lookups, 2>>& own = workspace().own;
  own.resize(joint.size());
  sys.terms.reserve(joint.size());
  if (prefix) {
    const JointPrefix::Impl& p = prefix->impl();
    sys.K = p.known.size();
    const size_t K = sys.K;
    if (K >= joint.size())
      throw std::invalid_argument("fit: a prefix of " + std::to_string(K) + " terms for " +
                                  std::to_string(joint.size()) + " joint terms (expected fewer)");
    for (size_t i = 0; i < K; ++i)
      if (joint[i].proj.P != p.known[i].proj.P || joint[i].proj.res != p.known[i].proj.res ||
          joint[i].proj.param != p.known[i].proj.param || joint[i].reciprocal != p.known[i].reciprocal)
        throw std::invalid_argument("fit: joint term " + std::to_string(i + 1) +
                                    " differs from the prefix's term it should equal");
    sys.terms = p.terms;
    for (size_t i = 0; i < K; ++i) sys.lookups.push_back(&p.lookups[i]);
    sys.M = p.M;
  }
  for (size_t i = sys.K; i < joint.size(); ++i) {
    add_layout(d, joint[i], sys.M, sys.terms, own[i]);
    sys.lookups.push_back(&own[i]);
  }
}

// Residual targets g - fixed (a prefix holds them) and, for the objective
// read off the normal equations, sum w r^2 per channel: both assembled paths.
void residual_inputs(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                     const JointPrefix* prefix, size_t K, SolveInputs& in) {
  if (K > 0) {
    for (int c = 0; c < 3; ++c) in.r[c] = prefix->impl().r[c].data();
    std::copy_n(prefix->impl().sum_wr2, 3, in.sum_wr2);
  } else if (all_zero(fixed_values)) {  // r = g, sum w r^2 = FitData::wg2
    for (int c = 0; c < 3; ++c) {
      in.r[c] = d.g[c].data();
      in.sum_wr2[c] = d.wg2[c];
    }
  } else {
    residual_targets(d, fixed_values, workspace().r);
    for (int c = 0; c < 3; ++c) in.r[c] = workspace().r[c].data();
    if (!in.exact_error) weighted_square_sums(d, in.r, in.sum_wr2);
  }
}

// The joint terms with their texels (Y's rows) and masks.
std::vector<FactorTerm> solved_terms(const std::vector<TermSpec>& joint, const std::vector<TermLayout>& terms,
                                     const Eigen::MatrixXd& Y) {
  std::vector<FactorTerm> out;
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const TermLayout& t = terms[ti];
    FactorTerm ft;
    ft.proj = joint[ti].proj;
    ft.reciprocal = joint[ti].reciprocal;
    ft.rotation = joint[ti].rotation;
    ft.mask = t.mask;
    for (int c = 0; c < 3; ++c) {
      ft.texels[c].assign(t.mask.size(), 0.0f);
      for (size_t i = 0; i < t.mask.size(); ++i)
        if (t.unk[i] >= 0) ft.texels[c][i] = static_cast<float>(Y(t.unk[i], c));
    }
    out.push_back(std::move(ft));
  }
  return out;
}

}  // namespace

JointSolution solve_joint(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermSpec>& joint, const FitOptions& opt,
                          bool exact_error, const JointPrefix* prefix) {
  check_cancel();  // every fit and every search evaluation is a joint solve
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  JointSystem sys;
  layout_joint(d, joint, prefix, sys);
  const int M = sys.M;

  SolveInputs in;
  in.exact_error = exact_error;
  in.mu = opt.smoothing * d.W / std::max(M, 1);
  const Prior prior = extrapolation_prior(d, fixed_values, sys.terms, sys.lookups, M, opt);
  in.prior = &prior;
  Eigen::MatrixXd Y(M, 3);  // solution, one column per channel
  double quad_rel_mse = -1;  // set by the dense and sparse paths when !exact_error

  const FitOptions::Solver solver = choose_linear_solver(opt.solver, static_cast<size_t>(M), d.size());
  if (solver != FitOptions::Solver::ReferenceQR) residual_inputs(d, fixed_values, prefix, sys.K, in);
  if (solver == FitOptions::Solver::Sparse)
    quad_rel_mse = solve_sparse(d, sys, in, Y);
  else if (solver == FitOptions::Solver::Dense)
    quad_rel_mse = solve_dense(d, sys, sys.K > 0 ? prefix : nullptr, in, Y);
  else
    solve_reference_qr(d, fixed_values, sys, in, Y);
  if (!Y.allFinite()) throw std::runtime_error("fit: the solution is not finite");

  // Residual: rel_mse of fixed + joint terms, with the reconstruction's clamping.
  JointSolution sol;
  sol.unknowns = static_cast<size_t>(M);
  sol.solver = solver;
  sol.rel_mse = !exact_error && quad_rel_mse >= 0 ? quad_rel_mse
                                                  : sample_rel_mse(d, fixed_values, sys, Y, opt, exact_error);
  sol.terms = solved_terms(joint, sys.terms, Y);
  return sol;
}

std::shared_ptr<HomomorphicFactorization> fit_homomorphic(const FitData& d,
                                                          const std::vector<TermSpec>& terms,
                                                          const FitOptions& opt,
                                                          const std::string& method,
                                                          std::vector<double>* errors) {
  opt.validate();
  if (terms.empty()) throw std::invalid_argument("terms: expected at least 1 term, found 0");
  std::vector<FactorTerm> done;  // terms 1..j with texels (the last ones re-solved each step)
  for (size_t j = 1; j <= terms.size(); ++j) {
    const size_t first = j > static_cast<size_t>(opt.solve_last) ? j - opt.solve_last : 0;
    std::vector<FactorTerm> fixed(done.begin(), done.begin() + first);
    std::vector<TermSpec> joint(terms.begin() + first, terms.begin() + j);
    const JointSolution sol = solve_joint(d, fixed_sum(d, fixed), joint, opt);
    done = fixed;
    done.insert(done.end(), sol.terms.begin(), sol.terms.end());
    if (errors) errors->push_back(sol.rel_mse);
  }
  return std::make_shared<HomomorphicFactorization>(
      done, d.transform.A, opt.eps, opt.subtract_eps, method,
      opt.clamp_log_range ? std::optional<LogRange>(d.log_range) : std::nullopt);
}

}  // namespace bf
