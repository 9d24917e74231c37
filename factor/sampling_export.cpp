// See sampling_export.h.
#include "factor/sampling_export.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "factor/glsl_target.h"

namespace bf {

namespace {
int block_width(const SamplerTable& t) { return std::max(t.theta_bins, t.phi_bins) + 1; }
}  // namespace

FloatImage sampling_texture(const SamplerTable& t) {
  const int T = t.theta_bins, P = t.phi_bins, W1 = block_width(t);
  FloatImage img;
  img.width = W1 * t.view_phi_bins;
  img.height = (T + 1) * t.view_bins;
  img.channel_names = {"R", "G", "B"};
  img.pixels.assign(static_cast<size_t>(img.width) * img.height * 3, 0.0f);
  auto px = [&](int x, int y) -> float& { return img.pixels[(static_cast<size_t>(y) * img.width + x) * 3]; };
  for (int vt = 0; vt < t.view_bins; ++vt)
    for (int vp = 0; vp < t.view_phi_bins; ++vp) {
      const int v = vt * t.view_phi_bins + vp, x0 = vp * W1, y0 = vt * (T + 1);
      for (int r = 0; r <= T; ++r) px(x0 + r, y0) = t.row_cdf[static_cast<size_t>(v) * (T + 1) + r];
      for (int r = 0; r < T; ++r)
        for (int c = 0; c <= P; ++c)
          px(x0 + c, y0 + 1 + r) = t.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1) + c];
    }
  return img;
}

nlohmann::json sampling_entry(const SamplerTable& t, const std::string& file, const std::string& glsl_file) {
  return {{"method", "tabulated"},
          {"file", file},
          {"glsl", glsl_file},
          {"view_bins", t.view_bins},
          {"view_phi_bins", t.view_phi_bins},
          {"theta_bins", t.theta_bins},
          {"phi_bins", t.phi_bins},
          {"cosine_fraction", t.cosine_fraction},
          {"storage_floats", t.row_cdf.size() + t.col_cdf.size()}};
}

SamplerTable sampling_table_from(const FloatImage& img, const nlohmann::json& e, const std::string& what) {
  auto get_int = [&](const char* key, int lo, int hi) {
    if (!e.contains(key) || !e[key].is_number_integer() || e[key].get<long long>() < lo || e[key].get<long long>() > hi)
      throw std::invalid_argument(what + ": sampling." + key + ": expected an integer in [" + std::to_string(lo) +
                                  ", " + std::to_string(hi) + "], found " + (e.contains(key) ? e[key].dump() : "nothing"));
    return e[key].get<int>();
  };
  SamplerTable t;
  t.view_bins = get_int("view_bins", 1, 256);
  t.view_phi_bins = get_int("view_phi_bins", 1, 256);
  t.theta_bins = get_int("theta_bins", 2, 1024);
  t.phi_bins = get_int("phi_bins", 2, 1024);
  // Used as float32 (as the GLSL holds it), which must still be in (0, 1).
  if (!e.contains("cosine_fraction") || !e["cosine_fraction"].is_number() ||
      !(static_cast<float>(e["cosine_fraction"].get<double>()) > 0 &&
        static_cast<float>(e["cosine_fraction"].get<double>()) < 1))
    throw std::invalid_argument(what + ": sampling.cosine_fraction: expected a number in (0, 1) also as float32, found " +
                                (e.contains("cosine_fraction") ? e["cosine_fraction"].dump() : "nothing"));
  t.cosine_fraction = static_cast<float>(e["cosine_fraction"].get<double>());
  const int T = t.theta_bins, P = t.phi_bins, W1 = block_width(t);
  if (img.width != W1 * t.view_phi_bins || img.height != (T + 1) * t.view_bins || img.channels() < 1)
    throw std::invalid_argument(what + ": expected a " + std::to_string(W1 * t.view_phi_bins) + " x " +
                                std::to_string((T + 1) * t.view_bins) + " image for the sizes in the sidecar, found " +
                                std::to_string(img.width) + " x " + std::to_string(img.height));
  // The value channel: R (EXR files list their channels sorted by name), or a single channel.
  const int ch = img.channels();
  int rc_index = ch == 1 ? 0 : -1;
  for (int k = 0; k < ch; ++k)
    if (img.channel_names[k] == "R") rc_index = k;
  if (rc_index < 0) throw std::invalid_argument(what + ": expected a channel R, found none");
  auto px = [&](int x, int y) { return img.pixels[(static_cast<size_t>(y) * img.width + x) * ch + rc_index]; };
  const int V = t.view_bins * t.view_phi_bins;
  t.row_cdf.resize(static_cast<size_t>(V) * (T + 1));
  t.col_cdf.resize(static_cast<size_t>(V) * T * (P + 1));
  t.empty.assign(V, 0);
  auto check_cdf = [&](const float* c, int n, bool allow_zero, int x, int y) {
    bool ok = c[0] == 0.0f && (c[n] == 1.0f || (allow_zero && c[n] == 0.0f));
    for (int k = 0; ok && k < n; ++k) ok = std::isfinite(c[k + 1]) && c[k + 1] >= c[k];
    if (!ok)
      throw std::invalid_argument(what + ": pixel row " + std::to_string(y) + " from x " + std::to_string(x) +
                                  ": expected a CDF (0 first, non-decreasing, 1 last), found other values");
  };
  for (int vt = 0; vt < t.view_bins; ++vt)
    for (int vp = 0; vp < t.view_phi_bins; ++vp) {
      const int v = vt * t.view_phi_bins + vp, x0 = vp * W1, y0 = vt * (T + 1);
      float* rc = &t.row_cdf[static_cast<size_t>(v) * (T + 1)];
      for (int r = 0; r <= T; ++r) rc[r] = px(x0 + r, y0);
      check_cdf(rc, T, true, x0, y0);
      t.empty[v] = rc[T] == 0.0f;
      for (int r = 0; r < T; ++r) {
        float* cc = &t.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1)];
        for (int c = 0; c <= P; ++c) cc[c] = px(x0 + c, y0 + 1 + r);
        check_cdf(cc, P, t.empty[v], x0, y0 + 1 + r);
      }
    }
  return t;
}

