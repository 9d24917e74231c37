// Homomorphic least-squares fit (see homomorphic_fit.h for the formulation).
#include "factor/homomorphic_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace bf {

void FitOptions::validate() const {
  if (!(eps > 0.0 && eps <= 1.0))
    throw std::invalid_argument("eps: expected 0 < eps <= 1, found " + std::to_string(eps));
  if (!(smoothing >= 0.0) || !std::isfinite(smoothing))
    throw std::invalid_argument("smoothing: expected a finite value >= 0, found " +
                                std::to_string(smoothing));
  if (solve_last < 1)
    throw std::invalid_argument("solve_last: expected >= 1, found " + std::to_string(solve_last));
}

FitData::FitData(const SampleSet& s, double eps) {
  transform = LogTransform::of(s, eps);
  const size_t n = s.valid_count();
  x_wiwo.reserve(n);
  x_halfdiff.reserve(n);
  w.reserve(n);
  for (int c = 0; c < 3; ++c) g[c].reserve(n);
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    x_wiwo.push_back(to_point(Parameterization::WiWo, s.wi[k], s.wo[k]));
    x_halfdiff.push_back(to_point(Parameterization::HalfDiff, s.wi[k], s.wo[k]));
    w.push_back(s.weight_of(k));
    W += s.weight_of(k);
    for (int c = 0; c < 3; ++c) g[c].push_back(transform.g(c, s.value[k][c]));
  }
  if (!(W > 0.0)) throw std::invalid_argument("fit: the valid samples' weights sum to 0");
}

double model_log_value(double s, const FitOptions& opt) {
  if (opt.subtract_eps) return std::max(s, std::log(opt.eps));
  // log(exp(s) + eps), computed without overflow.
  return s > 0 ? s + std::log1p(opt.eps * std::exp(-s)) : std::log(std::exp(s) + opt.eps);
}

std::array<std::vector<double>, 3> fixed_sum(const FitData& d,
                                             const std::vector<FactorTerm>& fixed) {
  std::array<std::vector<double>, 3> out;
  for (int c = 0; c < 3; ++c) out[c].assign(d.size(), 0.0);
  for (const FactorTerm& t : fixed) {
    const std::vector<Vec4>& x = d.points(t.proj.param);
    const Projection conj = t.proj.conjugate();
    for (size_t k = 0; k < d.size(); ++k) {
      const Eigen::Vector2d s = t.proj.texel_coords(x[k]);
      for (int c = 0; c < 3; ++c) out[c][k] += t.lookup(c, s);
      if (t.reciprocal) {
        const Eigen::Vector2d sc = conj.texel_coords(x[k]);
        for (int c = 0; c < 3; ++c) out[c][k] += t.lookup(c, sc);
      }
    }
  }
  return out;
}

namespace {

// A projection prepared for fast per-sample use: P pre-multiplied by the row
// scale and the affine map to texel coordinates.
struct FastProj {
  Eigen::Matrix<double, 2, 4> M;
  double off;
  int res;
  explicit FastProj(const Projection& p) : res(p.res) {
    const Eigen::Vector2d sc = p.row_scale();
    const double half = 0.5 * (p.res - 1);
    M.row(0) = p.P.row(0) * (sc[0] * half);
    M.row(1) = p.P.row(1) * (sc[1] * half);
    off = half;
  }
  Bilinear at(const Vec4& x) const {
    return bilinear(Eigen::Vector2d(M.row(0).dot(x) + off, M.row(1).dot(x) + off), res);
  }
};

struct TermLayout {
  FastProj proj, conj;
  bool reciprocal;
  const std::vector<Vec4>* x;
  std::vector<int> unk;  // texel -> unknown index, -1 outside the mask
  std::vector<uint8_t> mask;
  int first = 0, count = 0;
};

// Graph-Laplacian rows of one term's mask, accumulated as mu * L^T L.
template <class AddFn>
void laplacian_rows(const TermLayout& t, AddFn add_row) {
  const int R = t.proj.res;
  int idx[5];
  double val[5];
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < R; ++i) {
      const int c = t.unk[j * R + i];
      if (c < 0) continue;
      int n = 1;
      idx[0] = c;
      val[0] = 0.0;
      const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
      for (const auto& q : nb) {
        if (q[0] < 0 || q[0] >= R || q[1] < 0 || q[1] >= R) continue;
        const int u = t.unk[q[1] * R + q[0]];
        if (u < 0) continue;
        idx[n] = u;
        val[n] = -1.0;
        val[0] += 1.0;
        ++n;
      }
      if (n > 1) add_row(idx, val, n);
    }
}

}  // namespace

