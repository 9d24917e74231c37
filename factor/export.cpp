// Factor export: EXR textures, PNG previews, JSON sidecar, GLSL; and the loader
// that reads them back (see export.h).
#include "factor/export.h"

#include "brdfs/temp_file.h"

#include "brdfs/file_check.h"
#include "brdfs/safe_path.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "brdfs/catalogue.h"
#include "factor/atomic_batch.h"
#include "factor/baseline_export.h"
#include "factor/glsl.h"
#include "factor/image_io.h"
#include "factor/model_fit.h"
#include "factor/model_glsl.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* const kChannel[3] = {"R", "G", "B"};

// ---------------------------------------------------------------- writing

void write_text(const fs::path& tmp, const fs::path& final_path, const std::string& text) {
  std::ofstream out(tmp, std::ios::binary);
  if (!out) throw std::runtime_error(final_path.string() + ": cannot open for writing");
  out << text;
  out.close();
  if (!out) throw std::runtime_error(final_path.string() + ": write failed");
}

// Interleaved RGB float32 texels of a term, zero outside the mask.
std::vector<float> interleaved_texels(const FactorTerm& t) {
  const int R = t.proj.res;
  std::vector<float> px(size_t(R) * R * 3, 0.0f);
  for (size_t k = 0; k < size_t(R) * R; ++k) {
    if (!t.mask[k]) continue;
    for (int c = 0; c < 3; ++c) px[3 * k + c] = t.texels[c][k];
  }
  return px;
}

// 8-bit preview (see export.h), size (R*block)^2: the heat colour map of
// log10 of the factor value (mean over channels of exp(texel)) over the fixed
// range [kPreviewLog10Min, kPreviewLog10Max], the same for every term.
std::array<uint8_t, 3> preview_heat(double t) {
  static const double stops[5][3] = {{0, 0, 0}, {0.1, 0.15, 0.85}, {0.9, 0.1, 0.2}, {1, 0.85, 0.1}, {1, 1, 1}};
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int i = std::min(3, int(t));
  const double u = t - i;
  std::array<uint8_t, 3> c{};
  for (int ch = 0; ch < 3; ++ch)
    c[ch] = uint8_t(std::lround(255.0 * (stops[i][ch] * (1.0 - u) + stops[i + 1][ch] * u)));
  return c;
}

std::vector<uint8_t> preview_pixels(const FactorTerm& t, int& size) {
  const int R = t.proj.res;
  const int block = std::max(1, 256 / R);
  size = R * block;
  // One colour per texel, then replicated into its block.
  std::vector<std::array<uint8_t, 3>> colour(size_t(R) * R, {128, 128, 128});
  for (size_t k = 0; k < size_t(R) * R; ++k)
    if (t.mask[k]) {
      double v = 0.0;
      for (int c = 0; c < 3; ++c) v += std::exp(double(t.texels[c][k])) / 3.0;
      const double l = v > 0.0 ? std::log10(v) : kPreviewLog10Min;
      colour[k] = preview_heat((l - kPreviewLog10Min) / (kPreviewLog10Max - kPreviewLog10Min));
    }
  std::vector<uint8_t> px(size_t(size) * size * 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const auto& col = colour[size_t(y / block) * R + x / block];
      std::copy(col.begin(), col.end(), &px[(size_t(y) * size + x) * 3]);
    }
  return px;
}

