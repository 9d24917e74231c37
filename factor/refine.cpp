// Nonlinear refinement of homomorphic factorizations with Ceres (see refine.h).
#include "factor/refine.h"
#include "factor/ceres_cancel.h"
#include "factor/refine_internal.h"
#include "solvers/option_error.h"
#include "solvers/parallel.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unordered_map>

namespace bf {

namespace {

using detail::RefineObjective;
using Objective = RefineObjective;

// One sample's residuals in one channel (refine.h): the log-space model value
// s is the weighted sum of the distinct texels of the sample's stencil (one
// 1-double block per texel and channel), so d s / d y_a = w_a.
class SampleCost final : public ceres::CostFunction {
 public:
  SampleCost(const std::vector<double>& weights, double f, double sw, double cosw, double A,
             double scale, double eps, bool subtract_eps, Objective obj, double blend_weight)
      : w_(weights), blend_(obj == Objective::Blend), eps_(eps), subtract_eps_(subtract_eps) {
    for (size_t a = 0; a < w_.size(); ++a) mutable_parameter_block_sizes()->push_back(1);
    set_num_residuals(blend_ ? 2 : 1);
    e_ = subtract_eps ? eps : 0.0;
    // Linear residual k (A E - A e - f) / scale, k = sw * cosw or sqrt(blend_weight) * sw.
    const double k = (blend_ ? std::sqrt(blend_weight) * sw : sw * cosw) / scale;
    lin_scale_ = k * A;
    lin_offset_ = k * (A * e_ + std::max(f, 0.0));
    log_scale_ = sw;
    g_ = std::log(std::max(f, 0.0) / A + eps);
  }

  bool Evaluate(double const* const* p, double* r, double** J) const override {
    double s = 0.0;
    for (size_t a = 0; a < w_.size(); ++a) s += w_[a] * p[a][0];
    const double E = std::exp(s);
    if (!std::isfinite(E)) return false;
    double d[2];  // d r_i / d s
    const int lin = blend_ ? 1 : 0;
    r[lin] = lin_scale_ * E - lin_offset_;
    d[lin] = lin_scale_ * E;
    if (blend_) {
      // g_approx: s when eps is subtracted (unclamped), else log(exp(s) + eps).
      const double G =
          subtract_eps_ ? s : (s > 0 ? s + std::log1p(eps_ / E) : std::log(E + eps_));
      r[0] = log_scale_ * (G - g_);
      d[0] = log_scale_ * (subtract_eps_ ? 1.0 : E / (E + eps_));
    }
    if (J) {
      const int n = num_residuals();
      for (size_t a = 0; a < w_.size(); ++a) {
        if (!J[a]) continue;
        for (int i = 0; i < n; ++i) J[a][i] = d[i] * w_[a];
      }
    }
    return true;
  }

 private:
  std::vector<double> w_;
  bool blend_;
  double eps_, e_ = 0;
  bool subtract_eps_;
  double lin_scale_ = 1, lin_offset_ = 0, log_scale_ = 1;
  double g_ = 0;
};

// One graph-Laplacian row in one channel: r = scale * sum_b v_b y_b.
class LaplacianCost final : public ceres::CostFunction {
 public:
  LaplacianCost(std::vector<double> v, double scale) : v_(std::move(v)), scale_(scale) {
    for (size_t b = 0; b < v_.size(); ++b) mutable_parameter_block_sizes()->push_back(1);
    set_num_residuals(1);
  }
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    double s = 0;
    for (size_t b = 0; b < v_.size(); ++b) s += v_[b] * p[b][0];
    r[0] = scale_ * s;
    if (J)
      for (size_t b = 0; b < v_.size(); ++b)
        if (J[b]) J[b][0] = scale_ * v_[b];
    return true;
  }

