// Scene-weighted fits (see scene_weights.h).
#include "experiments/report/scene_weights.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "factor/lighting.h"

namespace bf {

namespace {

// Local frame of the sphere point with normal n (render.h: tangent = world +x
// projected onto the tangent plane).
void frame(const Vec3& n, Vec3& t, Vec3& b) {
  t = Vec3(1.0, 0.0, 0.0) - n.x() * n;
  if (t.norm() < 1e-9) t = Vec3(0.0, 1.0, 0.0) - n.y() * n;
  t.normalize();
  b = n.cross(t);
}

Vec3 to_local(const Vec3& w, const Vec3& t, const Vec3& b, const Vec3& n) {
  return Vec3(w.dot(t), w.dot(b), w.dot(n)).normalized();
}

}  // namespace

std::vector<ScenePair> scene_pairs(const Brdf& original, const SceneSettings& scene) {
  std::vector<ScenePair> out;
  std::vector<double> pixel_c;  // C per pair (the pixel's sum of c)
  std::vector<double> pair_c;
  std::vector<double> fval;
  const Vec3 wo_world(0.0, 0.0, 1.0);
  const int n = std::min(scene.size, scene.lighting ? 24 : 64);
  const int nt = 8, np = 16;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double px = -1.0 + (x + 0.5) * 2.0 / n, py = 1.0 - (y + 0.5) * 2.0 / n;
      const double rr = px * px + py * py;
      if (rr >= 1.0) continue;
      const Vec3 nrm(px, py, std::sqrt(1.0 - rr));
      Vec3 t, b;
      frame(nrm, t, b);
      const Vec3 wo = to_local(wo_world, t, b, nrm);
      if (wo.z() <= 0.0) continue;
      const size_t first = out.size();
      double C = 0;
      auto add = [&](const Vec3& wi, double c) {
        if (!(c > 0.0) || wi.z() <= 0.0) return;
        const Rgb f = original.eval(wi, wo);
        const double fm = f.isFinite().all() ? std::max(0.0, f.mean()) : 0.0;
        out.push_back({wi, wo, 0.0});
        pair_c.push_back(c);
        fval.push_back(fm);
        C += c;
      };
      if (!scene.lighting) {
        const Vec3 to_light = scene.light - nrm;
        const double d2 = to_light.squaredNorm();
        const Vec3 wi_world = to_light / std::sqrt(d2);
        const double cos_i = wi_world.dot(nrm);
        if (cos_i > 0.0) add(to_local(wi_world, t, b, nrm), scene.intensity * cos_i / d2);
      } else {
        // Midpoint rule in cos theta and phi over the hemisphere.
        for (int i = 0; i < nt; ++i)
          for (int j = 0; j < np; ++j) {
            const double ct = (i + 0.5) / nt, st = std::sqrt(1.0 - ct * ct), ph = 2.0 * M_PI * (j + 0.5) / np;
            const Vec3 wi(st * std::cos(ph), st * std::sin(ph), ct);
            const Vec3 wi_world = wi.x() * t + wi.y() * b + wi.z() * nrm;
            const double L = std::max(0.0, scene.lighting->radiance(wi_world).mean());
            add(wi, L * ct * 2.0 * M_PI / (nt * np));
          }
      }
      for (size_t k = first; k < out.size(); ++k) pixel_c.push_back(C);
    }
  double fmean = 0;
  for (double f : fval) fmean += f;
  const double e = out.empty() ? 0.0 : 0.01 * fmean / static_cast<double>(out.size());
  for (size_t k = 0; k < out.size(); ++k) out[k].a = pixel_c[k] * pair_c[k] * (fval[k] + e) * (fval[k] + e);
  return out;
}

SampleSet scene_weighted(const SampleSet& s, const std::vector<ScenePair>& pairs, double floor) {
  if (!(floor >= 0.0 && floor <= 1.0))
    throw std::invalid_argument("weight_floor: expected a number in [0, 1], found " + std::to_string(floor));
  std::vector<size_t> idx;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) idx.push_back(k);
  if (idx.empty()) throw std::invalid_argument("scene weights: the sample set has no valid sample");
  const double N = static_cast<double>(idx.size());
  const double h = std::pow(4.0 * M_PI * M_PI / N, 0.25), cut = 3.0 * h;
  // Buckets over (wi.x, wi.y, wo.x, wo.y) in [-1, 1]^4; the chord distance
  // bounds each coordinate's difference, so cells within `reach` hold every
  // sample within the cut.
  const double cell = 1.5 * h;
  const int g = std::max(1, static_cast<int>(std::ceil(2.0 / cell)));
  const int reach = static_cast<int>(std::ceil(cut / cell));
  auto coord = [&](double v) { return std::clamp(static_cast<int>((v + 1.0) / cell), 0, g - 1); };
  std::vector<std::vector<uint32_t>> buckets(static_cast<size_t>(g) * g * g * g);
  auto key = [g](int a, int b, int c, int d) { return ((static_cast<size_t>(a) * g + b) * g + c) * g + d; };
  for (uint32_t q = 0; q < idx.size(); ++q) {
    const size_t k = idx[q];
    buckets[key(coord(s.wi[k].x()), coord(s.wi[k].y()), coord(s.wo[k].x()), coord(s.wo[k].y()))].push_back(q);
  }
  std::vector<double> dens(idx.size(), 0.0);
  std::vector<std::pair<uint32_t, double>> near;
  const double inv2h2 = 1.0 / (2.0 * h * h), cut2 = cut * cut;
  for (const ScenePair& p : pairs) {
    near.clear();
    double Z = 0;
    const int c0 = coord(p.wi.x()), c1 = coord(p.wi.y()), c2 = coord(p.wo.x()), c3 = coord(p.wo.y());
    for (int a = std::max(0, c0 - reach); a <= std::min(g - 1, c0 + reach); ++a)
      for (int b = std::max(0, c1 - reach); b <= std::min(g - 1, c1 + reach); ++b)
        for (int c = std::max(0, c2 - reach); c <= std::min(g - 1, c2 + reach); ++c)
          for (int d = std::max(0, c3 - reach); d <= std::min(g - 1, c3 + reach); ++d)
            for (uint32_t q : buckets[key(a, b, c, d)]) {
              const size_t k = idx[q];
              const double d2 = (s.wi[k] - p.wi).squaredNorm() + (s.wo[k] - p.wo).squaredNorm();
              if (d2 >= cut2) continue;
              const double w = std::exp(-d2 * inv2h2);
              near.emplace_back(q, w);
              Z += w;
            }
    if (Z <= 0.0) continue;
    for (const auto& [q, w] : near) dens[q] += p.a * w / Z;
  }
  double mean = 0;
  for (double v : dens) mean += v;
  mean /= N;
  if (!(mean > 0.0) || !std::isfinite(mean))
    throw std::runtime_error("scene weights: no pixel of the scene reads a (wi, wo) pair near a sample (" +
                             std::to_string(pairs.size()) + " pairs, " + std::to_string(idx.size()) +
                             " samples)");
  SampleSet out = s;
  out.weight.assign(s.size(), 0.0);
  for (size_t k = 0; k < s.size(); ++k) out.weight[k] = s.weight_of(k);
  for (size_t q = 0; q < idx.size(); ++q) out.weight[idx[q]] *= floor + (1.0 - floor) * dens[q] / mean;
  out.description = s.description + ", scene-weighted";
  return out;
}

}  // namespace bf
