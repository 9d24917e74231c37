// Azimuthal-invariance test (see isotropy.h).
#include "factor/isotropy.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace bf {

void IsotropyOptions::validate() const {
  if (pairs < 1 || pairs > 1000000)
    throw std::invalid_argument("isotropy test: pairs: expected 1..1000000, found " + std::to_string(pairs));
  if (angles < 1 || angles > 1000)
    throw std::invalid_argument("isotropy test: angles: expected 1..1000, found " + std::to_string(angles));
  if (!(rel_tol > 0.0 && rel_tol < 1.0))
    throw std::invalid_argument("isotropy test: rel_tol: expected 0 < rel_tol < 1, found " + std::to_string(rel_tol));
  if (!(floor_fraction >= 0.0 && floor_fraction < 1.0))
    throw std::invalid_argument("isotropy test: floor_fraction: expected 0 <= floor_fraction < 1, found " +
                                std::to_string(floor_fraction));
}

namespace {
Vec3 rotz(const Vec3& v, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}
}  // namespace

IsotropyResult test_isotropy(const Brdf& brdf, const IsotropyOptions& opt) {
  opt.validate();
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto hemi = [&] {
    // Uniform on the hemisphere, kept off the exact horizon.
    const double z = 0.02 + 0.98 * U(rng), phi = 2.0 * M_PI * U(rng);
    const double s = std::sqrt(1.0 - z * z);
    return Vec3(s * std::cos(phi), s * std::sin(phi), z);
  };
  IsotropyResult r;
  struct Pair { Vec3 wi, wo; Rgb f; };
  std::vector<Pair> base;
  base.reserve(opt.pairs);
  double mean = 0.0;
  for (int k = 0; k < opt.pairs; ++k) {
    Pair p{hemi(), hemi(), Rgb::Zero()};
    p.f = brdf.eval(p.wi, p.wo);
    ++r.evaluations;
    if (!p.f.isFinite().all()) {
      ++r.skipped;
      continue;
    }
    mean += p.f.abs().mean();
    base.push_back(p);
  }
  if (base.empty()) return r;
  mean /= double(base.size());
  const double floor = opt.floor_fraction * mean;
  for (const Pair& p : base)
    for (int a = 0; a < opt.angles; ++a) {
      const double ang = 2.0 * M_PI * U(rng);
      const Rgb g = brdf.eval(rotz(p.wi, ang), rotz(p.wo, ang));
      ++r.evaluations;
      if (!g.isFinite().all()) {
        ++r.skipped;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const double den = std::max(std::abs(g[c]), std::abs(p.f[c])) + floor;
        const double dev = den > 0.0 ? std::abs(g[c] - p.f[c]) / den : 0.0;
        if (dev > r.max_rel_change) {
          r.max_rel_change = dev;
          r.worst_wi = p.wi;
          r.worst_wo = p.wo;
          r.worst_angle = ang;
        }
      }
    }
  r.isotropic = r.max_rel_change <= opt.rel_tol;
  return r;
}

nlohmann::json IsotropyResult::describe() const {
  return {{"isotropic", isotropic},
          {"max_rel_change", max_rel_change},
          {"worst_wi", {worst_wi.x(), worst_wi.y(), worst_wi.z()}},
          {"worst_wo", {worst_wo.x(), worst_wo.y(), worst_wo.z()}},
          {"worst_angle", worst_angle},
          {"evaluations", evaluations},
          {"skipped", skipped}};
}

}  // namespace bf