void check_finite(const HomomorphicFactorization& f) {
  const auto& terms = f.terms();
  for (size_t k = 0; k < terms.size(); ++k) {
    const FactorTerm& t = terms[k];
    const std::string term = "export: term " + std::to_string(k);
    if (!t.proj.P.allFinite()) throw std::invalid_argument(term + ": matrix has non-finite entries");
    if ((t.proj.P.rowwise().lpNorm<1>().array() == 0.0).any())
      throw std::invalid_argument(term + ": matrix has a zero row");
    if (t.mask.size() != size_t(t.proj.res) * t.proj.res)
      throw std::invalid_argument(term + ": mask has " + std::to_string(t.mask.size()) +
                                  " entries, expected " +
                                  std::to_string(size_t(t.proj.res) * t.proj.res));
    for (int c = 0; c < 3; ++c)
      for (size_t i = 0; i < t.texels[c].size(); ++i)
        if (t.mask[i] && !std::isfinite(t.texels[c][i]))
          throw std::invalid_argument(term + ": texel (" + std::to_string(i % t.proj.res) + ", " +
                                      std::to_string(i / t.proj.res) + ") channel " +
                                      kChannel[c] + " is " + std::to_string(t.texels[c][i]) +
                                      ": refusing to export a non-finite texel");
  }
  if (!std::isfinite(f.eps())) throw std::invalid_argument("export: eps is not finite");
}

json mat_json(const Eigen::Matrix<double, 2, 4>& M) {
  return {{M(0, 0), M(0, 1), M(0, 2), M(0, 3)}, {M(1, 0), M(1, 1), M(1, 2), M(1, 3)}};
}

Eigen::Matrix<double, 2, 4> texel_matrix(const Projection& p) {
  const Eigen::Vector2d k = p.row_scale() * (0.5 * (p.res - 1));
  return k.asDiagonal() * p.P;
}

// ---------------------------------------------------------------- reading

// Field access with messages "FILE: field 'a.b[2]': expected X, found Y".
class Sidecar {
 public:
  explicit Sidecar(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail_text(const std::string& field, const std::string& expected,
                              const std::string& found) const {
    throw std::invalid_argument(file_ + ": field '" + field + "': expected " + expected +
                                ", found " + found);
  }
  [[noreturn]] void fail(const std::string& field, const std::string& expected,
                         const json& found) const {
    fail_text(field, expected, describe(found));
  }

  // Member `key` of object `obj` (named `where`, "" at the top level).
  const json& member(const json& obj, const std::string& where, const std::string& key,
                     const std::string& expected) const {
    const std::string field = where.empty() ? key : where + "." + key;
    auto it = obj.find(key);
    if (it == obj.end()) fail_text(field, expected, "nothing (field missing)");
    return *it;
  }
  static std::string field(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }

  std::string string(const json& obj, const std::string& where, const std::string& key) const {
    const json& v = member(obj, where, key, "a string");
    if (!v.is_string()) fail(field(where, key), "a string", v);
    return v.get<std::string>();
  }
  bool boolean(const json& obj, const std::string& where, const std::string& key) const {
    const json& v = member(obj, where, key, "true or false");
    if (!v.is_boolean()) fail(field(where, key), "true or false", v);
    return v.get<bool>();
  }
  long long integer(const json& obj, const std::string& where, const std::string& key, long long lo,
                    long long hi) const {
    const std::string expected =
        "an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
    const json& v = member(obj, where, key, expected);
    if (!v.is_number_integer()) fail(field(where, key), expected, v);
    if (v.is_number_unsigned() && v.get<unsigned long long>() > static_cast<unsigned long long>(hi))
      fail(field(where, key), expected, v);
    const long long x = v.get<long long>();
    if (x < lo || x > hi) fail(field(where, key), expected, v);
    return x;
  }
  double number(const json& v, const std::string& field_name, const std::string& expected) const {
    if (!v.is_number()) fail(field_name, expected, v);
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(field_name, expected, v);
    return x;
  }
  // Array of exactly n elements.
  const json& array(const json& v, const std::string& field_name, size_t n,
                    const std::string& what) const {
    const std::string expected = "an array of " + std::to_string(n) + " " + what;
    if (!v.is_array()) fail(field_name, expected, v);
    if (v.size() != n)
      fail_text(field_name, expected, "an array of " + std::to_string(v.size()) + " elements");
    return v;
  }

  const std::string& file() const { return file_; }

 private:
  static std::string describe(const json& v) {
    if (v.is_null()) return "null";
    // Containers by size only: dump() recurses once per nesting level, and a
    // 20,000-deep array overflowed the stack under ASan (json_deep.json).
    if (v.is_array() || v.is_object())
      return std::string(v.type_name()) + " of " + std::to_string(v.size()) +
             (v.is_array() ? " element" : " member") + (v.size() == 1 ? "" : "s");
    std::string text = v.dump();
    if (text.size() > 60) text = text.substr(0, 57) + "...";
    return std::string(v.is_number() ? "number" : v.type_name()) + " " + text;
  }
  std::string file_;
};

// Reads a term's EXR into t.texels (planar), checking size, channels and values.
void read_texture(const std::string& path, const std::string& field, FactorTerm& t) {
  check_regular_file(path, kMaxImageFileBytes, field);
  const int R = t.proj.res;
  FloatImage img;
  try {
    // The size is checked from the header, before any pixel is allocated.
    const ImageSize size = read_exr_size(path);
    if (size.width != R || size.height != R)
      throw std::invalid_argument(path + ": expected " + std::to_string(R) + "x" +
                                  std::to_string(R) + " texels (" + field +
                                  " resolution in the sidecar), found " +
                                  std::to_string(size.width) + "x" + std::to_string(size.height));
    img = read_exr_rgb(path, false, (long long)R * R);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    throw std::invalid_argument(what.find(field) == std::string::npos ? what + " (" + field + ")" : what);
  }
  const std::vector<float>& px = img.pixels;
  for (int c = 0; c < 3; ++c) t.texels[c].assign(size_t(R) * R, 0.0f);
  for (size_t k = 0; k < size_t(R) * R; ++k)
    for (int c = 0; c < 3; ++c) {
      const float v = px[3 * k + c];
      const std::string where = "texel (" + std::to_string(k % R) + ", " +
                                std::to_string(k / R) + ") channel " + kChannel[c];
      if (!std::isfinite(v))
        throw std::invalid_argument(path + ": " + where + ": expected a finite value, found " +
                                    std::to_string(v));
      if (!t.mask[k] && v != 0.0f)
        throw std::invalid_argument(path + ": " + where +
                                    ": expected 0 outside the projection mask, found " +
                                    std::to_string(v));
      t.texels[c][k] = v;
    }
}

}  // namespace