 private:
  std::vector<double> v_;
  double scale_;
};

void choose_linear_solver(RefineOptions::LinearSolver which, ceres::Solver::Options& so,
                          std::string& name) {
  using LS = RefineOptions::LinearSolver;
  const bool have_ss = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  const bool have_eigen = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  if (which == LS::SuiteSparse && !have_ss)
    throw std::invalid_argument("linear_solver: suitesparse was requested but this Ceres was "
                                "built without SuiteSparse");
  if (which == LS::EigenSparse && !have_eigen)
    throw std::invalid_argument("linear_solver: eigen-sparse was requested but this Ceres was "
                                "built without EIGEN_SPARSE");
  if (which == LS::CGNR || (which == LS::Auto && !have_ss && !have_eigen)) {
    so.linear_solver_type = ceres::CGNR;
    so.preconditioner_type = ceres::JACOBI;
    name = "CGNR/JACOBI";
    return;
  }
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  const bool eigen = which == LS::EigenSparse || (which == LS::Auto && have_eigen);
  so.sparse_linear_algebra_library_type = eigen ? ceres::EIGEN_SPARSE : ceres::SUITE_SPARSE;
  name = eigen ? "SPARSE_NORMAL_CHOLESKY/EIGEN_SPARSE" : "SPARSE_NORMAL_CHOLESKY/SUITE_SPARSE";
}

}  // namespace

void RefineOptions::validate() const {
  detail::parse_refine_objective(objective);
  const auto shown = [](double v) {
    std::ostringstream s;
    s.precision(12);
    s << v;
    return s.str();
  };
  if (!(blend_weight >= 0.0 && blend_weight <= kMaxWeight))
    throw OptionError("blend_weight", "blend_weight: expected a number in [0, " + shown(kMaxWeight) + "], found " +
                                          shown(blend_weight));
  if (max_iterations < 1)
    throw OptionError("max_iterations", "max_iterations: expected >= 1, found " +
                                std::to_string(max_iterations));
  if (!(smoothing >= 0.0 && smoothing <= kMaxWeight))
    throw OptionError("smoothing", "smoothing: expected a number in [0, " + shown(kMaxWeight) + "], found " +
                                       shown(smoothing));
  if (threads < 0)
    throw OptionError("threads", "threads: expected >= 0 (0 = all hardware threads), found " +
                                std::to_string(threads));
  if (!(function_tolerance > 0.0) || !std::isfinite(function_tolerance))
    throw OptionError("function_tolerance", "function_tolerance: expected a finite value > 0, found " +
                                std::to_string(function_tolerance));
}

namespace detail {
RefineObjective parse_refine_objective(const std::string& s) {
  if (s == "linear") return RefineObjective::Linear;
  if (s == "cosine") return RefineObjective::Cosine;
  if (s == "blend") return RefineObjective::Blend;
  throw std::invalid_argument("objective: expected linear, cosine or blend, found '" + s + "'");
}

std::unique_ptr<ceres::CostFunction> make_refine_sample_cost(const std::vector<double>& weights,
                                                             double f, double sw, double cosw,
                                                             double A, double scale, double eps,
                                                             bool subtract_eps, RefineObjective objective,
                                                             double blend_weight) {
  return std::make_unique<SampleCost>(weights, f, sw, cosw, A, scale, eps, subtract_eps, objective,
                                      blend_weight);
}
}  // namespace detail

