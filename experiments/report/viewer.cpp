// report.html's WebGL2 viewer: data files and page section (see viewer.h).
#include "experiments/report/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "experiments/common/cli_util.h"
#include "experiments/report/escape.h"
#include "experiments/report/viewer_js.h"
#include "factor/image_io.h"
#include "factor/lighting.h"
#include "factor/svd_baseline.h"  // DiskGrid: the original's wiwo tabulation

namespace bf {

namespace {

std::string base64(const std::vector<float>& v) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = reinterpret_cast<const unsigned char*>(v.data());
  const size_t n = v.size() * sizeof(float);
  std::string o;
  o.reserve((n + 2) / 3 * 4);
  for (size_t i = 0; i < n; i += 3) {
    const unsigned x = (unsigned(b[i]) << 16) | (i + 1 < n ? unsigned(b[i + 1]) << 8 : 0u) |
                       (i + 2 < n ? unsigned(b[i + 2]) : 0u);
    o += t[(x >> 18) & 63];
    o += t[(x >> 12) & 63];
    o += i + 1 < n ? t[(x >> 6) & 63] : '=';
    o += i + 2 < n ? t[x & 63] : '=';
  }
  return o;
}

nlohmann::json texture_json(const std::string& sampler, const FloatImage& img) {
  return {{"sampler", sampler}, {"width", img.width}, {"height", img.height}, {"data", base64(img.pixels)}};
}

}  // namespace