ExportedFiles write_factorization(const HomomorphicFactorization& f, const std::string& dir,
                                  const std::string& stem) {
  if (stem.empty() || stem.find('/') != std::string::npos)
    throw std::invalid_argument("export: stem must be a non-empty file name without '/', found \"" +
                                stem + "\"");
  check_finite(f);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw std::runtime_error(dir + ": cannot create the export folder" +
                             (ec ? ": " + ec.message() : std::string()));

  const fs::path d(dir);
  const auto& terms = f.terms();
  ExportedFiles files;
  files.sidecar = (d / (stem + ".json")).string();
  files.glsl = (d / (stem + ".glsl")).string();
  std::vector<std::string> tex_names, png_names;
  for (size_t k = 0; k < terms.size(); ++k) {
    tex_names.push_back(stem + "_term" + std::to_string(k) + ".exr");
    png_names.push_back(stem + "_term" + std::to_string(k) + ".png");
    files.textures.push_back((d / tex_names.back()).string());
    files.previews.push_back((d / png_names.back()).string());
  }

  AtomicBatch batch(d);
  for (size_t k = 0; k < terms.size(); ++k) {
    const FactorTerm& t = terms[k];
    const int R = t.proj.res;
    {
      FloatImage img;
      img.width = img.height = R;
      img.channel_names = {"R", "G", "B"};
      img.pixels = interleaved_texels(t);
      write_exr(batch.add(tex_names[k]), img,
                "brdf-factor log-space factor texture, term " + std::to_string(k) + " of " + stem +
                    ".json");
    }
    {
      int size = 0;
      const std::vector<uint8_t> px = preview_pixels(t, size);
      write_png_rgb8(batch.add(png_names[k]), size, size, px);
    }
  }

  write_text(batch.add(stem + ".glsl"), files.glsl,
             generate_glsl(f, tex_names, stem + ".json"));

  json j = f.describe();
  j["format"] = kFactorExportFormat;
  j["format_version"] = kFactorExportFormatVersion;
  j["glsl"] = stem + ".glsl";
  j["combine"] =
      "per RGB channel: f = A * exp(" +
      std::string(f.log_range() ? "clamp(g, log_range[c][0], log_range[c][1])" : "g") + ") " +
      std::string(f.subtract_eps() ? "- eps * A" : "") +
      ", clamped at 0, where g = sum over terms of the bilinear lookup of the term's texture at "
      "s(pi(x)), plus a second lookup of the same texture at s(pi*(x)) (the conjugate "
      "projection) for reciprocal terms; x = the point of (wi, wo) in the term's "
      "parameterization; f = 0 if wi.z <= 0 or wo.z <= 0";
  j["texture_layout"] =
      "float32 EXR, channels R, G, B = log-space texels; pixel (x, y) = texel (i, j), index "
      "j * resolution + i, centred at s = (i, j); scanline y = 0 first; texels outside the "
      "projection mask are 0";
  j["conventions"] =
      "n = +z, t = +x; wi towards the light, wo towards the viewer, unit vectors; f in 1/sr, "
      "linear RGB, no cosine; parabolic map p(w) = (w.x, w.y) / (1 + w.z); wiwo: x = (p(wi), "
      "p(wo)); halfdiff: x = (p(h), p(d)), h = normalize(wi + wo), d = wi in the frame "
      "(r, s, h), r = normalize(t - (t.h) h) (t = +y if that is shorter than 1e-12), s = h x r";
  for (size_t k = 0; k < terms.size(); ++k) {
    const FactorTerm& t = terms[k];
    json& tj = j["terms"][k];
    tj["texture"] = tex_names[k];
    tj["preview"] = png_names[k];
    tj["sampler"] = glsl_sampler_name(k);
    tj["channels"] = {"R", "G", "B"};
    tj["texel_matrix"] = mat_json(texel_matrix(t.proj));
    tj["texel_offset"] = {0.5 * (t.proj.res - 1), 0.5 * (t.proj.res - 1)};
    tj["texel_mapping"] =
        "s = clamp(texel_matrix * x + texel_offset, 0, resolution - 1); bilinear lookup at s; on "
        "a GPU, GL_LINEAR at uv = (s + 0.5) / resolution";
    if (t.reciprocal) {
      const Projection c = t.proj.conjugate();
      tj["conjugate_matrix"] = mat_json(c.P);
      tj["conjugate_texel_matrix"] = mat_json(texel_matrix(c));
    }
  }
  write_text(batch.add(stem + ".json"), files.sidecar, j.dump(2) + "\n");

  batch.commit();
  return files;
}

