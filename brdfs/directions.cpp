// Direction maps and parameterizations (see directions.h).
#include "brdfs/directions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bf {

Vec3 from_spherical(double theta, double phi) {
  const double st = std::sin(theta);
  return Vec3(st * std::cos(phi), st * std::sin(phi), std::cos(theta));
}

void to_spherical(const Vec3& w, double& theta, double& phi) {
  theta = std::acos(std::clamp(w.z(), -1.0, 1.0));
  phi = std::atan2(w.y(), w.x());
}

Vec2 parabolic(const Vec3& w) { return Vec2(w.x(), w.y()) / (1.0 + w.z()); }

Vec3 parabolic_inverse(const Vec2& p) {
  // w = (2x, 2y, 1 - r^2) / (1 + r^2)
  const double r2 = p.squaredNorm();
  const double s = 1.0 / (1.0 + r2);
  return Vec3(2.0 * p.x() * s, 2.0 * p.y() * s, (1.0 - r2) * s);
}

Parameterization parse_parameterization(const std::string& s) {
  if (s == "wiwo") return Parameterization::WiWo;
  if (s == "halfdiff") return Parameterization::HalfDiff;
  throw std::invalid_argument("parameterization: expected \"wiwo\" or \"halfdiff\", found \"" +
                              s + "\"");
}

std::string to_string(Parameterization p) {
  return p == Parameterization::WiWo ? "wiwo" : "halfdiff";
}

Parameterization other_parameterization(Parameterization p) {
  return p == Parameterization::WiWo ? Parameterization::HalfDiff : Parameterization::WiWo;
}

namespace {
// Orthonormal frame (r, s, h) of eq. 1.4.
void frame_of(const Vec3& h, Vec3& r, Vec3& s) {
  Vec3 t(1.0, 0.0, 0.0);
  r = t - t.dot(h) * h;
  double n = r.norm();
  if (n < 1e-12) {
    t = Vec3(0.0, 1.0, 0.0);
    r = t - t.dot(h) * h;
    n = r.norm();
  }
  r /= n;
  s = h.cross(r);
}
}  // namespace

void half_diff(const Vec3& wi, const Vec3& wo, Vec3& h, Vec3& d) {
  h = wi + wo;
  const double n = h.norm();
  if (n < 1e-300) {
    h = Vec3(0.0, 0.0, 1.0);
  } else {
    h /= n;
  }
  Vec3 r, s;
  frame_of(h, r, s);
  // Near wi ~ -wo (theta_d -> 90 deg) wi.h suffers cancellation; there
  // cos(theta_d) = |wi + wo| / 2 is accurate, and the tangential part (norm
  // > 0.86) is rescaled so that |d| = 1. Elsewhere the plain dot products are
  // used, so small tangential components near n = h keep full precision.
  Vec2 t(wi.dot(r), wi.dot(s));
  double cz = wi.dot(h);
  if (0.5 * n < 0.5) {
    cz = 0.5 * n;
    const double tn = t.norm();
    if (tn > 0.0) t *= std::sqrt(1.0 - cz * cz) / tn;
  }
  d = Vec3(t.x(), t.y(), cz);
}

void half_diff_inverse(const Vec3& h, const Vec3& d, Vec3& wi, Vec3& wo) {
  Vec3 r, s;
  frame_of(h, r, s);
  wi = d.x() * r + d.y() * s + d.z() * h;
  wo = 2.0 * wi.dot(h) * h - wi;
}

Vec4 to_point(Parameterization param, const Vec3& wi, const Vec3& wo) {
  Vec4 x;
  if (param == Parameterization::WiWo) {
    x << parabolic(wi), parabolic(wo);
  } else {
    Vec3 h, d;
    half_diff(wi, wo, h, d);
    x << parabolic(h), parabolic(d);
  }
  return x;
}

void from_point(Parameterization param, const Vec4& x, Vec3& wi, Vec3& wo) {
  const Vec3 a = parabolic_inverse(x.head<2>());
  const Vec3 b = parabolic_inverse(x.tail<2>());
  if (param == Parameterization::WiWo) {
    wi = a;
    wo = b;
  } else {
    half_diff_inverse(a, b, wi, wo);
  }
}

}  // namespace bf