namespace {

// The refined problem's layout: the valid samples (ks, weight sum W), the
// terms' masks extended by every texel a sample reads (added of them), each
// term's texel -> unknown map, and per (sample, term) the direct and
// conjugate bilinear stencils.
struct RefineLayout {
  struct Term {
    Projection conj;
    std::vector<int> unk;
    int first = 0;
  };
  std::vector<size_t> ks;
  double W = 0;
  std::vector<Term> lay;
  std::vector<std::array<Bilinear, 2>> stencils;  // per (sample, term): direct, conjugate
  size_t added = 0;
  int M = 0;
};

RefineLayout refine_layout(std::vector<FactorTerm>& terms, const SampleSet& samples) {
  RefineLayout L;
  for (size_t k = 0; k < samples.size(); ++k)
    if (samples.valid[k]) {
      L.ks.push_back(k);
      L.W += samples.weight_of(k);
    }
  if (L.ks.empty()) throw std::invalid_argument("refine: the sample set has no valid sample");
  if (!(L.W > 0.0)) throw std::invalid_argument("refine: the valid samples' weights sum to 0");
  const size_t N = L.ks.size();
  L.lay.resize(terms.size());
  L.stencils.resize(N * terms.size());
  for (size_t t = 0; t < terms.size(); ++t) {
    FactorTerm& term = terms[t];
    const int R = term.proj.res;
    if (term.mask.size() != size_t(R) * R) term.mask.assign(size_t(R) * R, 1);
    L.lay[t].conj = term.proj.conjugate();
    for (size_t n = 0; n < N; ++n) {
      const size_t k = L.ks[n];
      const Vec4 x = to_point(term.proj.param, samples.wi[k], samples.wo[k]);
      auto& st = L.stencils[n * terms.size() + t];
      st[0] = bilinear(term.proj.texel_coords(x), R);
      if (term.reciprocal) st[1] = bilinear(L.lay[t].conj.texel_coords(x), R);
      for (int q = 0; q < (term.reciprocal ? 2 : 1); ++q)
        for (int a = 0; a < 4; ++a)
          if (!term.mask[st[q].idx[a]]) {
            term.mask[st[q].idx[a]] = 1;
            ++L.added;
          }
    }
    L.lay[t].unk.assign(term.mask.size(), -1);
    L.lay[t].first = L.M;
    for (size_t i = 0; i < term.mask.size(); ++i)
      if (term.mask[i]) L.lay[t].unk[i] = L.M++;
  }
  return L;
}

// One residual block per valid sample and channel (the sample's distinct
// texels, merged weights); returns the number of scalar residuals.
// y: channel c of unknown u at y[c * M + u].
size_t add_sample_residuals(ceres::Problem& problem, const RefineLayout& L, const std::vector<FactorTerm>& terms,
                            const SampleSet& samples, const HomomorphicFactorization& start, Objective obj,
                            double blend_weight, std::vector<double>& y) {
  const int M = L.M;
  auto at = [&](int c, int u) { return &y[size_t(c) * M + u]; };
  // Linear residuals are in units of the mean of A over the channels, so the
  // channels weigh as in lin_rmse.
  const double scale = start.A().mean();
  size_t residuals = 0;
  std::vector<int> ids;
  std::vector<double> ws;
  std::vector<double*> blocks;
  std::unordered_map<int, size_t> pos;
  for (size_t n = 0; n < L.ks.size(); ++n) {
    const size_t k = L.ks[n];
    ids.clear();
    ws.clear();
    pos.clear();
    for (size_t t = 0; t < terms.size(); ++t) {
      const auto& st = L.stencils[n * terms.size() + t];
      for (int q = 0; q < (terms[t].reciprocal ? 2 : 1); ++q)
        for (int a = 0; a < 4; ++a) {
          if (st[q].w[a] == 0.0) continue;
          const int id = L.lay[t].unk[st[q].idx[a]];
          auto it = pos.find(id);
          if (it == pos.end()) {
            pos.emplace(id, ids.size());
            ids.push_back(id);
            ws.push_back(st[q].w[a]);
          } else {
            ws[it->second] += st[q].w[a];
          }
        }
    }
    if (ids.empty()) continue;
    const double sw = std::sqrt(samples.weight_of(k) / (3.0 * L.W));
    const double cosw = obj == Objective::Cosine ? std::max(samples.wi[k].z(), 0.0) : 1.0;
    for (int c = 0; c < 3; ++c) {
      blocks.clear();
      for (int id : ids) blocks.push_back(at(c, id));
      auto* cost = new SampleCost(ws, samples.value[k][c], sw, cosw, start.A()[c], scale, start.eps(),
                                  start.subtract_eps(), obj, blend_weight);
      residuals += cost->num_residuals();
      problem.AddResidualBlock(cost, nullptr, blocks);
    }
  }
  return residuals;
}

// Laplacian rows (4-neighbours inside each term's mask), weighted
// sqrt(smoothing / 3M); returns the number of residuals.
size_t add_laplacian_residuals(ceres::Problem& problem, const RefineLayout& L, const std::vector<FactorTerm>& terms,
                               double smoothing, std::vector<double>& y) {
  const int M = L.M;
  auto at = [&](int c, int u) { return &y[size_t(c) * M + u]; };
  size_t residuals = 0;
  const double lscale = std::sqrt(smoothing / (3.0 * std::max(M, 1)));
  for (size_t t = 0; t < terms.size(); ++t) {
    const int R = terms[t].proj.res;
    for (int j = 0; j < R; ++j)
      for (int i = 0; i < R; ++i) {
        const int u0 = L.lay[t].unk[j * R + i];
        if (u0 < 0) continue;
        std::vector<int> b{u0};
        std::vector<double> v{0.0};
        const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
        for (const auto& q : nb) {
          if (q[0] < 0 || q[0] >= R || q[1] < 0 || q[1] >= R) continue;
          const int u = L.lay[t].unk[q[1] * R + q[0]];
          if (u < 0) continue;
          b.push_back(u);
          v.push_back(-1.0);
          v[0] += 1.0;
        }
        if (b.size() < 2) continue;
        for (int c = 0; c < 3; ++c) {
          std::vector<double*> pb;
          for (int u : b) pb.push_back(at(c, u));
          problem.AddResidualBlock(new LaplacianCost(v, lscale), nullptr, pb);
          ++residuals;
        }
      }
  }
  return residuals;
}

}  // namespace