namespace {

// One entry of the sidecar's "terms" (at `where`), its texture read from `folder`.
FactorTerm read_term(const Sidecar& s, const json& tj, const std::string& where, const fs::path& folder) {
  FactorTerm t;
  const std::string param = s.string(tj, where, "parameterization");
  if (param == "wiwo") {
    t.proj.param = Parameterization::WiWo;
  } else if (param == "halfdiff") {
    t.proj.param = Parameterization::HalfDiff;
  } else {
    s.fail_text(where + ".parameterization", "\"wiwo\" or \"halfdiff\"", "\"" + param + "\"");
  }
  t.proj.res = int(s.integer(tj, where, "resolution", 2, 1024));
  {
    const std::string field = where + ".matrix";
    const json& m = s.array(s.member(tj, where, "matrix", "a 2x4 array of numbers"), field, 2,
                            "rows of 4 numbers (a 2x4 matrix)");
    for (int r = 0; r < 2; ++r) {
      const std::string rf = field + "[" + std::to_string(r) + "]";
      const json& row = s.array(m[r], rf, 4, "numbers (a 2x4 matrix)");
      for (int c = 0; c < 4; ++c)
        t.proj.P(r, c) = s.number(row[c], rf + "[" + std::to_string(c) + "]", "a finite number");
      if (t.proj.P.row(r).lpNorm<1>() == 0.0)
        s.fail(rf, "a row with a non-zero entry", row);
    }
  }
  t.reciprocal = s.boolean(tj, where, "reciprocal");
  if (tj.contains("quaternion_pair")) {
    const std::string field = where + ".quaternion_pair";
    const json& q = s.array(tj["quaternion_pair"], field, 8, "numbers (S then T, each [w, x, y, z])");
    std::array<double, 8> qp{};
    for (int i = 0; i < 8; ++i)
      qp[i] = s.number(q[i], field + "[" + std::to_string(i) + "]", "a finite number");
    t.rotation = qp;
  }
  t.mask = projection_mask(t.proj);
  if (tj.contains("mask_texels")) {
    const long long n = s.integer(tj, where, "mask_texels", 0, 1024 * 1024);
    if (size_t(n) != t.mask_count())
      s.fail(where + ".mask_texels",
             std::to_string(t.mask_count()) + " (the projection mask of this matrix and resolution)",
             tj["mask_texels"]);
  }
  const std::string tex = s.string(tj, where, "texture");
  if (tex.empty()) s.fail_text(where + ".texture", "a file name", "\"\"");
  // Decided from the text alone: the message never tells whether a file
  // outside the sidecar's folder exists.
  if (!is_path_inside(tex))
    s.fail_text(where + ".texture",
                "a file name inside the sidecar's folder (relative, no '..')", quote_for_message(tex));
  // A symbolic link inside the folder could point anywhere: refused too.
  if (has_symlink_below(folder.string(), tex))
    s.fail_text(where + ".texture",
                "a file name inside the sidecar's folder (relative, no '..', not through a symbolic link)",
                quote_for_message(tex));
  read_texture((folder / tex).string(), where + ".texture", t);
  return t;
}

}  // namespace

