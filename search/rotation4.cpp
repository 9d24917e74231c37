// Quaternion-pair 4D rotations (see rotation4.h).
#include "search/rotation4.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace bf {

Quat qmul(const Quat& a, const Quat& b) {
  return Quat(a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
              a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
              a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
              a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]);
}

Quat qconj(const Quat& q) { return Quat(q[0], -q[1], -q[2], -q[3]); }

Quat qlog(const Quat& q) {
  const double vn = q.tail<3>().norm();
  const double theta = std::atan2(vn, q[0]);
  if (vn < 1e-300) return Quat::Zero();
  Quat r;
  r << 0.0, q.tail<3>() * (theta / vn);
  return r;
}

Quat qexp(const Quat& v) {
  const double a = v.tail<3>().norm();
  Quat r;
  if (a < 1e-300) {
    r << 1.0, v.tail<3>();
  } else {
    r << std::cos(a), v.tail<3>() * (std::sin(a) / a);
  }
  return r;
}

Quat qpow(const Quat& q, double t) { return qexp(qlog(q) * t); }

Quat random_unit_quat(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double u1 = U(rng), u2 = 2 * M_PI * U(rng), u3 = 2 * M_PI * U(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return Quat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3));
}

Vec4 Rotation4::apply(const Vec4& v) const { return qmul(qmul(S, v), T); }

Eigen::Matrix4d Rotation4::matrix() const {
  Eigen::Matrix4d M;
  for (int c = 0; c < 4; ++c) M.col(c) = apply(Vec4::Unit(c));
  return M;
}

Rotation4 Rotation4::compose(const Rotation4& o) const { return {qmul(S, o.S), qmul(o.T, T)}; }

Rotation4 Rotation4::pow(double t) const { return {qpow(S, t), qpow(T, t)}; }

Rotation4 Rotation4::normalized() const { return {S.normalized(), T.normalized()}; }

bool Rotation4::equal_up_to_sign(const Rotation4& o, double tol) const {
  const bool same = (S - o.S).cwiseAbs().maxCoeff() <= tol && (T - o.T).cwiseAbs().maxCoeff() <= tol;
  const bool flip = (S + o.S).cwiseAbs().maxCoeff() <= tol && (T + o.T).cwiseAbs().maxCoeff() <= tol;
  return same || flip;
}

Projection Rotation4::projection(Parameterization param, int res) const {
  Projection p;
  p.param = param;
  p.res = res;
  p.P.row(0) = apply(Vec4::Unit(0)).transpose();
  p.P.row(1) = apply(Vec4::Unit(1)).transpose();
  return p;
}

std::array<double, 8> Rotation4::packed() const {
  return {S[0], S[1], S[2], S[3], T[0], T[1], T[2], T[3]};
}

LineDirection LineDirection::unscaled(const Rotation4& D) {
  LineDirection d;
  // Pick signs so both angles are in [0, pi/2] (shortest arcs); (S, T) ~ (-S, -T)
  // allows flipping both together only, so flip the pair if S.w < 0, then T's
  // angle may exceed pi/2, which is fine: it is still a valid rate.
  Rotation4 R = D.normalized();
  if (R.S[0] < 0) {
    R.S = -R.S;
    R.T = -R.T;
  }
  d.logS = qlog(R.S);
  d.logT = qlog(R.T);
  return d;
}

LineDirection LineDirection::from(const Rotation4& D) {
  LineDirection d = unscaled(D);
  const double m = d.rate();
  if (m < 1e-300) return LineDirection{};
  d.logS *= 0.5 / m;
  d.logT *= 0.5 / m;
  return d;
}

Rotation4 LineDirection::at(const Rotation4& start, double t) const {
  return {qmul(qexp(logS * t), start.S), qmul(start.T, qexp(logT * t))};
}

std::array<Rotation4, 6> cole_basis_directions() {
  const Quat one(1, 0, 0, 0);
  return {Rotation4{Quat(0, 1, 0, 0), one}, Rotation4{Quat(0, 0, 1, 0), one},
          Rotation4{Quat(0, 0, 0, 1), one}, Rotation4{one, Quat(0, 1, 0, 0)},
          Rotation4{one, Quat(0, 0, 1, 0)}, Rotation4{one, Quat(0, 0, 0, 1)}};
}

// (S, T) of a rotation matrix M (orthonormal, det +1). With M v = S v T:
// M e0 = S T and M e_c = S u_c T for u = (i, j, k), so
// conj(M e0) (M e_c) = conj(T) u_c T: the columns of the 3D rotation x -> conj(T) x T.
// Reading that rotation's quaternion gives conj(T), then S = (M e0) conj(T).
Rotation4 Rotation4::from_matrix(const Eigen::Matrix4d& M) {
  Eigen::Matrix3d Rt;
  const Quat m0 = M.col(0);
  for (int c = 1; c < 4; ++c) {
    const Quat img = qmul(qconj(m0), Quat(M.col(c)));
    Rt.col(c - 1) = img.tail<3>();
  }
  // Rt maps x to conj(T) x T, i.e. the 3D rotation of quaternion conj(T).
  Eigen::Quaterniond q(Rt);  // Eigen coeffs are [x, y, z, w]; convert explicitly.
  const Quat conjT(q.w(), q.x(), q.y(), q.z());
  const Quat T = qconj(conjT).normalized();
  const Quat S = qmul(m0, qconj(T)).normalized();
  return {S, T};
}

Rotation4 guess_rotation(const std::string& name) {
  if (name == "wi") return Rotation4::identity();
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  if (name == "wo") {
    // e0 -> e2, e1 -> e3, e2 -> e0, e3 -> e1 (det +1).
    M(2, 0) = M(3, 1) = M(0, 2) = M(1, 3) = 1.0;
  } else if (name == "wi+wo") {
    const double r = std::sqrt(0.5);
    M.col(0) << r, 0, r, 0;
    M.col(1) << 0, r, 0, r;
    M.col(2) << -r, 0, r, 0;
    M.col(3) << 0, -r, 0, r;
  } else {
    throw std::invalid_argument("guesses: expected \"wi\", \"wo\" or \"wi+wo\", found \"" + name +
                                "\"");
  }
  return Rotation4::from_matrix(M);
}

double plane_distance(const Mat24& a, const Mat24& b) { return 2 - (a * b.transpose()).squaredNorm(); }

}  // namespace bf