namespace {
// The functions of sampling.glsl after its constants (docs/design.md §5.12).
const char* const kSamplingGlslBody = R"(const float BF_S_PI = 3.14159265358979;
float bf_s_at(int x, int y) { return texelFetch(brdf_factor_sampling, ivec2(x, y), 0).r; }
float bf_s_row(int v, int r) { return bf_s_at((v % BF_S_VP) * BF_S_W + r, (v / BF_S_VP) * (BF_S_T + 1)); }
float bf_s_col(int v, int r, int c) { return bf_s_at((v % BF_S_VP) * BF_S_W + c, (v / BF_S_VP) * (BF_S_T + 1) + 1 + r); }
float bf_s_u(float u) { return clamp(u, 0.0, 0.99999994); }
// The unit direction of w.xy, (1, 0) on the pole (scaled first: no underflow).
vec2 bf_s_axis(vec3 w) {
  float m = max(abs(w.x), abs(w.y));
  if (m == 0.0) return vec2(1.0, 0.0);
  vec2 p = w.xy / m;
  return p / length(p);
}
// The wedge k of [2 pi k / n, 2 pi (k + 1) / n) holding the angle of p != 0:
// atan's guess, corrected by the signs of the cross products with its edges.
int bf_s_wedge(vec2 p, int n) {
  float a = atan(p.y, p.x);
  if (a < 0.0) a += 2.0 * BF_S_PI;
  int k = int(a / (2.0 * BF_S_PI) * float(n)) % n;
  for (int it = 0; it < 2; ++it) {
    float e0 = float(k) * 2.0 * BF_S_PI / float(n), e1 = float(k + 1) * 2.0 * BF_S_PI / float(n);
    if (cos(e0) * p.y - sin(e0) * p.x < 0.0) k = (k + n - 1) % n;
    else if (cos(e1) * p.y - sin(e1) * p.x >= 0.0) k = (k + 1) % n;
    else break;
  }
  return k;
}
// The two view tables and the weights of the cosine lobe and of each: linear
// in cos theta_o between the two nearest bin centres, nearest phi_o bin.
void bf_s_mix(vec3 wo, out int va, out int vb, out vec3 w) {
  float z = wo.z;
  int a = 0, b = 0;
  float t = 0.0;
  if (z >= BF_S_VC[0]) {
    a = 0;
    b = 0;
  } else if (z <= BF_S_VC[BF_S_V - 1]) {
    a = BF_S_V - 1;
    b = BF_S_V - 1;
  } else {
    int lo = 0, hi = BF_S_V - 1;
    while (hi - lo > 1) {
      int mid = (lo + hi) / 2;
      if (BF_S_VC[mid] >= z) lo = mid; else hi = mid;
    }
    a = lo;
    b = hi;
    t = (BF_S_VC[a] - z) / (BF_S_VC[a] - BF_S_VC[b]);
  }
  int vp = 0;
  if (BF_S_VP > 1 && (wo.x != 0.0 || wo.y != 0.0)) {
    float h = BF_S_PI / float(BF_S_VP), c = cos(h), s = sin(h);
    vp = bf_s_wedge(vec2(c * wo.x - s * wo.y, s * wo.x + c * wo.y), BF_S_VP);
  }
  va = a * BF_S_VP + vp;
  vb = b * BF_S_VP + vp;
  float rest = 1.0 - BF_S_COS;
  float wa = rest * (1.0 - t), wb = rest * t;
  bool ea = bf_s_row(va, BF_S_T) == 0.0, eb = bf_s_row(vb, BF_S_T) == 0.0;
  w = vec3(BF_S_COS + (ea ? wa : 0.0) + (eb ? wb : 0.0), ea ? 0.0 : wa, eb ? 0.0 : wb);
}
// The table's density in cell (r, c) of view bin v.
float bf_s_cell_pdf(int v, int r, int c) {
  float prob = (bf_s_row(v, r + 1) - bf_s_row(v, r)) * (bf_s_col(v, r, c + 1) - bf_s_col(v, r, c));
  return prob / ((BF_S_RO[r + 1] - BF_S_RO[r]) * 2.0 * BF_S_PI / float(BF_S_P));
}
// 1 - cos theta of a unit direction, precise also near the normal.
float bf_s_omc(vec3 w) { return w.z >= 0.5 ? (w.x * w.x + w.y * w.y) / (1.0 + w.z) : 1.0 - w.z; }
// The cell of wi: BF_S_RO[r] <= 1 - wi.z < BF_S_RO[r + 1], azimuth relative to wo's.
ivec2 bf_s_cell(vec3 wi, vec3 wo) {
  float omc = bf_s_omc(wi);
  int lo = 0, hi = BF_S_T;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (BF_S_RO[mid] <= omc) lo = mid; else hi = mid;
  }
  int c = 0;
  if (wi.x != 0.0 || wi.y != 0.0) {
    vec2 ex = bf_s_axis(wo);
    c = bf_s_wedge(vec2(wi.x * ex.x + wi.y * ex.y, wi.y * ex.x - wi.x * ex.y), BF_S_P);
  }
  return ivec2(lo, c);
}
float bf_s_pdf_mix(int va, int vb, vec3 w, vec3 wi, vec3 wo) {
  if (!(wi.z > 0.0)) return 0.0;
  float p = w.x * wi.z / BF_S_PI;
  if (w.y > 0.0 || w.z > 0.0) {
    ivec2 rc = bf_s_cell(wi, wo);
    if (w.y > 0.0) p += w.y * bf_s_cell_pdf(va, rc.x, rc.y);
    if (w.z > 0.0) p += w.z * bf_s_cell_pdf(vb, rc.x, rc.y);
  }
  return p;
}
float brdf_factor_pdf(vec3 wi, vec3 wo) {
  if (!(wo.z > 0.0)) return 0.0;
  int va, vb;
  vec3 w;
  bf_s_mix(wo, va, vb, w);
  return bf_s_pdf_mix(va, vb, w, wi, wo);
}
vec4 brdf_factor_sample(vec3 wo, vec2 u) {
  if (!(wo.z > 0.0)) return vec4(0.0);
  float u1 = bf_s_u(u.x), u2 = bf_s_u(u.y);
  int va, vb;
  vec3 w;
  bf_s_mix(wo, va, vb, w);
  if (u1 < w.x) {
    float v = bf_s_u(u1 / w.x);
    float rr = sqrt(v), ph = 2.0 * BF_S_PI * u2;
    vec3 wi = vec3(rr * cos(ph), rr * sin(ph), sqrt(max(0.0, 1.0 - v)));
    return vec4(wi, bf_s_pdf_mix(va, vb, w, wi, wo));
  }
  u1 -= w.x;
  int v = va;
  float wv = w.y;
  if (u1 >= w.y && w.z > 0.0) {
    u1 -= w.y;
    v = vb;
    wv = w.z;
  }
  u1 = bf_s_u(u1 / wv);
  int lo = 0, hi = BF_S_T;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (bf_s_row(v, mid) <= u1) lo = mid; else hi = mid;
  }
  int r = lo;
  float r0 = bf_s_row(v, r);
  float v1 = bf_s_u((u1 - r0) / (bf_s_row(v, r + 1) - r0));
  lo = 0;
  hi = BF_S_P;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (bf_s_col(v, r, mid) <= u2) lo = mid; else hi = mid;
  }
  int c = lo;
  float c0 = bf_s_col(v, r, c);
  float v2 = bf_s_u((u2 - c0) / (bf_s_col(v, r, c + 1) - c0));
  float oa = BF_S_RO[r], ob = BF_S_RO[r + 1];
  float omc = oa + (ob - oa) * v1;
  float ct = 1.0 - omc;
  float st = sqrt(max(0.0, omc * (2.0 - omc)));
  float ph = (float(c) + v2) * 2.0 * BF_S_PI / float(BF_S_P);
  float cp = cos(ph), sp = sin(ph);
  vec2 ex = bf_s_axis(wo);
  vec3 wi = vec3(st * (cp * ex.x - sp * ex.y), st * (cp * ex.y + sp * ex.x), ct);
  // The density in the cell wi was drawn from.
  float p = w.x * wi.z / BF_S_PI;
  if (w.y > 0.0) p += w.y * bf_s_cell_pdf(va, r, c);
  if (w.z > 0.0) p += w.z * bf_s_cell_pdf(vb, r, c);
  return vec4(wi, wi.z > 0.0 ? p : 0.0);
}
)";