std::shared_ptr<HomomorphicFactorization> load_factorization(const std::string& json_path) {
  json j;
  {
    check_regular_file(json_path, kMaxTextFileBytes, "factorization sidecar");
    std::ifstream in(json_path, std::ios::binary);
    if (!in) {
      throw std::invalid_argument(json_path + ": cannot open factorization sidecar" +
                                  (fs::exists(json_path) ? "" : ": file not found"));
    }
    try {
      j = json::parse(in);
    } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e400
      throw std::invalid_argument(json_path + ": invalid JSON: " + e.what());
    }
  }
  const Sidecar s(json_path);
  if (!j.is_object()) s.fail("(top level)", "a JSON object", j);

  const std::string format = s.string(j, "", "format");
  if (format != kFactorExportFormat)
    s.fail_text("format", "\"" + std::string(kFactorExportFormat) + "\"", "\"" + format + "\"");
  {
    const std::string expected = std::to_string(kFactorExportFormatVersion) +
                                 " (the version this build reads)";
    const json& v = s.member(j, "", "format_version", expected);
    if (!v.is_number_integer() || v.get<long long>() != kFactorExportFormatVersion)
      s.fail("format_version", expected, v);
  }
  const std::string method = s.string(j, "", "method");

  Rgb A;
  {
    const json& a = s.array(s.member(j, "", "A", "an array of 3 numbers"), "A", 3, "numbers");
    for (int c = 0; c < 3; ++c) {
      const std::string field = "A[" + std::to_string(c) + "]";
      A[c] = s.number(a[c], field, "a finite number > 0");
      if (!(A[c] > 0.0)) s.fail(field, "a finite number > 0", a[c]);
    }
  }
  const double eps = s.number(s.member(j, "", "eps", "a number in (0, 1]"), "eps",
                              "a number in (0, 1]");
  if (!(eps > 0.0 && eps <= 1.0)) s.fail("eps", "a number in (0, 1]", j["eps"]);
  const bool subtract_eps = s.boolean(j, "", "subtract_eps");
  // Optional (absent in exports before the log-range clamp: no clamp).
  std::optional<LogRange> log_range;
  if (j.contains("log_range")) {
    const std::string expected = "an array of 3 [lo, hi] pairs of finite numbers, lo <= hi";
    const json& r = s.array(j["log_range"], "log_range", 3, "[lo, hi] pairs");
    log_range.emplace();
    for (int c = 0; c < 3; ++c) {
      const std::string field = "log_range[" + std::to_string(c) + "]";
      const json& p = s.array(r[c], field, 2, "finite numbers (lo, hi)");
      const double lo = s.number(p[0], field + "[0]", "a finite number");
      const double hi = s.number(p[1], field + "[1]", "a finite number");
      if (!(lo <= hi)) s.fail(field, "lo <= hi", r[c]);
      (*log_range)[c] = {lo, hi};
    }
  }

  const json& tjs = s.member(j, "", "terms", "an array of terms");
  if (!tjs.is_array()) s.fail("terms", "an array of terms", tjs);
  // Bounded memory: a few bytes of JSON per term could otherwise name one large
  // texture thousands of times.
  if (tjs.size() > kMaxSidecarTerms)
    s.fail_text("terms", "at most " + std::to_string(kMaxSidecarTerms) + " terms",
                std::to_string(tjs.size()));
  const fs::path folder = fs::path(json_path).parent_path();
  {  // Counted before any texture is read.
    uint64_t texels = 0;
    for (const json& tj : tjs)
      if (tj.is_object() && tj.contains("resolution") && tj["resolution"].is_number_integer()) {
        const int64_t r = tj["resolution"].get<int64_t>();
        if (r >= 2 && r <= 1024) texels += uint64_t(r) * uint64_t(r);
      }
    if (texels > kMaxSidecarTexels)
      s.fail_text("terms", "at most " + std::to_string(kMaxSidecarTexels) + " texels over all terms (" +
                               std::to_string(kMaxSidecarTexels >> 20) + " Mi, e.g. 64 terms of 1024x1024)",
                  std::to_string(texels) + " texels");
  }
  std::vector<FactorTerm> terms;
  for (size_t k = 0; k < tjs.size(); ++k) {
    const std::string where = "terms[" + std::to_string(k) + "]";
    const json& tj = tjs[k];
    if (!tj.is_object()) s.fail(where, "an object", tj);
    FactorTerm t = read_term(s, tj, where, folder);
    terms.push_back(std::move(t));
  }
  return std::make_shared<HomomorphicFactorization>(std::move(terms), A, eps, subtract_eps, method,
                                                    log_range);
}

