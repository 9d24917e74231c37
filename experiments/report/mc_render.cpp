// Monte Carlo render of the SH-lit sphere (see mc_render.h).
#include "experiments/report/mc_render.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "factor/lighting.h"
#include "experiments/common/splitmix.h"

namespace bf {

namespace {

// splitmix64 (experiments/common/splitmix.h); one stream per pixel.
struct Rng {
  uint64_t s;
  uint64_t next() { return splitmix(s); }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

}  // namespace

LightSampler::LightSampler(const ShLighting& light, int rows, int cols, double uniform)
    : rows_(rows), cols_(cols), uniform_(uniform) {
  if (rows < 1 || cols < 1 || rows > 4096 || cols > 4096)
    throw std::invalid_argument("light sampler: rows and cols: expected 1..4096, found " + std::to_string(rows) +
                                " x " + std::to_string(cols));
  if (!(uniform > 0 && uniform <= 1))
    throw std::invalid_argument("light sampler: uniform: expected a number in (0, 1], found " +
                                std::to_string(uniform));
  const size_t n = static_cast<size_t>(rows) * cols;
  std::vector<double> w(n);
  double total = 0;
  for (int r = 0; r < rows; ++r) {
    const double z = -1.0 + (r + 0.5) * 2.0 / rows, sz = std::sqrt(std::max(0.0, 1.0 - z * z));
    for (int c = 0; c < cols; ++c) {
      const double ph = (c + 0.5) * 2.0 * M_PI / cols;
      const Rgb L = light.radiance(Vec3(sz * std::cos(ph), sz * std::sin(ph), z));
      const double y = std::abs(0.2126 * L[0] + 0.7152 * L[1] + 0.0722 * L[2]);
      w[static_cast<size_t>(r) * cols + c] = std::isfinite(y) ? y : 0.0;
      total += w[static_cast<size_t>(r) * cols + c];
    }
  }
  if (!(total > 0)) uniform_ = 1.0;  // a black sky: uniform sampling only
  // Probability of each cell (table and uniform parts mixed), then the CDFs.
  const double cell_area = 4.0 * M_PI / static_cast<double>(n);
  cell_pdf_.resize(n);
  row_cdf_.assign(rows + 1, 0.0);
  col_cdf_.assign(static_cast<size_t>(rows) * (cols + 1), 0.0);
  for (int r = 0; r < rows; ++r) {
    double row = 0;
    for (int c = 0; c < cols; ++c) {
      const size_t k = static_cast<size_t>(r) * cols + c;
      const double p = (1.0 - uniform_) * (total > 0 ? w[k] / total : 0.0) + uniform_ / static_cast<double>(n);
      cell_pdf_[k] = p / cell_area;
      col_cdf_[static_cast<size_t>(r) * (cols + 1) + c + 1] = (row += p);
    }
    for (int c = 1; c <= cols; ++c) col_cdf_[static_cast<size_t>(r) * (cols + 1) + c] /= row;
    row_cdf_[r + 1] = row_cdf_[r] + row;
  }
  for (double& v : row_cdf_) v /= row_cdf_[rows];
}

namespace {
// Index i in [0, n) with cdf[i] <= u < cdf[i + 1], skipping empty steps.
int find_step(const double* cdf, int n, double u) {
  const int i = static_cast<int>(std::upper_bound(cdf, cdf + n + 1, u) - cdf) - 1;
  return std::min(std::max(i, 0), n - 1);
}
}  // namespace

DirectionSample LightSampler::sample(double u1, double u2) const {
  const int r = find_step(row_cdf_.data(), rows_, u1);
  const double v1 = std::min(1.0, std::max(0.0, (u1 - row_cdf_[r]) / (row_cdf_[r + 1] - row_cdf_[r])));
  const double* cc = &col_cdf_[static_cast<size_t>(r) * (cols_ + 1)];
  const int c = find_step(cc, cols_, u2);
  const double v2 = std::min(1.0, std::max(0.0, (u2 - cc[c]) / (cc[c + 1] - cc[c])));
  const double z = std::min(1.0, std::max(-1.0, -1.0 + (r + v1) * 2.0 / rows_));
  const double sz = std::sqrt(std::max(0.0, 1.0 - z * z)), ph = (c + v2) * 2.0 * M_PI / cols_;
  return {Vec3(sz * std::cos(ph), sz * std::sin(ph), z), cell_pdf_[static_cast<size_t>(r) * cols_ + c]};
}

double LightSampler::pdf(const Vec3& w) const {
  const int r = std::min(rows_ - 1, std::max(0, static_cast<int>((w.z() + 1.0) * 0.5 * rows_)));
  double ph = std::atan2(w.y(), w.x());
  if (ph < 0) ph += 2.0 * M_PI;
  const int c = std::min(cols_ - 1, std::max(0, static_cast<int>(ph / (2.0 * M_PI) * cols_)));
  return cell_pdf_[static_cast<size_t>(r) * cols_ + c];
}

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
                          uint64_t seed, const LightSampler* light_sampler) {
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
        DirectionSample d;
        if (!light_sampler) {
          d = sampler.sample(wo, u1, u2);
        } else {
          // One-sample MIS: the choice by a third number, the mixture's pdf.
          const bool from_light = rng.uniform() < 0.5;
          if (from_light) {
            const DirectionSample l = light_sampler->sample(u1, u2);
            d.wi = Vec3(l.wi.dot(t), l.wi.dot(b), l.wi.dot(nrm));
            d.pdf = 0.5 * l.pdf + 0.5 * sampler.pdf(d.wi, wo);
          } else {
            d = sampler.sample(wo, u1, u2);
            if (d.pdf > 0.0) {
              const Vec3 w = d.wi.x() * t + d.wi.y() * b + d.wi.z() * nrm;
              d.pdf = 0.5 * d.pdf + 0.5 * light_sampler->pdf(w);
            }
          }
        }
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
        }  // a light sample below the horizon: estimate 0 (it is part of the mixture)
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