// "const float NAME[n] = float[n](v0, v1, ...);" (float32 literals).
std::string glsl_const_array(const std::string& name, const std::vector<double>& v) {
  const std::string n = std::to_string(v.size());
  std::string s = "const float " + name + "[" + n + "] = float[" + n + "](";
  for (size_t k = 0; k < v.size(); ++k) {
    if (k) s += (k % 6 == 0) ? ",\n    " : ", ";
    s += glsl_float(v[k], name);
  }
  return s + ");\n";
}
}  // namespace

std::string sampling_glsl(const SamplerTable& t) {
  const std::string T = std::to_string(t.theta_bins), P = std::to_string(t.phi_bins),
                    V = std::to_string(t.view_bins), VP = std::to_string(t.view_phi_bins),
                    W1 = std::to_string(block_width(t));
  const SamplerGeometry g = sampler_geometry(t);
  std::string s = glsl_target_prelude();
  s += "#ifndef BRDF_FACTOR_SAMPLING_BINDING\n#define BRDF_FACTOR_SAMPLING_BINDING 15\n#endif\n";
  s += "// Importance sampling of f cos(theta_i) (docs/design.md, \"Importance sampling\"):\n"
       "// brdf_factor_sample(wo, u) = (wi, pdf per solid angle), brdf_factor_pdf(wi, wo) = that pdf.\n"
       "// Directions are binned by comparing with the cosines below and by signs of cross\n"
       "// products (no acos; atan only as a first guess), as the CPU sampler does.\n"
       "BRDF_FACTOR_BINDING(BRDF_FACTOR_SAMPLING_BINDING) uniform sampler2D brdf_factor_sampling;\n";
  s += "const int BF_S_T = " + T + ";\nconst int BF_S_P = " + P + ";\nconst int BF_S_V = " + V +
       ";\nconst int BF_S_VP = " + VP + ";\nconst int BF_S_W = " + W1 +
       ";\nconst float BF_S_COS = " + glsl_float(t.cosine_fraction, "cosine_fraction") + ";\n";
  s += "// cos of the theta_o bin centres (decreasing); 1 - cos of the theta_i row edges (0 first, 1 last).\n";
  s += glsl_const_array("BF_S_VC", g.view_cos);
  s += glsl_const_array("BF_S_RO", g.row_omc);
  s += kSamplingGlslBody;
  return s;
}

nlohmann::json write_sampling_export(const BrdfSampler& s, const std::string& dir) {
  const SamplerTable* t = sampler_table(s);
  if (!t) throw std::invalid_argument("sampling export: the " + s.method() + " sampler has no table to export");
  const std::filesystem::path d(dir);
  write_exr((d / "sampling.exr").string(), sampling_texture(*t), "brdf-factor importance-sampling table");
  {
    const std::filesystem::path tmp = d / "sampling.glsl.tmp";
    std::ofstream out(tmp);
    out << sampling_glsl(*t);
    out.close();
    if (!out) throw std::runtime_error((d / "sampling.glsl").string() + ": cannot write");
    std::filesystem::rename(tmp, d / "sampling.glsl");
  }
  return sampling_entry(*t, "sampling.exr", "sampling.glsl");
}

}  // namespace bf