ExportedFiles write_export(const Factorization& f, const std::string& dir, const std::string& stem,
                           const std::string& origin) {
  return f.write_export_files(dir, stem, origin);
}

// ---- The outputs of the homomorphic and model-fit results (factor/factorization.h).

ExportedFiles HomomorphicFactorization::write_export_files(const std::string& dir, const std::string& stem,
                                                           const std::string& origin) const {
  (void)origin;  // the GLSL quotes the sidecar's name
  return write_factorization(*this, dir, stem);
}

std::string HomomorphicFactorization::glsl(const std::string& stem, const std::string& origin) const {
  std::vector<std::string> tex_names;
  for (size_t k = 0; k < terms().size(); ++k) tex_names.push_back(stem + "_term" + std::to_string(k) + ".exr");
  return generate_glsl(*this, tex_names, origin.empty() ? stem + ".json" : origin);
}

std::optional<ShaderView> HomomorphicFactorization::viewer_data() const {
  ShaderView v;
  v.glsl = generate_glsl(*this, {}, "report.html viewer");
  for (size_t k = 0; k < terms().size(); ++k) {
    const FactorTerm& t = terms()[k];
    const int R = t.proj.res;
    FloatImage img;  // the log texels, as the EXR holds them
    img.width = img.height = R;
    img.channel_names = {"R", "G", "B"};
    img.pixels.assign(size_t(R) * R * 3, 0.0f);
    for (size_t q = 0; q < size_t(R) * R; ++q)
      if (t.mask[q])
        for (int c = 0; c < 3; ++c) img.pixels[3 * q + c] = t.texels[c][q];
    v.textures.emplace_back(glsl_sampler_name(k), std::move(img));
  }
  return v;
}

