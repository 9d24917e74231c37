// report.html's interactive viewer (WebGL2, offline): per run a data file
// runs/<id>/viewer.js beside the page, read with a plain <script src> (works
// from file://, no network, no CDN), and the page section with its script.
//
// viewer.js sets window.BF_VIEWER[run_id] = {
//   label, method,
//   glsl:      the run's exported GLSL (the same text as factors.glsl; for
//              model-fit the formula of model.glsl, no textures),
//   textures:  [{sampler, width, height, data}] float32 RGB, base64, in
//              binding order (the export's EXR contents),
//   original:  the original BRDF tabulated, float32 RGB base64:
//              {kind: "iso", nh, nd, np, data} (isotropic BRDFs, see
//              kViewerIsoThetaH) or {kind: "wiwo", res: R, data}: R^2 x R^2
//              texels, pixel (x, y) = (texel of p(wo), texel of p(wi)), texel
//              index j*R + i at p = (-1 + 2i/(R-1), -1 + 2j/(R-1)) pulled in
//              to radius 1 - 1/(R-1) (docs/design.md §3.6),
//   scene:     {light: [x, y, z], intensity, size}, exposure: 1 / the 99th
//              percentile of the original render's brightest channel
//              (sphere.png's exposure) }.
#pragma once

#include <string>
#include <vector>

#include "experiments/plan/plan.h"
#include "experiments/report/render.h"
#include "factor/factorization.h"

namespace bf {

// The original BRDF's tabulation in viewer.js: isotropic BRDFs on a
// (theta_h, theta_d, phi_d) grid of 64 x 32 x 32 nodes (theta_h = (i/63)^2
// pi/2 as MERL's bins, theta_d = j/31 pi/2, phi_d = k/31 pi; pixel
// (k + 32 j, i)), read trilinearly; others on the wiwo parabolic grid of
// resolution R = 16 (R^2 x R^2 texels), read bilinearly in both halves. Both
// about 0.8 MB of float32 (1 MB of base64) per run.
inline constexpr int kViewerTableRes = 16;
inline constexpr int kViewerIsoThetaH = 64, kViewerIsoThetaD = 32, kViewerIsoPhiD = 32;
// SH-lit scenes: the band-limited lighting on a W x W/2 lat-long grid.
inline constexpr int kViewerEnvWidth = 128;

// Writes viewer.js (atomically) from approx.viewer_data() (factor/factorization.h);
// throws std::invalid_argument naming the method when it has none.
// original_render: the CPU render of the original (its exposure is reused).
void write_viewer_data(const Factorization& approx, const Brdf& original, const SphereRender& original_render,
                       const SceneSettings& scene, const std::string& run_id, const std::string& label,
                       const std::string& path);

// The viewer section of report.html: canvas, controls and the inline script.
// Each run's viewer.js (path relative to the page) is loaded when the run is
// shown; with "#viewer-test" all are read while the page loads.
struct ViewerRun {
  std::string id, path, label;
};
std::string viewer_section(const std::vector<ViewerRun>& runs);

}  // namespace bf
