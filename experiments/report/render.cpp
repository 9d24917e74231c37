// Sphere pictures and shade_rmse (see render.h).
#include "experiments/report/render.h"

#include "brdfs/temp_file.h"
#include "factor/image_io.h"
#include "factor/lighting.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace bf {

SphereRender render_sphere(const Brdf& brdf, const SceneSettings& scene) {
  SphereRender r;
  const int n = scene.size;
  r.size = n;
  r.L.assign(static_cast<size_t>(n) * n, Rgb::Zero());
  r.inside.assign(static_cast<size_t>(n) * n, 0);
  const Vec3 wo_world(0.0, 0.0, 1.0);
  // SH-lit scene: the same hemisphere quadrature for every BRDF (factor/lighting.h).
  std::optional<LitShader> shader;
  if (scene.lighting) shader.emplace(scene.lighting, scene.lighting_nodes);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double px = -1.0 + (x + 0.5) * 2.0 / n;
      const double py = 1.0 - (y + 0.5) * 2.0 / n;
      const double rr = px * px + py * py;
      if (rr >= 1.0) continue;
      const size_t k = static_cast<size_t>(y) * n + x;
      r.inside[k] = 1;
      const Vec3 nrm(px, py, std::sqrt(1.0 - rr));
      Vec3 t = Vec3(1.0, 0.0, 0.0) - nrm.x() * nrm;
      if (t.norm() < 1e-9) t = Vec3(0.0, 1.0, 0.0) - nrm.y() * nrm;
      t.normalize();
      const Vec3 b = nrm.cross(t);
      if (shader) {
        r.L[k] = shader->shade(brdf, nrm, t, b, wo_world, &r.nonfinite);
        continue;
      }
      const Vec3 to_light = scene.light - nrm;
      const double d2 = to_light.squaredNorm();
      const Vec3 wi_world = to_light / std::sqrt(d2);
      const double cos_i = wi_world.dot(nrm);
      if (cos_i <= 0.0) continue;
      const Vec3 wi(wi_world.dot(t), wi_world.dot(b), wi_world.dot(nrm));
      const Vec3 wo(wo_world.dot(t), wo_world.dot(b), wo_world.dot(nrm));
      if (wo.z() <= 0.0) continue;
      Rgb f = brdf.eval(wi.normalized(), wo.normalized());
      if (!f.isFinite().all()) {
        ++r.nonfinite;
        f = Rgb::Zero();
      }
      r.L[k] = scene.intensity * f * cos_i / d2;
    }
  return r;
}

SphereRender render_sphere_radiance(const std::function<Rgb(const Vec3& n, const Vec3& wo_world)>& radiance,
                                    int size) {
  SphereRender r;
  r.size = size;
  r.L.assign(static_cast<size_t>(size) * size, Rgb::Zero());
  r.inside.assign(static_cast<size_t>(size) * size, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double px = -1.0 + (x + 0.5) * 2.0 / size, py = 1.0 - (y + 0.5) * 2.0 / size;
      const double rr = px * px + py * py;
      if (rr >= 1.0) continue;
      const size_t k = static_cast<size_t>(y) * size + x;
      r.inside[k] = 1;
      Rgb v = radiance(Vec3(px, py, std::sqrt(1.0 - rr)), Vec3(0.0, 0.0, 1.0));
      if (!v.isFinite().all()) {
        ++r.nonfinite;
        v = Rgb::Zero();
      }
      r.L[k] = v;
    }
  return r;
}

double shade_rmse(const SphereRender& a, const SphereRender& b) {
  if (a.size != b.size) throw std::invalid_argument("shade_rmse: renders of different size");
  double s = 0;
  size_t count = 0;
  for (size_t k = 0; k < a.L.size(); ++k) {
    if (!a.inside[k]) continue;
    s += (b.L[k] - a.L[k]).square().sum();
    count += 3;
  }
  return count ? std::sqrt(s / count) : 0.0;
}

namespace {

double srgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

uint8_t byte(double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

// black -> blue -> red -> yellow -> white, t in [0, 1].
Rgb heat(double t) {
  static const Rgb stops[] = {Rgb(0, 0, 0), Rgb(0.1, 0.15, 0.85), Rgb(0.9, 0.1, 0.2), Rgb(1.0, 0.85, 0.1),
                              Rgb(1, 1, 1)};
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(t));
  const double u = t - i;
  return stops[i] * (1 - u) + stops[i + 1] * u;
}

}  // namespace

void write_comparison_png(const SphereRender& original, const SphereRender& approx, const std::string& path) {
  if (original.size != approx.size) throw std::invalid_argument(path + ": renders of different size");
  const int n = original.size, gap = 4, W = 3 * n + 2 * gap;
  // Exposure: the 99th percentile of the original's brightest channel.
  std::vector<double> peaks;
  for (size_t k = 0; k < original.L.size(); ++k)
    if (original.inside[k]) peaks.push_back(original.L[k].maxCoeff());
  double white = 1.0;
  if (!peaks.empty()) {
    const size_t q = std::min(peaks.size() - 1, static_cast<size_t>(0.99 * peaks.size()));
    std::nth_element(peaks.begin(), peaks.begin() + q, peaks.end());
    if (peaks[q] > 0 && std::isfinite(peaks[q])) white = peaks[q];
  }
  const double expo = 1.0 / white;
  std::vector<uint8_t> px(static_cast<size_t>(W) * n * 3, 96);
  auto put = [&](int x, int y, const Rgb& c) {
    const size_t o = (static_cast<size_t>(y) * W + x) * 3;
    for (int ch = 0; ch < 3; ++ch) px[o + ch] = byte(c[ch]);
  };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const size_t k = static_cast<size_t>(y) * n + x;
      const Rgb bg(0.16, 0.16, 0.16);
      if (!original.inside[k]) {
        put(x, y, bg);
        put(n + gap + x, y, bg);
        put(2 * (n + gap) + x, y, bg);
        continue;
      }
      Rgb a, b;
      for (int ch = 0; ch < 3; ++ch) {
        a[ch] = srgb(original.L[k][ch] * expo);
        b[ch] = srgb(approx.L[k][ch] * expo);
      }
      put(x, y, a);
      put(n + gap + x, y, b);
      const double e = (approx.L[k] - original.L[k]).abs().mean() * expo;
      put(2 * (n + gap) + x, y, heat(std::isfinite(e) ? e / 0.25 : 1.0));
    }
  namespace fs = std::filesystem;
  const fs::path final_path(path);
  const fs::path tmp = create_unique_temp(path);
  try {
    bf::write_png_rgb8(tmp.string(), W, n, px);
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write PNG: " + e.what());
  }
  std::error_code ec;
  fs::rename(tmp, final_path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename temporary file: " + ec.message());
  }
}

}  // namespace bf