void write_viewer_data(const Factorization& approx, const Brdf& original, const SphereRender& original_render,
                       const SceneSettings& scene, const std::string& run_id, const std::string& label,
                       const std::string& path) {
  nlohmann::json j;
  j["label"] = label;
  j["method"] = approx.method();
  // The result's own GLSL and textures (Factorization::viewer_data).
  const std::optional<ShaderView> view = approx.viewer_data();
  if (!view)
    throw std::invalid_argument("viewer: method " + approx.method() +
                                ": its kind declares a viewer (MethodKind::has_viewer) but its result has no "
                                "viewer data (Factorization::viewer_data)");
  j["glsl"] = view->glsl;
  nlohmann::json tex = nlohmann::json::array();
  for (const auto& [sampler, img] : view->textures) tex.push_back(texture_json(sampler, img));
  j["textures"] = tex;

  if (original.isotropic()) {
    // Isotropic: (theta_h, theta_d, phi_d) nodes, theta_h spaced as MERL's bins
    // (dense near the highlight), phi_d over [0, pi] (reciprocity folds the rest).
    const int NH = kViewerIsoThetaH, ND = kViewerIsoThetaD, NP = kViewerIsoPhiD;
    std::vector<float> table(size_t(NH) * ND * NP * 3, 0.0f);
    for (int i = 0; i < NH; ++i)
      for (int jd = 0; jd < ND; ++jd)
        for (int k = 0; k < NP; ++k) {
          const double u = double(i) / (NH - 1), th = u * u * M_PI / 2, td = double(jd) / (ND - 1) * M_PI / 2,
                       pd = double(k) / (NP - 1) * M_PI;
          const Vec3 h(std::sin(th), 0.0, std::cos(th));
          const Vec3 d(std::sin(td) * std::cos(pd), std::sin(td) * std::sin(pd), std::cos(td));
          const Vec3 wi(std::cos(th) * d.x() + std::sin(th) * d.z(), d.y(), -std::sin(th) * d.x() + std::cos(th) * d.z());
          const Vec3 wo = 2.0 * wi.dot(h) * h - wi;
          // Nodes below the horizon hold the BRDF at the directions lifted to
          // elevation 0.01 (a continuous extension), so that trilinear lookups
          // near grazing angles are not pulled towards 0.
          const auto lift = [](Vec3 w) {
            const double zmin = 0.01;
            if (w.z() >= zmin) return Vec3(w.normalized());
            const double t = std::hypot(w.x(), w.y()), sxy = std::sqrt(1.0 - zmin * zmin);
            return t < 1e-300 ? Vec3(sxy, 0.0, zmin) : Vec3(w.x() * sxy / t, w.y() * sxy / t, zmin);
          };
          Rgb f = original.eval(lift(wi), lift(wo));
          if (!f.isFinite().all()) f = Rgb::Zero();
          for (int c = 0; c < 3; ++c)
            table[((size_t(i) * ND + jd) * NP + k) * 3 + c] = float(std::max(0.0, f[c]));
        }
    j["original"] = {{"kind", "iso"}, {"nh", NH}, {"nd", ND}, {"np", NP}, {"data", base64(table)}};
  } else {
    // Anisotropic: the wiwo parabolic grid (all R*R texels of each half, pulled
    // in to radius 1 - 1/(R-1) like the SVD table).
    const int R = kViewerTableRes;
    const DiskGrid grid = DiskGrid::make(R);
    const double inset = 1.0 / (R - 1);
    const int RR = R * R;
    std::vector<Vec3> dir(RR);
    for (int t = 0; t < RR; ++t) dir[t] = grid.direction(t, inset);
    std::vector<float> table(size_t(RR) * RR * 3, 0.0f);
    for (int a = 0; a < RR; ++a)      // wi texel: row
      for (int b = 0; b < RR; ++b) {  // wo texel: column
        Rgb f = original.eval(dir[a], dir[b]);
        if (!f.isFinite().all()) f = Rgb::Zero();
        for (int c = 0; c < 3; ++c) table[(size_t(a) * RR + b) * 3 + c] = float(std::max(0.0, f[c]));
      }
    j["original"] = {{"kind", "wiwo"}, {"res", R}, {"data", base64(table)}};
  }

  std::vector<double> peaks;
  for (size_t k = 0; k < original_render.L.size(); ++k)
    if (original_render.inside[k]) peaks.push_back(original_render.L[k].maxCoeff());
  double white = 1.0;
  if (!peaks.empty()) {
    const size_t q = std::min(peaks.size() - 1, static_cast<size_t>(0.99 * peaks.size()));
    std::nth_element(peaks.begin(), peaks.begin() + q, peaks.end());
    if (peaks[q] > 0 && std::isfinite(peaks[q])) white = peaks[q];
  }
  j["exposure"] = 1.0 / white;
  // SH-lit scene (factor/lighting.h): the band-limited radiance on a lat-long
  // grid and LitShader's hemisphere rule (local frame), so the page shades as
  // render_sphere does: sum over nodes of w s.z L(M s) f(s, wo).
  if (scene.lighting) {
    const int W = kViewerEnvWidth, H = W / 2;
    std::vector<float> env(size_t(W) * H * 3);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double th = M_PI * (y + 0.5) / H, ph = 2.0 * M_PI * (x + 0.5) / W;
        const Rgb L = scene.lighting->radiance(Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
        for (int c = 0; c < 3; ++c) env[(size_t(y) * W + x) * 3 + c] = float(std::isfinite(L[c]) ? L[c] : 0.0);
      }
    const LitShader shader(scene.lighting, scene.lighting_nodes);
    const SphereRule& rule = shader.rule();
    std::vector<float> nodes;
    for (size_t k = 0; k < rule.size(); ++k) {
      for (int c = 0; c < 3; ++c) nodes.push_back(float(rule.dir[k][c]));
      nodes.push_back(float(rule.w[k]));
    }
    j["environment"] = {{"width", W}, {"height", H}, {"data", base64(env)}, {"nodes", rule.size()},
                        {"rule", base64(nodes)}};
  }
  j["scene"] = {{"light", {scene.light.x(), scene.light.y(), scene.light.z()}},
                {"intensity", scene.intensity},
                {"size", scene.size}};
  const std::string text = "(window.BF_VIEWER = window.BF_VIEWER || {})[" + script_json(run_id) +
                           "] = " + script_json(j) + ";\n";
  write_file_atomic(path, [&](std::ostream& o) { o << text; });
}

