// The per-run picture (like the thesis's Figures 4.1 and 4.4): a sphere lit by
// one point light, rendered with the original BRDF, with the approximation, and
// an error heat map, side by side; and shade_rmse (docs/design.md §4) from the same
// two renders.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "experiments/plan/plan.h"

namespace bf {

// Radiance of a unit sphere at the origin, seen by an orthographic camera on +z
// (every pixel's wo = +z), lit by a point light at scene.light:
//   L = intensity * f(wi, wo) * max(0, n.wi) / |light - p|^2   (per RGB channel)
// in the local frame of each surface point: normal n = p, tangent = the
// world +x projected onto the tangent plane, bitangent = n x tangent.
// Pixel (x, y), row y = 0 at the top, covers [-1, 1]^2; pixels whose centre
// lies outside the unit disk are background (inside = 0, L = 0). A non-finite
// BRDF value is rendered as 0 and counted in `nonfinite`.
struct SphereRender {
  int size = 0;                // pixels per edge
  std::vector<Rgb> L;          // size*size radiances, row-major
  std::vector<uint8_t> inside; // 1 = sphere pixel
  size_t nonfinite = 0;
};
// With SH lighting (scene.lighting: [scene] environment or lighting_order)
// every pixel is instead LitShader::shade (factor/lighting.h): the integral of
// the band-limited lighting x f x cos over a hemisphere rule, the same rule for
// the original and the approximation; `nonfinite` then counts BRDF values.
SphereRender render_sphere(const Brdf& brdf, const SceneSettings& scene);
// Same sphere and camera, radiance(n, wo_world) per pixel (e.g. an SHRM).
SphereRender render_sphere_radiance(const std::function<Rgb(const Vec3& n, const Vec3& wo_world)>& radiance,
                                    int size);

// RMS over the sphere pixels and the three channels of (b - a); 0 when a has
// no sphere pixel. Throws std::invalid_argument for renders of different size.
double shade_rmse(const SphereRender& a, const SphereRender& b);

// Writes original | approximation | error as one 8-bit sRGB PNG (atomically:
// a temporary in the same folder renamed into place). Both renders share one
// exposure: the 99th percentile of the original's brightest channel maps to
// white. Error panel: |L_approx - L_orig| (mean over RGB) times that exposure,
// full scale (yellow-white) at 0.25, through a black-blue-red-yellow ramp.
// Background dark grey; panels separated by 4 mid-grey pixels. Throws std::runtime_error naming the
// path when it cannot be written.
void write_comparison_png(const SphereRender& original, const SphereRender& approx,
                          const std::string& path);

}  // namespace bf
