// 4D rotations as pairs of unit quaternions (S, T) acting as v -> S v T
// (thesis 2.3.1), and the projections they define.
//
// Layout, fixed here once for the whole code base: a quaternion is a
// Eigen::Vector4d stored [w, x, y, z]; a 4D vector v = (v0, v1, v2, v3) is the
// quaternion v0 + v1 i + v2 j + v3 k. (S, T) and (-S, -T) are the same rotation;
// compare with equal_up_to_sign(). Never pass Eigen::Quaterniond::coeffs()
// ([x, y, z, w]) to anything here.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <random>

#include "factor/projection.h"

namespace bf {

using Quat = Eigen::Vector4d;  // [w, x, y, z]

Quat qmul(const Quat& a, const Quat& b);
Quat qconj(const Quat& q);
// log of a unit quaternion: the pure quaternion (0, theta n) with q = (cos theta, sin theta n),
// theta in [0, pi].
Quat qlog(const Quat& q);
// exp of a pure quaternion (0, v): (cos |v|, sin |v| v / |v|).
Quat qexp(const Quat& v);
// q^t = exp(t log q), continuous in t.
Quat qpow(const Quat& q, double t);
// A uniformly distributed random unit quaternion (Shoemake's method).
Quat random_unit_quat(std::mt19937_64& rng);

struct Rotation4 {
  Quat S = Quat(1, 0, 0, 0);
  Quat T = Quat(1, 0, 0, 0);

  static Rotation4 identity() { return {}; }
  static Rotation4 random(std::mt19937_64& rng) { return {random_unit_quat(rng), random_unit_quat(rng)}; }

  // v -> S v T.
  Vec4 apply(const Vec4& v) const;
  // 4x4 matrix M with M v = apply(v); orthonormal with det +1.
  Eigen::Matrix4d matrix() const;
  // Composition (this o other): v -> this(other(v)); S' = S1 S2, T' = T2 T1.
  Rotation4 compose(const Rotation4& other) const;
  Rotation4 inverse() const { return {qconj(S), qconj(T)}; }
  // R^t = (S^t, T^t); R^0 = I, R^1 = R, R^a R^b = R^(a+b).
  Rotation4 pow(double t) const;
  // Renormalizes S and T (guards against drift over many compositions).
  Rotation4 normalized() const;
  bool equal_up_to_sign(const Rotation4& o, double tol = 1e-12) const;

  // The projection of thesis 2.3.1: rows are R e1 and R e2 (the rotated first two
  // basis vectors), scaled into the texture square by Projection's row scale.
  Projection projection(Parameterization param, int res) const;
  // [S.w, S.x, S.y, S.z, T.w, T.x, T.y, T.z]
  std::array<double, 8> packed() const;
  // The rotation of a 4x4 matrix M (orthonormal, det +1; not checked):
  // matrix() of the result equals M to rounding.
  static Rotation4 from_matrix(const Eigen::Matrix4d& M);
  static Rotation4 from_packed(const std::array<double, 8>& p) {
    return {Quat(p[0], p[1], p[2], p[3]), Quat(p[4], p[5], p[6], p[7])};
  }
};

// A search direction prepared for the line R(t) = D^t R_s: D's two angles are
// rescaled so that the larger one advances at 1/2 radian per unit t (quaternion
// half-angle convention), so t is the rotation angle of the faster factor and
// a direction whose other factor is the identity (Cole's six basis directions)
// or has the same angle is exactly periodic with period 4 pi. The ratio of the
// two angles is kept, so the net direction of a Powell sweep passes through its
// end point.
struct LineDirection {
  Quat logS = Quat::Zero(), logT = Quat::Zero();  // pure quaternions (rates)
  static LineDirection from(const Rotation4& D);
  // D's logs without the rescaling (shortest-arc signs as in from()); a
  // direction over several rotations at once scales all of them by one factor.
  static LineDirection unscaled(const Rotation4& D);
  // The larger of the two rates' norms.
  double rate() const { return std::max(logS.norm(), logT.norm()); }
  // D^t applied to the start: (exp(t logS) S_s, T_s exp(t logT)).
  Rotation4 at(const Rotation4& start, double t) const;
  bool is_zero() const { return logS.squaredNorm() + logT.squaredNorm() == 0.0; }
};

// Cole's six initial basis directions (thesis 3.1.1).
std::array<Rotation4, 6> cole_basis_directions();

// The projection guesses of thesis 3.1.3 as rotations: wi (identity), wo
// (e1 -> e3, e2 -> e4) and wi + wo (e1 -> (e1 + e3)/sqrt 2, e2 -> (e2 + e4)/sqrt 2).
Rotation4 guess_rotation(const std::string& name);

// The distance 2 - |A B^T|_F^2 between the planes spanned by the orthonormal
// rows of A and B: 0 for the same plane, 2 for orthogonal planes.
double plane_distance(const Mat24& a, const Mat24& b);

}  // namespace bf