std::shared_ptr<HomomorphicFactorization> refine(const HomomorphicFactorization& start,
                                                 const SampleSet& samples,
                                                 const RefineOptions& opt, RefineReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  opt.validate();
  const Objective obj = detail::parse_refine_objective(opt.objective);
  if (start.terms().empty()) throw std::invalid_argument("refine: the start has no terms");

  // Terms: projections (direct and conjugate), masks extended by every texel a
  // sample reads, and the texel -> unknown map.
  std::vector<FactorTerm> terms = start.terms();
  const RefineLayout L = refine_layout(terms, samples);
  const int M = L.M;

  // Parameters: one double (log texel) per unknown and channel, from the start;
  // channel c of unknown u is y[c * M + u].
  std::vector<double> y(size_t(3) * M);
  auto at = [&](int c, int u) { return &y[size_t(c) * M + u]; };
  for (size_t t = 0; t < terms.size(); ++t)
    for (size_t i = 0; i < terms[t].mask.size(); ++i)
      if (L.lay[t].unk[i] >= 0)
        for (int c = 0; c < 3; ++c) *at(c, L.lay[t].unk[i]) = terms[t].texels[c][i];

  ceres::Problem problem;
  size_t residuals = add_sample_residuals(problem, L, terms, samples, start, obj, opt.blend_weight, y);
  if (opt.smoothing > 0.0) residuals += add_laplacian_residuals(problem, L, terms, opt.smoothing, y);

  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  std::string solver_name;
  choose_linear_solver(opt.linear_solver, so, solver_name);
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.num_threads = hardware_threads(opt.threads);
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  CeresCancelCallback cancel;
  so.callbacks.push_back(&cancel);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  check_cancel();  // an aborted solve is no result
  if (summary.termination_type == ceres::FAILURE ||
      !std::all_of(y.begin(), y.end(), [](double v) { return std::isfinite(v); }))
    throw std::runtime_error("refine: Ceres failed: " + summary.message);

  for (size_t t = 0; t < terms.size(); ++t)
    for (size_t i = 0; i < terms[t].mask.size(); ++i)
      for (int c = 0; c < 3; ++c)
        terms[t].texels[c][i] =
            L.lay[t].unk[i] >= 0 ? static_cast<float>(*at(c, L.lay[t].unk[i])) : 0.0f;

  auto out = std::make_shared<HomomorphicFactorization>(
      std::move(terms), start.A(), start.eps(), start.subtract_eps(),
      start.method() + "+refine-" + opt.objective, start.log_range());
  if (report) {
    report->objective = opt.objective;
    report->linear_solver = solver_name;
    report->iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
    report->initial_cost = summary.initial_cost;
    report->final_cost = summary.final_cost;
    report->termination =
        std::string(ceres::TerminationTypeToString(summary.termination_type)) + ": " +
        summary.message;
    report->parameters = size_t(3) * M;
    report->residuals = residuals;
    report->texels_added = L.added;
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

}  // namespace bf
