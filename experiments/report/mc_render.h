// A renderer's check of a BrdfSampler (factor/sampling.h): the SH-lit sphere of
// render.h rendered by Monte Carlo, wi drawn from the sampler, estimator
//   L_o = mean over j of f(wi_j, wo) cos(theta_i) L(wi_j) / pdf(wi_j)
// (per RGB channel, L the scene's band-limited radiance in world directions).
// It converges to render_sphere's SH-lit render (the same integral, there by
// a hemisphere quadrature) for any sampler whose pdf is exact and positive
// where f cos L is nonzero. The point-light scene has no integrable light (a
// sampled direction never hits a point), so its Monte Carlo counterpart is the
// point light band-limited by [scene] lighting_order (the SH-lit scene the
// deterministic render already supports).
#pragma once

#include <cstdint>

#include "brdfs/brdf.h"
#include "experiments/plan/plan.h"
#include "experiments/report/render.h"
#include "factor/lighting.h"
#include "factor/sampling.h"

namespace bf {

struct McRender {
  SphereRender image;          // the per-pixel means
  // Per pixel (row-major like image.L): the variance of ONE sample's estimate,
  // mean over RGB, unbiased (n - 1) estimate from the spp samples; 0 outside.
  std::vector<double> sample_variance;
  int spp = 0;
  size_t no_sample = 0;        // draws the sampler refused (pdf 0): counted as estimate 0
  // Mean over the sphere's pixels of sample_variance / spp: the variance of a
  // pixel of this render.
  double pixel_variance() const;
};

// Importance sampling of the scene's light for multiple importance sampling:
// a table of |Y(L)| (Y the Rec. 709 luminance of the SH radiance, in world
// directions) at the centres of rows x cols cells of equal solid angle (rows
// uniform in z over [-1, 1], cols uniform in the azimuth), plus `uniform`
// of the uniform sphere density so that the pdf is positive everywhere; wi
// uniform in solid angle inside a cell. Exact pdf of what it draws.
class LightSampler {
 public:
  // rows, cols >= 1; 0 < uniform <= 1. Throws std::invalid_argument naming the field.
  explicit LightSampler(const ShLighting& light, int rows = 64, int cols = 128, double uniform = 0.05);
  DirectionSample sample(double u1, double u2) const;  // world direction, pdf per solid angle
  double pdf(const Vec3& w) const;                     // w world, unit
 private:
  int rows_, cols_;
  double uniform_;
  std::vector<double> cell_pdf_;    // per solid angle, for the table part
  std::vector<double> row_cdf_;     // rows + 1
  std::vector<double> col_cdf_;     // rows * (cols + 1)
};

// scene.lighting must be set (SH-lit scene), else std::invalid_argument
// naming `[scene] environment or lighting_order`. spp >= 2. Pixels are
// independent streams of a 64-bit generator seeded by (seed, pixel), so the
// render is deterministic for a seed. Non-finite values of f count as 0 and in
// image.nonfinite.
//
// With `light`: one-sample multiple importance sampling (the balance
// heuristic): each sample draws wi from the BRDF sampler or from the light
// with probability 1/2 each, and the estimate is
//   f cos L / (p_brdf(wi) / 2 + p_light(wi) / 2),
// which stays unbiased where either pdf is positive and removes the variance
// of a light (a sun) the BRDF sampler cannot find.
McRender render_sphere_mc(const Brdf& f, const BrdfSampler& sampler, const SceneSettings& scene, int spp,
                          uint64_t seed, const LightSampler* light = nullptr);

}  // namespace bf
