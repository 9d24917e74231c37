// Fits of raw samples with the BRDF's symmetries (brdfs/symmetry.h,
// expand_orbit): a half-slice of an isotropic BRDF, expanded by its orbit,
// fits as well as samples over the whole domain.
#include <cmath>
#include <random>

#include "brdfs/directions.h"
#include "brdfs/sampleset.h"
#include "brdfs/symmetry.h"
#include "factor/homomorphic_fit.h"
#include "factor/metrics.h"
#include "test_common.h"

using namespace bf;

namespace {

// p(wi) q(h) p(wo) with radial p and q (isotropic, reciprocal, bilateral),
// exactly McCool's form up to the textures' bilinear interpolation.
class RadialMcCool final : public Brdf {
 public:
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0 || wo.z() <= 0) return Rgb::Zero();
    const Vec3 h = (wi + wo).normalized();
    const double p = std::exp(0.4 * parabolic(wi).squaredNorm()) * std::exp(0.4 * parabolic(wo).squaredNorm());
    return Rgb(0.2, 0.3, 0.5) * (p * std::exp(-2.5 * parabolic(h).squaredNorm()));
  }
  std::string name() const override { return "radial-mccool"; }
  std::string to_string() const override { return name(); }
  bool bilateral() const override { return true; }
};

// Cornell's coverage: phi_i = 0, phi_o in (-pi, 0): half of one 3D slice.
SampleSet half_slice(const Brdf& b, int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  SampleSet s;
  for (int k = 0; k < n; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 0.0);
    const Vec3 wo = from_spherical(std::acos(U(rng)), -M_PI * U(rng));
    s.push(wi, wo, b.eval(wi, wo));
  }
  s.validate();
  return s;
}

}  // namespace

TEST_CASE("symmetry fit: a half-slice of an isotropic BRDF with its orbit matches the full-domain fit") {
  const RadialMcCool brdf;
  const SampleSet held = sample_stratified(brdf, 4000, 9);
  FitOptions opt;
  auto error_of = [&](const SampleSet& train) {
    const FitData d(train, opt.eps);
    const auto f = fit_homomorphic(d, mccool_terms(12), opt, "mccool");
    return evaluate_metrics(*f, held, LogTransform::of(held, opt.eps)).rel_mse;
  };
  const double full = error_of(sample_stratified(brdf, 6000, 4));
  const SampleSet half = half_slice(brdf, 1500, 5);
  OrbitInfo info;
  const double orbit = error_of(expand_orbit(half, symmetries_of(brdf), {24, 50'000}, &info));
  const double raw = error_of(half);
  INFO("full " << full << ", half-slice with orbit " << orbit << " (" << info.describe() << "), without "
               << raw);
  CHECK(info.rotations == 8);
  // Stated tolerance: within 2x of the full-domain fit's whole-domain error (plus 1e-4 absolute).
  CHECK(orbit <= 2.0 * full + 1e-4);
  // Without the orbit the same samples leave most of the domain to extrapolation.
  CHECK(raw > 3.0 * orbit);
}
