// SH projection and rotation by exact quadrature (see sh_rotation.h).
#include "solvers/sh_rotation.h"

#include <Eigen/LU>
#include <algorithm>
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

void sh_rotate_z(int order, double angle, double* c) {
  // cos(m a), sin(m a) by the angle-addition recurrence (two trig calls per
  // rotation; the error grows ~ m * 1e-16, negligible for m <= 200).
  const double c1 = std::cos(angle), s1 = std::sin(angle);
  double cm = 1.0, sm = 0.0;
  for (int m = 1; m <= order; ++m) {
    const double cn = cm * c1 - sm * s1;
    sm = sm * c1 + cm * s1;
    cm = cn;
    for (int l = m; l <= order; ++l) {
      double& p = c[sh_index(l, m)];
      double& n = c[sh_index(l, -m)];
      const double a = p, b = n;
      p = a * cm - b * sm;
      n = a * sm + b * cm;
    }
  }
}

void sh_rotate_z(int order, double angle, Eigen::MatrixXd& C) {
  const double c1 = std::cos(angle), s1 = std::sin(angle);
  double cm = 1.0, sm = 0.0;
  Eigen::RowVectorXd a, b;
  for (int m = 1; m <= order; ++m) {
    const double cn = cm * c1 - sm * s1;
    sm = sm * c1 + cm * s1;
    cm = cn;
    for (int l = m; l <= order; ++l) {
      a = C.row(sh_index(l, m));
      b = C.row(sh_index(l, -m));
      C.row(sh_index(l, m)) = a * cm - b * sm;
      C.row(sh_index(l, -m)) = a * sm + b * cm;
    }
  }
}

void ShFastRotator::rotate_zyz(double a, double b, double g, Eigen::MatrixXd& C) const {
  if (C.rows() != sh_count(order_))
    throw std::invalid_argument("sh fast rotator: expected " + std::to_string(sh_count(order_)) + " rows, found " +
                                std::to_string(C.rows()));
  Eigen::MatrixXd tmp;
  sh_rotate_z(order_, g, C);
  for (int l = 1; l <= order_; ++l) {
    tmp = xp_[l] * C.middleRows(l * l, 2 * l + 1);
    C.middleRows(l * l, 2 * l + 1) = tmp;
  }
  sh_rotate_z(order_, b, C);
  for (int l = 1; l <= order_; ++l) {
    tmp = xm_[l] * C.middleRows(l * l, 2 * l + 1);
    C.middleRows(l * l, 2 * l + 1) = tmp;
  }
  sh_rotate_z(order_, a, C);
}

ShFastRotator::ShFastRotator(int order) : order_(order) {
  if (order < 0 || order > 200)
    throw std::invalid_argument("sh fast rotator: order: expected 0..200, found " + std::to_string(order));
  Eigen::Matrix3d Rx;
  Rx << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // R_x(+90): y -> z
  const ShRotation p = sh_rotation(order, Rx), m = sh_rotation(order, Rx.transpose());
  xp_ = p.blocks;
  xm_ = m.blocks;
}

void ShFastRotator::rotate_zyz(double a, double b, double g, double* c) const {
  // D(Rz(a) Ry(b) Rz(g)) c = Z(a) Xm Z(b) Xp Z(g) c.
  sh_rotate_z(order_, g, c);
  Eigen::VectorXd tmp;
  for (int l = 1; l <= order_; ++l) {
    Eigen::Map<Eigen::VectorXd> seg(c + l * l, 2 * l + 1);
    tmp = xp_[l] * seg;
    seg = tmp;
  }
  sh_rotate_z(order_, b, c);
  for (int l = 1; l <= order_; ++l) {
    Eigen::Map<Eigen::VectorXd> seg(c + l * l, 2 * l + 1);
    tmp = xm_[l] * seg;
    seg = tmp;
  }
  sh_rotate_z(order_, a, c);
}

Eigen::Vector3d ShFastRotator::euler_zyz(const Eigen::Matrix3d& R) {
  if (!R.allFinite() || (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
      R.determinant() < 0.0)
    throw std::invalid_argument("sh fast rotator: R is not a rotation to 1e-9");
  // R = Rz(a) Ry(b) Rz(g): R(2,2) = cos b, R(0,2) = cos a sin b, R(1,2) = sin a sin b,
  // R(2,0) = -sin b cos g, R(2,1) = sin b sin g.
  const double cb = std::clamp(R(2, 2), -1.0, 1.0);
  const double b = std::acos(cb);
  const double sb = std::sqrt(R(0, 2) * R(0, 2) + R(1, 2) * R(1, 2));
  if (sb > 1e-12) return {std::atan2(R(1, 2), R(0, 2)), b, std::atan2(R(2, 1), -R(2, 0))};
  // Gimbal: b = 0 (R = Rz(a + g)) or b = pi (R = Rz(a) Ry(pi), g = 0).
  if (cb > 0) return {std::atan2(R(1, 0), R(0, 0)), 0.0, 0.0};
  return {std::atan2(-R(1, 0), -R(0, 0)), M_PI, 0.0};
}

void ShFastRotator::rotate(const Eigen::Matrix3d& R, double* c) const {
  const Eigen::Vector3d e = euler_zyz(R);
  rotate_zyz(e[0], e[1], e[2], c);
}

}  // namespace bf