std::string viewer_section(const std::vector<ViewerRun>& runs) {
  std::ostringstream h;
  h << "<h2 id=\"viewer-h\">Viewer</h2>\n<div id=\"viewer\">\n"
    << "<p class=\"note\">WebGL2, offline. Left to right: the original BRDF (a tabulation read by the page: "
    << "isotropic BRDFs on a " << kViewerIsoThetaH << " &times; " << kViewerIsoThetaD << " &times; "
    << kViewerIsoPhiD << " (&theta;<sub>h</sub>, &theta;<sub>d</sub>, &phi;<sub>d</sub>) grid, others on the "
    << kViewerTableRes << "<sup>4</sup> wiwo parabolic grid), the approximation (the run's exported GLSL, "
    << "the same formula as <code>factors.glsl</code> or <code>model.glsl</code>), and |difference|. Drag on a "
    << "sphere to move the point light (under the scene's environment: to turn the environment with it); "
    << "shift-drag to move the view. Exposure as sphere.png (99th percentile of the original = white).</p>\n"
    << "<p><label>Run <select id=\"v-run\"></select></label> "
    << "<label>exposure <input id=\"v-exposure\" type=\"range\" min=\"-6\" max=\"6\" step=\"0.5\" value=\"0\"></label> "
    << "<label>incidence &theta;<sub>i</sub> (lobes, Cartesian slices) <input id=\"v-theta\" type=\"range\" "
       "min=\"0\" max=\"89\" value=\"30\"> <span id=\"v-theta-val\">30</span>&deg;</label> <button id=\"v-reset\">reset light and view</button> <label><input id=\"v-env\" type=\"checkbox\" "
       "checked> light by the environment (a loaded map, else the scene's SH lighting when it has one)</label> "
       "<label>environment map (Radiance .hdr, lat-long) <input id=\"v-hdr\" type=\"file\" accept=\".hdr,.pic\"></label> <label>shape <select id=\"v-shape\"><option value=\"sphere\">sphere</option>"
       "<option value=\"torus\">torus (varying curvature)</option></select></label> <span id=\"v-status\">"
       "loading&hellip;</span></p>\n"
    << "<p id=\"v-info\"></p>\n"
    << "<div class=\"vrow\"><figure><canvas id=\"v-orig\"></canvas><figcaption>original</figcaption></figure>"
    << "<figure><canvas id=\"v-approx\"></canvas><figcaption>approximation</figcaption></figure>"
    << "<figure><canvas id=\"v-diff\"></canvas><figcaption>|difference|</figcaption></figure></div>\n"
    << "<div class=\"vrow\"><canvas id=\"v-bar-rad\"></canvas> <canvas id=\"v-bar-diff\"></canvas></div>\n"
    << "<h3>Slices</h3><p><label>&phi;<sub>d</sub> <input id=\"v-phid\" type=\"range\" min=\"0\" max=\"180\" "
       "value=\"90\"> <span id=\"v-phid-val\">90</span>&deg;</label> <label>channel <select id=\"v-channel\">"
       "<option value=\"mean\">mean RGB</option><option value=\"0\">R</option><option value=\"1\">G</option>"
       "<option value=\"2\">B</option></select></label> <label><input id=\"v-log\" type=\"checkbox\" checked> "
       "log scale</label></p>\n"
    << "<div class=\"vrow\"><figure><canvas id=\"v-slice-orig\"></canvas><figcaption>original: "
       "&theta;<sub>h</sub> &rarr; (0..90&deg;), &theta;<sub>d</sub> &uarr; (0..90&deg;), &phi;<sub>d</sub> as set"
       "</figcaption></figure><figure><canvas id=\"v-slice-approx\"></canvas><figcaption>approximation"
       "</figcaption></figure><figure><canvas id=\"v-lobe\" width=\"420\" height=\"240\"></canvas><figcaption>"
       "in-plane lobes: original solid blue, approximation dashed red</figcaption></figure></div>\n"
    << "<div class=\"vrow\"><canvas id=\"v-bar-slice\"></canvas></div>\n"
    << "<div class=\"vrow\"><figure><canvas id=\"v-cart-in\" class=\"vplot\" width=\"420\" height=\"260\"></canvas>"
       "<figcaption>f in the incidence plane at &theta;<sub>i</sub> (channel and scale as set)</figcaption></figure>"
       "<figure><canvas id=\"v-cart-out\" class=\"vplot\" width=\"420\" height=\"260\"></canvas><figcaption>f "
       "normal to the incidence plane at &theta;<sub>i</sub></figcaption></figure>"
       "<figure><canvas id=\"v-albedo\" class=\"vplot\" width=\"420\" height=\"260\"></canvas><figcaption>directional "
       "albedo &int; f cos&theta;<sub>i</sub> d&omega;<sub>i</sub> against &theta;<sub>o</sub> (Gauss-Legendre 64 "
       "&times; 128 hemisphere rule)<br><span id=\"v-albedo-note\"></span></figcaption></figure></div>\n"
    << "<h3>Compare</h3><p class=\"note\">Tick two or more: runs' approximations, or a BRDF (the original of "
       "a run, tabulated as above). They are drawn under one point light (the shown run's: drag its spheres) and "
       "one exposure (the shown run's, with the slider); their slices and albedo curves are overlaid (channel, "
       "scale and &theta;<sub>i</sub> as set); the difference image is A &minus; B per channel, shown as mean "
       "|A &minus; B|.</p>\n<div id=\"v-cmp-list\" class=\"vlist\"></div>\n<div id=\"v-cmp-out\" hidden>"
       "<div class=\"vrow\" id=\"v-cmp-spheres\"></div>\n<p><label>difference <select id=\"v-cmp-a\"></select></label> "
       "<label>&minus; <select id=\"v-cmp-b\"></select></label></p>\n<div class=\"vrow\"><figure><canvas id=\"v-cmp-diff\" "
       "class=\"vcmp\"></canvas><br><canvas id=\"v-cmp-bar\"></canvas></figure>"
       "<figure><canvas id=\"v-cmp-in\" class=\"vplot\" width=\"420\" height=\"300\"></canvas><figcaption>f in the "
       "incidence plane</figcaption></figure><figure><canvas id=\"v-cmp-out-plane\" class=\"vplot\" width=\"420\" "
       "height=\"300\"></canvas><figcaption>f normal to the incidence plane</figcaption></figure><figure><canvas "
       "id=\"v-cmp-albedo\" class=\"vplot\" width=\"420\" height=\"300\"></canvas><figcaption>directional albedo"
       "</figcaption></figure></div></div>\n"
    << "<h3>Factor textures</h3><div class=\"vrow\" id=\"v-textures\"></div>\n"
    << "<pre id=\"viewer-test\" hidden></pre>\n"
    << "<script type=\"x-shader/x-fragment\" id=\"v-shader-main\">" << kViewerShaderMain << "</script>\n";
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : runs) {
    list.push_back({{"id", r.id}, {"path", url_path(r.path)}, {"label", r.label}});
  }
  // Inside a <script> element: no "</script", "<!--" or "<script" (escape.h).
  const std::string text = script_json(list);
  // Test mode writes every viewer.js in while the page is parsed (so the
  // numbers exist when the page has loaded), "?viewer[=ID]" the run it opens
  // (and the first, its fallback: drawn before a headless screenshot is
  // taken); otherwise each is loaded when its run is shown. (The attribute is
  // spelled in pieces: this is page text.)
  h << "<script>window.BF_VIEWER_FILES = " << text << ";\n"
    << "{const q = new URLSearchParams(location.search);\n"
       "for (const [i, f] of window.BF_VIEWER_FILES.entries()) if (location.hash === \"#viewer-test\" || "
       "(q.has(\"viewer\") && (i === 0 || f.id === q.get(\"viewer\")))) "
       "document.write(\"<scr\" + \"ipt s\" + \"rc='\" + f.path + \"'></scr\" + \"ipt>\");}</script>\n";
  h << "<script>" << kViewerScript << "</script>\n</div>\n";
  return h.str();
}

}  // namespace bf
