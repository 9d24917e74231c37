// Monte Carlo render of the SH-lit sphere (see mc_render.h).
#include "experiments/report/mc_render.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "factor/lighting.h"

namespace bf {

namespace {

// splitmix64: a small, well-mixed generator; one stream per pixel.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

}  // namespace

double McRender::pixel_variance() const {
  double s = 0;
  size_t n = 0;
  for (size_t k = 0; k < sample_variance.size(); ++k)
    if (image.inside[k]) {
      s += sample_variance[k];
      ++n;
    }
  return n && spp > 0 ? s / static_cast<double>(n) / spp : 0.0;
}

McRender render_sphere_mc(const Brdf& f, const BrdfSampler& sampler, const SceneSettings& scene, int spp,
                          uint64_t seed) {
  if (!scene.lighting)
    throw std::invalid_argument("Monte Carlo render: the scene has no integrable light: set [scene] environment or "
                                "lighting_order (a point light is never hit by a sampled direction)");
  if (spp < 2) throw std::invalid_argument("Monte Carlo render: spp: expected >= 2, found " + std::to_string(spp));
  McRender r;
  r.spp = spp;
  const int n = scene.size;
  r.image.size = n;
  r.image.L.assign(static_cast<size_t>(n) * n, Rgb::Zero());
  r.image.inside.assign(static_cast<size_t>(n) * n, 0);
  r.sample_variance.assign(static_cast<size_t>(n) * n, 0.0);
  const ShLighting& light = *scene.lighting;
  const Vec3 wo_world(0.0, 0.0, 1.0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double px = -1.0 + (x + 0.5) * 2.0 / n, py = 1.0 - (y + 0.5) * 2.0 / n;
      const double rr = px * px + py * py;
      if (rr >= 1.0) continue;
      const size_t k = static_cast<size_t>(y) * n + x;
      r.image.inside[k] = 1;
      // The local frame of render_sphere.
      const Vec3 nrm(px, py, std::sqrt(1.0 - rr));
      Vec3 t = Vec3(1.0, 0.0, 0.0) - nrm.x() * nrm;
      if (t.norm() < 1e-9) t = Vec3(0.0, 1.0, 0.0) - nrm.y() * nrm;
      t.normalize();
      const Vec3 b = nrm.cross(t);
      const Vec3 wo = Vec3(wo_world.dot(t), wo_world.dot(b), wo_world.dot(nrm)).normalized();
      Rng rng{seed * 0x2545f4914f6cdd1dull + k};
      Rgb sum = Rgb::Zero();
      double s1 = 0, s2 = 0;  // mean-over-RGB estimate: sum and sum of squares
      for (int j = 0; j < spp; ++j) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const DirectionSample d = sampler.sample(wo, u1, u2);
        Rgb e = Rgb::Zero();
        if (d.pdf > 0.0 && d.wi.z() > 0.0) {
          Rgb fv = f.eval(d.wi, wo);
          if (!fv.isFinite().all()) {
            ++r.image.nonfinite;
            fv = Rgb::Zero();
          }
          const Vec3 wi_world = d.wi.x() * t + d.wi.y() * b + d.wi.z() * nrm;
          e = fv * light.radiance(wi_world) * (d.wi.z() / d.pdf);
        } else if (!(d.pdf > 0.0)) {
          ++r.no_sample;
        }
        sum += e;
        const double m = e.mean();
        s1 += m;
        s2 += m * m;
      }
      r.image.L[k] = sum / spp;
      const double mean = s1 / spp;
      r.sample_variance[k] = std::max(0.0, (s2 - spp * mean * mean) / (spp - 1));
    }
  return r;
}

}  // namespace bf
