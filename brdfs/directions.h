// Direction maps: spherical angles, the Heidrich-Seidel parabolic map, and the
// two 4D parameterizations of (wi, wo) the fitter works in (docs/design.md §2).
#pragma once

#include <string>

#include "brdfs/brdf.h"

namespace bf {

// Unit vector from spherical angles: theta from +z, phi from +x towards +y (radians).
Vec3 from_spherical(double theta, double phi);
// theta in [0, pi], phi in (-pi, pi].
void to_spherical(const Vec3& w, double& theta, double& phi);

// Parabolic map of the upper hemisphere onto the unit disk: p(w) = (w.x, w.y) / (1 + w.z).
// Defined for w.z > -1; exact for the upper hemisphere.
Vec2 parabolic(const Vec3& w);
// Inverse of parabolic(): a point of the closed unit disk -> unit vector with z >= 0.
// Points outside the disk map below the horizon (z < 0).
Vec3 parabolic_inverse(const Vec2& p);

enum class Parameterization { WiWo, HalfDiff };
// "wiwo" | "halfdiff"; throws std::invalid_argument naming the accepted values otherwise.
Parameterization parse_parameterization(const std::string& s);
std::string to_string(Parameterization p);
// The other one of the two: wiwo <-> halfdiff.
Parameterization other_parameterization(Parameterization p);

// Half vector and difference vector in the numerically stable form of Kautz-McCool
// (thesis eq. 1.4): h = normalize(wi + wo); r = normalize(t - (t.h) h) with t = +x
// (falls back to +y when h is within 1e-12 of +-x); s = h x r; d = (wi.r, wi.s, wi.h).
// wi, wo unit vectors. wi = -wo (h undefined) gives h = n, d = wi.
void half_diff(const Vec3& wi, const Vec3& wo, Vec3& h, Vec3& d);
// Inverse of half_diff: wi = d.x r + d.y s + d.z h, wo = 2 (wi.h) h - wi.
void half_diff_inverse(const Vec3& h, const Vec3& d, Vec3& wi, Vec3& wo);

// The 4D point x in [-1,1]^4 of (wi, wo) under a parameterization:
//   wiwo:     x = (p(wi), p(wo))
//   halfdiff: x = (p(h), p(d))
Vec4 to_point(Parameterization param, const Vec3& wi, const Vec3& wo);
// Inverse of to_point (both halves must lie in the unit disk for a valid pair).
void from_point(Parameterization param, const Vec4& x, Vec3& wi, Vec3& wo);

}  // namespace bf
