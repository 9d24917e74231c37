// Projection of spherical functions onto real SH by exact quadrature, and
// rotation of SH coefficient vectors (block-diagonal per band, built by
// projection with a rule that is exact for band-limited products, so every
// block is orthogonal to rounding; notes P12/P13).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "solvers/quadrature.h"
#include "solvers/sh.h"

namespace bf {

// c_i = sum_k w_k y_i(dir_k) f(dir_k) over the rule: the SH projection of f,
// order F ((F+1)^2 coefficients, sh.h convention). With
// sphere_rule(F + 1, 2F + 1) it is exact for f of order <= F.
Eigen::VectorXd sh_project(int order, const std::function<double(const Eigen::Vector3d&)>& f,
                           const SphereRule& rule);

// Rotation of real SH coefficients. For a rotation R (3x3, orthogonal, det +1)
// and f = sum_i c_i y_i, the rotated function g(s) = f(R^T s) has coefficients
// c'_l = D^l c_l per band l, with
//   D^l_{m m'} = integral y_lm(R u) y_lm'(u) du,   rows/cols m, m' = -l..l
// (Kautz et al. 2002 Appendix, with its OCR typos fixed: M_ij, sum over j).
// The composition rule is D(R1 R2) = D(R1) D(R2).
struct ShRotation {
  int order = 0;
  std::vector<Eigen::MatrixXd> blocks;  // blocks[l] is (2l+1) x (2l+1)
  // c' = D c; c has sh_count(order) entries (throws otherwise).
  Eigen::VectorXd apply(const Eigen::VectorXd& c) const;
  // The full block-diagonal (F+1)^2 x (F+1)^2 matrix.
  Eigen::MatrixXd dense() const;
};

// Cost O(F^4) (projection with an exact (F+1) x (2F+1) rule); fine to F ~ 60.
// Throws std::invalid_argument if R is not a rotation to 1e-9 or order < 0.
ShRotation sh_rotation(int order, const Eigen::Matrix3d& R);
// Convenience: sh_rotation(order, R).apply(c), order from c's size.
Eigen::VectorXd sh_rotate(const Eigen::Matrix3d& R, const Eigen::VectorXd& c);

// In place c <- D(R_z(angle)) c (same convention as ShRotation): for m > 0,
//   c'_m = c_m cos(m a) - c_{-m} sin(m a),  c'_{-m} = c_m sin(m a) + c_{-m} cos(m a).
// O((F+1)^2); c holds sh_count(order) values.
void sh_rotate_z(int order, double angle, double* c);
// Same for every column of C ((F+1)^2 rows).
void sh_rotate_z(int order, double angle, Eigen::MatrixXd& C);

// Fast rotation of real SH coefficients by zyz Euler angles (Kautz et al.
// 2002 Appendix, method 2): D(R_y(b)) = D(R_x(-90)) D(R_z(b)) D(R_x(+90)),
// with the two fixed x-rotations built once, exactly, by sh_rotation. Cost per
// rotation O(F^3) instead of sh_rotation's O(F^4).
class ShFastRotator {
 public:
  explicit ShFastRotator(int order);  // order 0..200
  int order() const { return order_; }
  // c <- D(R) c for R = R_z(a) R_y(b) R_z(g) (c: sh_count(order) values).
  void rotate_zyz(double a, double b, double g, double* c) const;
  // Every column of C ((F+1)^2 rows) rotated at once (block products).
  void rotate_zyz(double a, double b, double g, Eigen::MatrixXd& C) const;
  // c <- D(R) c for any rotation R (to 1e-9; Euler angles extracted, both
  // gimbal cases handled). Throws std::invalid_argument for a non-rotation.
  void rotate(const Eigen::Matrix3d& R, double* c) const;
  // zyz angles (a, b, g) with R = R_z(a) R_y(b) R_z(g), b in [0, pi].
  static Eigen::Vector3d euler_zyz(const Eigen::Matrix3d& R);

 private:
  int order_;
  std::vector<Eigen::MatrixXd> xp_, xm_;  // D(R_x(+90)), D(R_x(-90)) per band
};

}  // namespace bf