JointSolution solve_joint(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                          const std::vector<TermSpec>& joint, const FitOptions& opt) {
  opt.validate();
  if (joint.empty()) throw std::invalid_argument("fit: no terms to solve");
  const size_t N = d.size();

  // Layout: masks (thesis 3.2.4) extended by every texel a sample touches, so
  // no sample ever reads a texel that is not an unknown.
  std::vector<TermLayout> terms;
  terms.reserve(joint.size());
  int M = 0;
  for (const TermSpec& s : joint) {
    s.proj.validate();
    TermLayout t{FastProj(s.proj), FastProj(s.proj.conjugate()), s.reciprocal,
                 &d.points(s.proj.param), {}, projection_mask(s.proj), 0, 0};
    const std::vector<Vec4>& x = *t.x;
    for (size_t k = 0; k < N; ++k) {
      const Bilinear b = t.proj.at(x[k]);
      for (int a = 0; a < 4; ++a) t.mask[b.idx[a]] = 1;
      if (t.reciprocal) {
        const Bilinear bc = t.conj.at(x[k]);
        for (int a = 0; a < 4; ++a) t.mask[bc.idx[a]] = 1;
      }
    }
    t.unk.assign(t.mask.size(), -1);
    t.first = M;
    for (size_t i = 0; i < t.mask.size(); ++i)
      if (t.mask[i]) t.unk[i] = M++;
    t.count = M - t.first;
    terms.push_back(std::move(t));
  }

  // Per-sample stencils: up to 8 entries per term.
  const int maxL = 8 * static_cast<int>(terms.size());
  auto stencil = [&](size_t k, int* idx, double* val) {
    int L = 0;
    for (const TermLayout& t : terms) {
      const Bilinear b = t.proj.at((*t.x)[k]);
      for (int a = 0; a < 4; ++a) {
        idx[L] = t.unk[b.idx[a]];
        val[L++] = b.w[a];
      }
      if (t.reciprocal) {
        const Bilinear bc = t.conj.at((*t.x)[k]);
        for (int a = 0; a < 4; ++a) {
          idx[L] = t.unk[bc.idx[a]];
          val[L++] = bc.w[a];
        }
      }
    }
    return L;
  };

  const double mu = opt.smoothing * d.W / std::max(M, 1);
  Eigen::MatrixXd Y(M, 3);  // solution, one column per channel
  std::vector<int> idx(maxL);
  std::vector<double> val(maxL);

  FitOptions::Solver solver = opt.solver;
  if (solver == FitOptions::Solver::Auto)
    solver = M <= 2500 ? FitOptions::Solver::Dense : FitOptions::Solver::Sparse;

  if (solver == FitOptions::Solver::Sparse) {
    using SpMat = Eigen::SparseMatrix<double>;
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(N * maxL);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(M, 3);
    for (size_t k = 0; k < N; ++k) {
      const int L = stencil(k, idx.data(), val.data());
      const double sw = std::sqrt(d.w[k]);
      const double r0 = d.g[0][k] - fixed_values[0][k];
      const double r1 = d.g[1][k] - fixed_values[1][k];
      const double r2 = d.g[2][k] - fixed_values[2][k];
      for (int a = 0; a < L; ++a) {
        trip.emplace_back(static_cast<int>(k), idx[a], sw * val[a]);
        const double wa = d.w[k] * val[a];
        rhs(idx[a], 0) += wa * r0;
        rhs(idx[a], 1) += wa * r1;
        rhs(idx[a], 2) += wa * r2;
      }
    }
    int row = static_cast<int>(N);
    const double smu = std::sqrt(mu);
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        for (int a = 0; a < n; ++a) trip.emplace_back(row, li[a], smu * lv[a]);
        ++row;
      });
    SpMat B(row, M);
    B.setFromTriplets(trip.begin(), trip.end());
    trip.clear();
    trip.shrink_to_fit();
    SpMat A = (B.transpose() * B).pruned();
    double mean_diag = A.diagonal().sum() / std::max(M, 1);
    // Gauge as a soft constraint on each later term's texel mean would make the
    // matrix dense in that block; in the sparse path we pin one texel of each
    // later joint term instead (same effect: removes the constant freedom).
    for (size_t t = 1; t < terms.size(); ++t) {
      const int i0 = terms[t].first;
      A.coeffRef(i0, i0) += mean_diag;
    }
    for (int i = 0; i < M; ++i) A.coeffRef(i, i) += 1e-12 * mean_diag + std::numeric_limits<double>::min();
    Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> llt(A);
    if (llt.info() != Eigen::Success)
      throw std::runtime_error("fit: the normal matrix is not positive definite (" +
                               std::to_string(M) + " unknowns)");
    Y = llt.solve(rhs);
  } else if (solver == FitOptions::Solver::Dense) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(M, M);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(M, 3);
    double* Ad = A.data();
    for (size_t k = 0; k < N; ++k) {
      const int L = stencil(k, idx.data(), val.data());
      const double w = d.w[k];
      const double r0 = d.g[0][k] - fixed_values[0][k];
      const double r1 = d.g[1][k] - fixed_values[1][k];
      const double r2 = d.g[2][k] - fixed_values[2][k];
      for (int a = 0; a < L; ++a) {
        const double wa = w * val[a];
        const int ia = idx[a];
        double* col = Ad + static_cast<size_t>(ia) * M;
        for (int b = 0; b < L; ++b) col[idx[b]] += wa * val[b];
        rhs(ia, 0) += wa * r0;
        rhs(ia, 1) += wa * r1;
        rhs(ia, 2) += wa * r2;
      }
    }
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        for (int a = 0; a < n; ++a)
          for (int b = 0; b < n; ++b) A(li[a], li[b]) += mu * lv[a] * lv[b];
      });
    const double mean_diag = A.diagonal().sum() / std::max(M, 1);
    for (size_t t = 1; t < terms.size(); ++t) {
      const double gamma = mean_diag / terms[t].count;
      A.block(terms[t].first, terms[t].first, terms[t].count, terms[t].count).array() += gamma;
    }
    A.diagonal().array() += 1e-12 * mean_diag + std::numeric_limits<double>::min();
    Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(A);
    if (llt.info() != Eigen::Success)
      throw std::runtime_error("fit: the normal matrix is not positive definite (" +
                               std::to_string(M) + " unknowns)");
    Y = llt.solve(rhs);
  } else {
    // Reference path: form B (data rows, Laplacian rows, gauge rows) densely and
    // solve the least-squares problem by Householder QR, without normal equations.
    int lap_rows = 0;
    for (const TermLayout& t : terms) laplacian_rows(t, [&](const int*, const double*, int) { ++lap_rows; });
    const int rows = static_cast<int>(N) + lap_rows + static_cast<int>(terms.size()) - 1;
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(rows, M);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(rows, 3);
    for (size_t k = 0; k < N; ++k) {
      const int L = stencil(k, idx.data(), val.data());
      const double sw = std::sqrt(d.w[k]);
      for (int a = 0; a < L; ++a) B(k, idx[a]) += sw * val[a];
      for (int c = 0; c < 3; ++c) r(k, c) = sw * (d.g[c][k] - fixed_values[c][k]);
    }
    int row = static_cast<int>(N);
    const double smu = std::sqrt(mu);
    for (const TermLayout& t : terms)
      laplacian_rows(t, [&](const int* li, const double* lv, int n) {
        for (int a = 0; a < n; ++a) B(row, li[a]) += smu * lv[a];
        ++row;
      });
    const double mean_diag = B.colwise().squaredNorm().sum() / std::max(M, 1);
    for (size_t t = 1; t < terms.size(); ++t) {
      const double sg = std::sqrt(mean_diag / terms[t].count);
      for (int i = 0; i < terms[t].count; ++i) B(row, terms[t].first + i) = sg;
      ++row;
    }
    Y = B.colPivHouseholderQr().solve(r);
  }
  if (!Y.allFinite()) throw std::runtime_error("fit: the solution is not finite");

  // Residual: rel_mse of fixed + joint terms, with the reconstruction's clamping.
  JointSolution sol;
  sol.unknowns = static_cast<size_t>(M);
  double se = 0;
  for (size_t k = 0; k < N; ++k) {
    const int L = stencil(k, idx.data(), val.data());
    for (int c = 0; c < 3; ++c) {
      double s = fixed_values[c][k];
      for (int a = 0; a < L; ++a) s += val[a] * Y(idx[a], c);
      const double e = model_log_value(s, opt) - d.g[c][k];
      se += d.w[k] * e * e;
    }
  }
  sol.rel_mse = se / (3.0 * d.W);

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
    sol.terms.push_back(std::move(ft));
  }
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
  return std::make_shared<HomomorphicFactorization>(done, d.transform.A, opt.eps,
                                                    opt.subtract_eps, method);
}

std::vector<TermSpec> mccool_terms(int res) {
  TermSpec p{projection_first_pair(Parameterization::WiWo, res), true, std::nullopt};
  TermSpec q{projection_first_pair(Parameterization::HalfDiff, res), false, std::nullopt};
  return {p, q};
}

}  // namespace bf