ExportedFiles ModelFitFactorization::write_export_files(const std::string& dir, const std::string& stem,
                                                        const std::string& origin) const {
  if (stem.empty() || stem.find('/') != std::string::npos)
    throw std::invalid_argument("export: stem must be a non-empty file name without '/', found \"" + stem + "\"");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create folder: " + ec.message());
  ExportedFiles e;
  e.sidecar = (fs::path(dir) / (stem + ".json")).string();
  // The GLSL first: a parameter it refuses (not a finite float) leaves no file.
  const std::string text = glsl(stem, origin);
  write_model_fit(result(), e.sidecar);
  e.glsl = (fs::path(dir) / (stem + ".glsl")).string();
  AtomicBatch batch{fs::path(dir)};
  write_text(batch.add(stem + ".glsl"), e.glsl, text);
  batch.commit();
  return e;
}

std::string ModelFitFactorization::glsl(const std::string& stem, const std::string& origin) const {
  (void)stem;  // no texture files
  return generate_model_glsl(*result().brdf, origin);
}

std::optional<ShaderView> ModelFitFactorization::viewer_data() const {
  // The fitted model's formula (model.glsl), no textures; none for a model without generated GLSL.
  if (!result().brdf || !has_model_glsl(*result().brdf)) return std::nullopt;
  return ShaderView{generate_model_glsl(*result().brdf, "report.html viewer"), {}};
}

namespace {

// The sidecar's text, checked as a regular file of at most kMaxTextFileBytes.
json read_sidecar_json(const std::string& path) {
  const std::string text = read_regular_file(path, kMaxTextFileBytes, "factorization sidecar");
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e400
    throw std::invalid_argument(path + ": invalid JSON: " + e.what());
  }
}

}  // namespace

namespace {

// Readers of result types outside the formats below, by the sidecar's method.
std::map<std::string, ExportReader>& export_readers() {
  static std::map<std::string, ExportReader> readers;
  return readers;
}
std::mutex& export_readers_mutex() {
  static std::mutex mu;
  return mu;
}

}  // namespace

void register_export_reader(const std::string& method, ExportReader read) {
  std::lock_guard<std::mutex> lk(export_readers_mutex());
  if (!read) export_readers().erase(method);
  else export_readers()[method] = std::move(read);
}

BrdfPtr load_export(const std::string& json_path) {
  const json j = read_sidecar_json(json_path);
  // A result type that registered its reader (register_export_reader).
  if (j.is_object() && j.contains("method") && j["method"].is_string()) {
    ExportReader read;
    {
      std::lock_guard<std::mutex> lk(export_readers_mutex());
      const auto it = export_readers().find(j["method"].get<std::string>());
      if (it != export_readers().end()) read = it->second;
    }
    if (read) return read(json_path);
  }
  // A model fit's file (factor/model_fit.h) is a catalogue spec in JSON.
  if (j.is_object() && j.contains("format") && j["format"] == kModelFitFormat) return load_model_fit(json_path);
  // SVD / SH exports (factor/baseline_export.h) dispatch on the sidecar's method.
  if (j.is_object() && j.contains("method") && j["method"].is_string() &&
      is_baseline_method(j["method"].get<std::string>()))
    return load_baseline_export(json_path);
  return load_factorization(json_path);
}

void register_export_loader(Catalogue& cat) {
  cat.add_loader(".json", [](const std::string& path, const ParamDict& options) -> BrdfPtr {
    options.check_unused("factorization sidecar", {});
    return load_export(path);
  });
}

}  // namespace bf
