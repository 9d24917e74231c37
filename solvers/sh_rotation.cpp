// SH projection and rotation by exact quadrature (see sh_rotation.h).
#include "solvers/sh_rotation.h"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bf {

Eigen::VectorXd sh_project(int order, const std::function<double(const Eigen::Vector3d&)>& f,
                           const SphereRule& rule) {
  const ShBasis basis(order);
  Eigen::VectorXd c = Eigen::VectorXd::Zero(basis.size());
  Eigen::VectorXd y(basis.size());
  for (size_t k = 0; k < rule.size(); ++k) {
    basis.eval(rule.dir[k], y.data());
    c += (rule.w[k] * f(rule.dir[k])) * y;
  }
  return c;
}

Eigen::VectorXd ShRotation::apply(const Eigen::VectorXd& c) const {
  if (c.size() != sh_count(order))
    throw std::invalid_argument("sh rotation: expected " + std::to_string(sh_count(order)) +
                                " coefficients (order " + std::to_string(order) + "), found " +
                                std::to_string(c.size()));
  Eigen::VectorXd out(c.size());
  for (int l = 0; l <= order; ++l)
    out.segment(l * l, 2 * l + 1) = blocks[l] * c.segment(l * l, 2 * l + 1);
  return out;
}

Eigen::MatrixXd ShRotation::dense() const {
  const int n = sh_count(order);
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  for (int l = 0; l <= order; ++l) D.block(l * l, l * l, 2 * l + 1, 2 * l + 1) = blocks[l];
  return D;
}

ShRotation sh_rotation(int order, const Eigen::Matrix3d& R) {
  if (order < 0) throw std::invalid_argument("sh rotation: order must be >= 0, found " + std::to_string(order));
  if (!R.allFinite() || (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9)
    throw std::invalid_argument("sh rotation: R is not orthogonal to 1e-9");
  if (R.determinant() < 0.0)
    throw std::invalid_argument("sh rotation: R has determinant -1 (a reflection, not a rotation)");
  const ShBasis basis(order);
  const int n = basis.size();
  // Exact for products of two functions of order <= F.
  const SphereRule rule = sphere_rule(order + 1, 2 * order + 1);
  const Eigen::Index N = Eigen::Index(rule.size());
  Eigen::MatrixXd Y(N, n), YR(N, n);  // Y(k, i) = w_k y_i(u_k), YR(k, i) = y_i(R u_k)
  Eigen::VectorXd y(n);
  for (Eigen::Index k = 0; k < N; ++k) {
    basis.eval(rule.dir[k], y.data());
    Y.row(k) = rule.w[k] * y.transpose();
    basis.eval(R * rule.dir[k], y.data());
    YR.row(k) = y.transpose();
  }
  ShRotation rot;
  rot.order = order;
  rot.blocks.resize(order + 1);
  for (int l = 0; l <= order; ++l)
    rot.blocks[l] = YR.middleCols(l * l, 2 * l + 1).transpose() * Y.middleCols(l * l, 2 * l + 1);
  return rot;
}

Eigen::VectorXd sh_rotate(const Eigen::Matrix3d& R, const Eigen::VectorXd& c) {
  const int order = int(std::lround(std::sqrt(double(c.size())))) - 1;
  if (order < 0 || sh_count(order) != c.size())
    throw std::invalid_argument("sh rotation: coefficient count " + std::to_string(c.size()) +
                                " is not a square (F+1)^2");
  return sh_rotation(order, R).apply(c);
}

}  // namespace bf
