// Tests of the factor export: round trip through EXR + JSON sidecar, loader
// validation messages, atomic writes, catalogue registration, and the
// generated GLSL compiled by glslangValidator.
#include <array>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "factor/export.h"
#include "factor/glsl.h"
#include "factor/image_io.h"
#include "test_common.h"
#include "factor/glsl_compile.h"

using namespace bf;
namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using nlohmann::json;

namespace {

using bf_test::TempDir;

Mat24 random_orthonormal(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Vec4 a, b;
  for (int i = 0; i < 4; ++i) a[i] = N(rng), b[i] = N(rng);
  a.normalize();
  b -= b.dot(a) * a;
  b.normalize();
  Mat24 P;
  P.row(0) = a.transpose();
  P.row(1) = b.transpose();
  return P;
}

// Smooth random log-space texels (a few low-frequency sinusoids), 0 outside the mask.
FactorTerm make_term(const Projection& p, bool reciprocal, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  FactorTerm t;
  t.proj = p;
  t.reciprocal = reciprocal;
  t.mask = projection_mask(p);
  const int R = p.res;
  for (int c = 0; c < 3; ++c) {
    double a[3], fx[3], fy[3], ph[3];
    for (int m = 0; m < 3; ++m) a[m] = 0.3 * U(rng), fx[m] = 3 * U(rng), fy[m] = 3 * U(rng),
                                ph[m] = 3 * U(rng);
    t.texels[c].assign(size_t(R) * R, 0.0f);
    for (int j = 0; j < R; ++j)
      for (int i = 0; i < R; ++i) {
        if (!t.mask[j * R + i]) continue;
        double v = -0.2 * c;
        for (int m = 0; m < 3; ++m) v += a[m] * std::sin(fx[m] * i / R + fy[m] * j / R + ph[m]);
        t.texels[c][j * R + i] = float(v);
      }
  }
  return t;
}

// Three terms: a wiwo term with a random orthonormal projection (and a
// quaternion pair), a reciprocal halfdiff term, a reciprocal wiwo term.
std::vector<std::pair<Vec3, Vec3>> direction_pairs();

// ranged: with a log range (docs/design.md §3.2) at the 20th and 80th
// percentiles of the unclamped log value over direction_pairs(), per channel.
HomomorphicFactorization make_factorization(bool subtract_eps = true, bool ranged = false) {
  std::mt19937_64 rng(2024);
  std::vector<FactorTerm> terms;
  Projection p0;
  p0.param = Parameterization::WiWo;
  p0.P = random_orthonormal(rng);
  p0.res = 16;
  terms.push_back(make_term(p0, false, rng));
  terms.back().rotation = std::array<double, 8>{0.5, 0.5, -0.5, 0.5, 0.8, 0.0, 0.6, 0.0};
  Projection p1;
  p1.param = Parameterization::HalfDiff;
  p1.P = random_orthonormal(rng);
  p1.res = 12;
  terms.push_back(make_term(p1, true, rng));
  terms.push_back(make_term(projection_first_pair(Parameterization::WiWo, 8), true, rng));
  HomomorphicFactorization f(terms, Rgb(0.3, 0.5, 0.7), 1e-5, subtract_eps, "fit");
  if (!ranged) return f;
  LogRange range;
  const auto pairs = direction_pairs();
  for (int c = 0; c < 3; ++c) {
    std::vector<double> v;
    for (const auto& [wi, wo] : pairs) v.push_back(f.eval_log(wi, wo)[c]);
    std::sort(v.begin(), v.end());
    range[c] = {v[v.size() / 5], v[4 * v.size() / 5]};
  }
  return HomomorphicFactorization(std::move(terms), Rgb(0.3, 0.5, 0.7), 1e-5, subtract_eps, "fit", range);
}

Vec3 random_upper(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double z = U(rng), phi = 2 * M_PI * U(rng);
  return from_spherical(std::acos(std::max(z, 1e-6)), phi);
}

// 1000 random pairs plus n = h, grazing, wi = wo and near wi = -wo pairs.
std::vector<std::pair<Vec3, Vec3>> direction_pairs() {
  std::mt19937_64 rng(99);
  std::vector<std::pair<Vec3, Vec3>> v;
  for (int k = 0; k < 1000; ++k) v.push_back({random_upper(rng), random_upper(rng)});
  for (double th : {0.0, 1e-7, 0.5, 1.3, M_PI / 2 - 1e-7}) {
    v.push_back({from_spherical(th, 0.3), from_spherical(th, 0.3 + M_PI)});
    v.push_back({from_spherical(th, 1.0), from_spherical(th, 1.0)});
    v.push_back({from_spherical(th, 0.0), from_spherical(M_PI / 2 - 1e-6, M_PI)});
  }
  return v;
}

json read_export_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

void write_export_json(const std::string& path, const json& j) {
  std::ofstream out(path);
  out << j.dump(2);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Exports the test factorization to a folder, lets `corrupt` edit the sidecar,
// and returns the sidecar path.
std::string corrupted_export(const TempDir& dir, const std::function<void(json&)>& corrupt) {
  const HomomorphicFactorization f = make_factorization();
  const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
  json j = read_export_json(files.sidecar);
  corrupt(j);
  write_export_json(files.sidecar, j);
  return files.sidecar;
}

void write_exr(const std::string& path, int w, int h, int channels, const std::vector<float>& px) {
  const std::vector<std::string> names = {"R", "G", "B", "A"};
  bf::FloatImage img;
  img.width = w;
  img.height = h;
  img.channel_names = channels == 1 ? std::vector<std::string>{"Y"}
                                    : std::vector<std::string>(names.begin(), names.begin() + channels);
  img.pixels = px;
  bf::write_exr(path, img);
}

}  // namespace

TEST_CASE("export: reload evaluates bit-identically to the in-memory factorization") {
  for (int variant = 0; variant < 4; ++variant) {
    const bool subtract_eps = variant % 2 == 0, ranged = variant >= 2;
    INFO("subtract_eps " << subtract_eps << ", log range " << ranged);
    const HomomorphicFactorization f = make_factorization(subtract_eps, ranged);
    TempDir dir("export");
    const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
    for (const std::string& p : files.textures) CHECK(fs::exists(p));
    for (const std::string& p : files.previews) CHECK(fs::exists(p));
    CHECK(fs::exists(files.glsl));
    // No temporaries left behind.
    for (const auto& e : fs::directory_iterator(dir.path))
      CHECK(e.path().filename().string()[0] != '.');

    const auto g = load_factorization(files.sidecar);
    CHECK(g->storage_floats() == f.storage_floats());
    CHECK(g->method() == f.method());
    CHECK(g->subtract_eps() == f.subtract_eps());
    CHECK(g->eps() == f.eps());
    CHECK((g->A() == f.A()).all());
    CHECK(g->log_range() == f.log_range());
    CHECK(g->log_range().has_value() == ranged);
    REQUIRE(g->terms().size() == f.terms().size());
    for (size_t k = 0; k < f.terms().size(); ++k) {
      const FactorTerm &a = f.terms()[k], &b = g->terms()[k];
      CHECK(a.proj.param == b.proj.param);
      CHECK(a.proj.res == b.proj.res);
      CHECK(a.proj.P == b.proj.P);
      CHECK(a.reciprocal == b.reciprocal);
      CHECK(a.rotation == b.rotation);
      CHECK(a.mask == b.mask);
      for (int c = 0; c < 3; ++c) CHECK(a.texels[c] == b.texels[c]);
    }

    double max_rel = 0.0;
    size_t identical = 0, n = 0;
    for (const auto& [wi, wo] : direction_pairs()) {
      const Rgb a = f.eval(wi, wo), b = g->eval(wi, wo);
      INFO("wi = " << bf_test::str(wi) << ", wo = " << bf_test::str(wo));
      REQUIRE(a.allFinite());
      for (int c = 0; c < 3; ++c) {
        const double rel = std::abs(a[c] - b[c]) / std::max(std::abs(a[c]), 1e-300);
        max_rel = std::max(max_rel, a[c] == b[c] ? 0.0 : rel);
        CHECK(rel <= 1e-6);
        identical += a[c] == b[c];
        ++n;
      }
    }
    INFO("max relative difference " << max_rel);
    CHECK(identical == n);
  }
}

TEST_CASE("export: sidecar holds what a renderer needs") {
  const HomomorphicFactorization f = make_factorization();
  TempDir dir("export");
  const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
  const json j = read_export_json(files.sidecar);
  CHECK(j.at("format") == kFactorExportFormat);
  CHECK(j.at("format_version") == kFactorExportFormatVersion);
  CHECK(j.at("glsl") == "factors.glsl");
  CHECK(j.at("eps") == 1e-5);
  CHECK(j.at("subtract_eps") == true);
  CHECK(j.at("A").size() == 3);
  CHECK(j.contains("combine"));
  REQUIRE(j.at("terms").size() == 3);
  const json& t0 = j.at("terms")[0];
  CHECK(t0.at("texture") == "factors_term0.exr");
  CHECK(t0.at("preview") == "factors_term0.png");
  CHECK(t0.at("sampler") == "brdf_factor_tex0");
  CHECK(t0.at("resolution") == 16);
  CHECK(t0.at("quaternion_pair").size() == 8);
  CHECK(t0.at("reciprocal") == false);
  CHECK_FALSE(t0.contains("conjugate_matrix"));
  CHECK(j.at("terms")[1].contains("conjugate_matrix"));
  // texel_matrix * x + texel_offset reproduces Projection::texel_coords.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (size_t k = 0; k < 3; ++k) {
    const json& tj = j.at("terms")[k];
    for (int trial = 0; trial < 20; ++trial) {
      const Vec4 x(U(rng), U(rng), U(rng), U(rng));
      const Eigen::Vector2d s = f.terms()[k].proj.texel_coords(x);
      for (int r = 0; r < 2; ++r) {
        double v = tj.at("texel_offset")[r].get<double>();
        for (int c = 0; c < 4; ++c) v += tj.at("texel_matrix")[r][c].get<double>() * x[c];
        CHECK(v == Approx(s[r]).margin(1e-12));
      }
    }
  }
  // Previews: upscaled to 256 px, outside-mask texels grey; inside, the heat
  // colour map of log10 (mean over channels of exp(texel)) on the fixed range
  // [-3, 3], the same for every term (not normalized per term).
  const auto heat = [](double v) {
    const double st[5][3] = {{0, 0, 0}, {0.1, 0.15, 0.85}, {0.9, 0.1, 0.2}, {1, 0.85, 0.1}, {1, 1, 1}};
    const double t = std::clamp((std::log10(v) + 3.0) / 6.0, 0.0, 1.0) * 4.0;
    const int i = std::min(3, int(t));
    std::array<int, 3> c{};
    for (int ch = 0; ch < 3; ++ch) c[ch] = int(std::lround(255.0 * (st[i][ch] + (t - i) * (st[i + 1][ch] - st[i][ch]))));
    return c;
  };
  for (size_t term = 0; term < files.previews.size(); ++term) {
    int pw = 0, ph = 0;
    const std::vector<uint8_t> px = bf::read_png_rgb8(files.previews[term], pw, ph);
    const FactorTerm& t = f.terms()[term];
    const int R = t.proj.res, block = std::max(1, 256 / R), size = R * block;
    CHECK(pw == size);
    CHECK(ph == size);
    REQUIRE(px.size() == size_t(size) * size * 3);
    int inside = 0;
    for (int k = 0; k < R * R; ++k) {
      const int x = (k % R) * block + block / 2, y = (k / R) * block + block / 2;
      const uint8_t* p = &px[(size_t(y) * size + x) * 3];
      if (!t.mask[k]) {
        CHECK((p[0] == 128 && p[1] == 128 && p[2] == 128));
        continue;
      }
      ++inside;
      double v = 0;
      for (int c = 0; c < 3; ++c) v += std::exp(double(t.texels[c][k])) / 3;
      const auto e = heat(v);
      INFO("term " << term << " texel " << k << " value " << v);
      CHECK(std::abs(int(p[0]) - e[0]) <= 1);
      CHECK(std::abs(int(p[1]) - e[1]) <= 1);
      CHECK(std::abs(int(p[2]) - e[2]) <= 1);
    }
    CHECK(inside > 0);
  }
}

TEST_CASE("export: the loader names the file, field, expectation and finding") {
  SECTION("missing field") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j.erase("eps"); });
    REQUIRE_THROWS_WITH(load_factorization(p),
                        Contains(p) && Contains("field 'eps'") && Contains("(0, 1]") &&
                            Contains("field missing"));
  }
  SECTION("missing term field") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["terms"][2].erase("matrix"); });
    REQUIRE_THROWS_WITH(load_factorization(p),
                        Contains("field 'terms[2].matrix'") && Contains("field missing"));
  }
  SECTION("wrong type") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["terms"][1]["resolution"] = "12"; });
    REQUIRE_THROWS_WITH(load_factorization(p),
                        Contains(p) && Contains("field 'terms[1].resolution'") &&
                            Contains("expected an integer in 2..1024") &&
                            Contains("found string \"12\""));
  }
  SECTION("boolean of the wrong type") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["terms"][0]["reciprocal"] = 1; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'terms[0].reciprocal'") &&
                                                   Contains("expected true or false") &&
                                                   Contains("found number 1"));
  }
  SECTION("resolution out of range") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["terms"][0]["resolution"] = 4096; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'terms[0].resolution'") &&
                                                   Contains("found number 4096"));
  }
  SECTION("resolution differs from the EXR") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) {
      j["terms"][0]["resolution"] = 8;
      j["terms"][0].erase("mask_texels");
    });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("factors_term0.exr") &&
                                                   Contains("expected 8x8 texels") &&
                                                   Contains("found 16x16"));
  }
  SECTION("mask_texels inconsistent with matrix and resolution") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["terms"][0]["resolution"] = 8; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'terms[0].mask_texels'"));
  }
  SECTION("matrix of the wrong shape") {
    TempDir dir("export");
    const std::string p =
        corrupted_export(dir, [](json& j) { j["terms"][1]["matrix"][0] = {1.0, 0.0, 0.0}; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'terms[1].matrix[0]'") &&
                                                   Contains("expected an array of 4") &&
                                                   Contains("found an array of 3"));
  }
  SECTION("NaN in A (JSON has no NaN: it is written as null)") {
    TempDir dir("export");
    const std::string p =
        corrupted_export(dir, [](json& j) { j["A"][1] = std::numeric_limits<double>::quiet_NaN(); });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains(p) && Contains("field 'A[1]'") &&
                                                   Contains("expected a finite number > 0") &&
                                                   Contains("found null"));
  }
  SECTION("literal NaN in the text is invalid JSON") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) {});
    std::string text = read_text(p);
    const size_t a = text.find("\"A\": [");
    REQUIRE(a != std::string::npos);
    text.insert(a + 6, "NaN, ");
    std::ofstream(p) << text;
    REQUIRE_THROWS_WITH(load_factorization(p), Contains(p) && Contains("invalid JSON"));
  }
  SECTION("A <= 0 and eps out of range") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["A"][0] = 0.0; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'A[0]'") && Contains("found number 0"));
    TempDir dir2("export");
    const std::string q = corrupted_export(dir2, [](json& j) { j["eps"] = 2.0; });
    REQUIRE_THROWS_WITH(load_factorization(q), Contains("field 'eps'") && Contains("found number 2"));
  }
  SECTION("format and version") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["format_version"] = 2; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'format_version'") &&
                                                   Contains("expected 1") && Contains("found number 2"));
    TempDir dir2("export");
    const std::string q = corrupted_export(dir2, [](json& j) { j.erase("format"); });
    REQUIRE_THROWS_WITH(load_factorization(q), Contains("field 'format'") && Contains("field missing"));
  }
  SECTION("unknown parameterization") {
    TempDir dir("export");
    const std::string p =
        corrupted_export(dir, [](json& j) { j["terms"][0]["parameterization"] = "wohi"; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'terms[0].parameterization'") &&
                                                   Contains("\"wiwo\" or \"halfdiff\"") &&
                                                   Contains("\"wohi\""));
  }
  SECTION("missing EXR") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) {});
    fs::remove(dir.file("factors_term1.exr"));
    REQUIRE_THROWS_WITH(load_factorization(p), Contains(dir.file("factors_term1.exr")) &&
                                                   Contains("terms[1].texture") &&
                                                   Contains("file not found"));
  }
  SECTION("EXR with a NaN texel, a nonzero texel outside the mask, 1 channel") {
    const HomomorphicFactorization f = make_factorization();
    const FactorTerm& t = f.terms()[2];
    const int R = t.proj.res;
    size_t inside = 0, outside = 0;
    for (size_t k = 0; k < t.mask.size(); ++k) (t.mask[k] ? inside : outside) = k;
    std::vector<float> px(size_t(R) * R * 3, 0.0f);
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) {});
    px[3 * inside + 1] = std::numeric_limits<float>::quiet_NaN();
    write_exr(dir.file("factors_term2.exr"), R, R, 3, px);
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("factors_term2.exr") &&
                                                   Contains("channel G") &&
                                                   Contains("expected a finite value"));
    if (outside != inside && !t.mask[outside]) {
      px.assign(px.size(), 0.0f);
      px[3 * outside] = 1.0f;
      write_exr(dir.file("factors_term2.exr"), R, R, 3, px);
      REQUIRE_THROWS_WITH(load_factorization(p), Contains("outside the projection mask"));
    }
    write_exr(dir.file("factors_term2.exr"), R, R, 1, std::vector<float>(size_t(R) * R, 0.0f));
    REQUIRE_THROWS_WITH(load_factorization(p),
                        Contains("expected 3 channels") && Contains("found 1"));
  }
  SECTION("missing sidecar") {
    TempDir dir("export");
    REQUIRE_THROWS_WITH(load_factorization(dir.file("nope.json")),
                        Contains("nope.json") && Contains("file not found"));
  }
}

TEST_CASE("export: a non-finite texel is refused and no file is written") {
  std::vector<FactorTerm> terms = make_factorization().terms();
  size_t k = 0;
  while (!terms[1].mask[k]) ++k;
  terms[1].texels[0][k] = std::numeric_limits<float>::infinity();
  const HomomorphicFactorization f(terms, Rgb(1, 1, 1), 1e-5, true, "fit");
  TempDir dir("export");
  REQUIRE_THROWS_WITH(write_factorization(f, dir.path.string(), "factors"),
                      Contains("term 1") && Contains("channel R") && Contains("non-finite"));
  CHECK(fs::is_empty(dir.path));
}

TEST_CASE("export: a failed write leaves the previous export in place") {
  TempDir dir("export");
  const HomomorphicFactorization f = make_factorization();
  const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
  const std::string before = read_text(files.sidecar);
  // A folder where the GLSL file should go makes its rename fail after the
  // textures were written to temporaries.
  fs::remove(files.glsl);
  fs::create_directories(files.glsl + "/blocker");
  CHECK_THROWS_WITH(write_factorization(f, dir.path.string(), "factors"),
                    Contains("factors.glsl"));
  CHECK(read_text(files.sidecar) == before);
  for (const auto& e : fs::directory_iterator(dir.path))
    CHECK(e.path().filename().string()[0] != '.');
}

TEST_CASE("export: the catalogue loads a sidecar through the .json loader") {
  TempDir dir("export");
  const HomomorphicFactorization f = make_factorization();
  const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
  Catalogue cat;
  register_export_loader(cat);
  const BrdfPtr b = cat.make(files.sidecar);
  const Vec3 wi = from_spherical(0.4, 0.2), wo = from_spherical(0.7, 2.5);
  CHECK((b->eval(wi, wo) == f.eval(wi, wo)).all());
  CHECK_THROWS_WITH(cat.make(files.sidecar + ":scale=2"), Contains("unknown parameter 'scale'"));
}

TEST_CASE("export: generated GLSL compiles for GL 3.3, GL 4.5, GLES 3.0 and Vulkan") {
  // Installed by scripts/install-deps.sh (glslang-tools): missing, the test fails.
  INFO("glslangValidator not found: scripts/install-deps.sh installs glslang-tools");
  REQUIRE(std::system("command -v glslangValidator > /dev/null 2>&1") == 0);
  for (const bool ranged : {false, true}) {
    TempDir dir("export");
    const HomomorphicFactorization f = make_factorization(true, ranged);
    const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
    const std::string glsl = read_text(files.glsl);
    CHECK_THAT(glsl, Contains("vec3 brdf_factor_eval(vec3 wi, vec3 wo)"));
    CHECK((glsl.find("g = clamp(g, ") != std::string::npos) == ranged);
    const std::string err =
        bf_test::compile_glsl_all_targets(glsl, dir.path, "#define BRDF_FACTOR_EXACT_BILINEAR\n");
    INFO("log range " << ranged << ": " << err);
    CHECK(err.empty());
  }
}

TEST_CASE("export: a bad log_range is refused naming the field, an absent one means no clamp") {
  SECTION("lo > hi") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["log_range"] = {{0, 1}, {2, 1}, {0, 1}}; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains(p) && Contains("field 'log_range[1]'") &&
                                                   Contains("lo <= hi"));
  }
  SECTION("not a number, wrong shape") {
    TempDir dir("export");
    const std::string p = corrupted_export(dir, [](json& j) { j["log_range"] = {{0, 1}, {0, 1}, {0, "x"}}; });
    REQUIRE_THROWS_WITH(load_factorization(p), Contains("field 'log_range[2][1]'") && Contains("finite number"));
    TempDir dir2("export");
    const std::string q = corrupted_export(dir2, [](json& j) { j["log_range"] = {{0, 1}, {0, 1}}; });
    REQUIRE_THROWS_WITH(load_factorization(q), Contains("field 'log_range'") && Contains("array of 2"));
  }
  SECTION("absent (an export from before the clamp)") {
    TempDir dir("export");
    const HomomorphicFactorization f = make_factorization(true, true);
    const ExportedFiles files = write_factorization(f, dir.path.string(), "factors");
    json j = read_export_json(files.sidecar);
    REQUIRE(j.contains("log_range"));
    j.erase("log_range");
    write_export_json(files.sidecar, j);
    const auto g = load_factorization(files.sidecar);
    CHECK(!g->log_range());
    size_t differ = 0;
    for (const auto& [wi, wo] : direction_pairs()) differ += (g->eval(wi, wo) != f.eval(wi, wo)).any();
    CHECK(differ > 0);  // unclamped: the range was binding
  }
}

namespace {
// Log texel of the orientation pattern: affine in (i, j) with different
// slopes per axis, term and channel, so a transposed or shifted read changes
// the value. t(i, j) = alpha i + beta j + gamma.
struct Pattern {
  double alpha, beta, gamma;
};
Pattern pattern(size_t term, int c) {
  return {0.04 + 0.01 * c - 0.004 * double(term), -0.07 + 0.015 * c + 0.005 * double(term), -0.3 + 0.1 * c};
}

// Texel coordinates by the documented formula (projection.h, glsl.h):
// s_r = (P x)_r / l1(P_r) * (res - 1) / 2 + (res - 1) / 2, clamped to [0, res - 1].
Eigen::Vector2d documented_texel_coords(const Projection& p, const Vec4& x) {
  Eigen::Vector2d s;
  for (int r = 0; r < 2; ++r) {
    const double l1 = p.P.row(r).cwiseAbs().sum();
    s[r] = std::clamp(p.P.row(r).dot(x) / l1 * 0.5 * (p.res - 1) + 0.5 * (p.res - 1), 0.0, double(p.res - 1));
  }
  return s;
}

// The pattern factorization's log value at (wi, wo), computed from the
// pattern's closed form: bilinear interpolation of an affine function is the
// function, so each lookup is alpha s.x + beta s.y + gamma with s from the
// documented formula; reciprocal terms add the lookup at (wo, wi).
Rgb pattern_log(const HomomorphicFactorization& f, const Vec3& wi, const Vec3& wo) {
  Rgb g = Rgb::Zero();
  for (size_t k = 0; k < f.terms().size(); ++k) {
    const FactorTerm& t = f.terms()[k];
    const auto add = [&](const Vec3& a, const Vec3& b) {
      const Eigen::Vector2d s = documented_texel_coords(t.proj, to_point(t.proj.param, a, b));
      for (int c = 0; c < 3; ++c) {
        const Pattern q = pattern(k, c);
        g[c] += q.alpha * s.x() + q.beta * s.y() + q.gamma;
      }
    };
    add(wi, wo);
    if (t.reciprocal) add(wo, wi);
  }
  return g;
}
}  // namespace

TEST_CASE("export: texture orientation holds through write, read, eval and the GLSL run on Mesa") {
  // Three terms with the asymmetric pattern: wiwo first pair (res 9), a
  // reciprocal halfdiff term and a reciprocal wiwo term with random
  // projections (res 12, 8). Texel (i, j) is texels[c][j * res + i].
  std::mt19937_64 rng(77);
  std::vector<FactorTerm> terms;
  std::vector<Projection> projs(3);
  projs[0] = projection_first_pair(Parameterization::WiWo, 9);
  projs[1].param = Parameterization::HalfDiff;
  projs[1].P = random_orthonormal(rng);
  projs[1].res = 12;
  projs[2].param = Parameterization::WiWo;
  projs[2].P = random_orthonormal(rng);
  projs[2].res = 8;
  for (size_t k = 0; k < 3; ++k) {
    FactorTerm t;
    t.proj = projs[k];
    t.reciprocal = k > 0;
    t.mask = projection_mask(t.proj);
    const int R = t.proj.res;
    for (int c = 0; c < 3; ++c) {
      const Pattern q = pattern(k, c);
      t.texels[c].assign(size_t(R) * R, 0.0f);
      for (int j = 0; j < R; ++j)
        for (int i = 0; i < R; ++i)
          if (t.mask[j * R + i]) t.texels[c][j * R + i] = float(q.alpha * i + q.beta * j + q.gamma);
    }
    terms.push_back(std::move(t));
  }
  const HomomorphicFactorization f(terms, Rgb(0.3, 0.5, 0.7), 1e-5, true, "fit");
  TempDir dir("export");
  const ExportedFiles files = write_factorization(f, dir.path.string(), "orient");
  REQUIRE(files.textures.size() == 3);

  // 1. The EXR holds texel (i, j) at pixel x = i of scanline y = j (the
  //    convention glsl.h documents: scanline 0 is the first row, t = 0).
  for (size_t k = 0; k < 3; ++k) {
    // Read with the plain EXR reader (factor/image_io.h), not the export's
    // loader, so a transpose in the export's writer and loader together shows.
    const bf::FloatImage img = bf::read_exr_rgb(files.textures[k]);
    const int R = projs[k].res;
    REQUIRE(img.width == R);
    REQUIRE(img.height == R);
    const std::vector<float>& px = img.pixels;
    size_t wrong = 0;
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x)
        for (int c = 0; c < 3; ++c) {
          const Pattern q = pattern(k, c);
          const float want = terms[k].mask[y * R + x] ? float(q.alpha * x + q.beta * y + q.gamma) : 0.0f;
          wrong += px[(size_t(y) * R + x) * 3 + c] != want;
        }
    INFO("term " << k << ": " << wrong << " EXR values not at (x = i, y = j)");
    CHECK(wrong == 0);
  }

  // 2. eval of the in-memory and of the reloaded factorization against the
  //    pattern's closed form at the documented texel coordinates.
  const auto g = load_factorization(files.sidecar);
  std::vector<std::pair<Vec3, Vec3>> pairs;
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int n = 0; n < 300; ++n) {
    const double ti = std::acos(0.08 + 0.92 * U(rng)), to = std::acos(0.08 + 0.92 * U(rng));
    pairs.push_back({from_spherical(ti, 2 * M_PI * U(rng)), from_spherical(to, 2 * M_PI * U(rng))});
  }
  double eval_err = 0.0, reload_err = 0.0;
  for (const auto& [wi, wo] : pairs) {
    const Rgb want = pattern_log(f, wi, wo);
    eval_err = std::max(eval_err, (f.eval_log(wi, wo) - want).abs().maxCoeff());
    reload_err = std::max(reload_err, (g->eval_log(wi, wo) - want).abs().maxCoeff());
  }
  INFO("max |eval_log - closed form|: " << eval_err << " (in memory), " << reload_err << " (reloaded)");
  CHECK(eval_err < 1e-5);  // texels are floats: ~1e-7 each
  CHECK(reload_err < 1e-5);

  // 3. The generated GLSL executed on Mesa's llvmpipe (tests/glsl/glsl_run.cpp),
  //    textures bound as the header says, both lookup paths, against eval.
  const fs::path runner = fs::read_symlink("/proc/self/exe").parent_path() / "bf_glsl_run";
  INFO("GLSL runner " << runner.string() << " (built with the tests; needs Mesa's EGL: scripts/install-deps.sh)");
  REQUIRE(fs::exists(runner));
  {
    std::ofstream d(dir.file("dirs.txt"));
    d.precision(17);
    for (const auto& [wi, wo] : pairs)
      d << wi.x() << " " << wi.y() << " " << wi.z() << " " << wo.x() << " " << wo.y() << " " << wo.z() << "\n";
  }
  // The same terms with a log range that binds on both sides at about a
  // quarter of the pairs each (the log-range clamp, docs/design.md §3.2).
  LogRange range;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> v;
    for (const auto& [wi, wo] : pairs) v.push_back(f.eval_log(wi, wo)[c]);
    std::sort(v.begin(), v.end());
    range[c] = {v[v.size() / 4], v[3 * v.size() / 4]};
  }
  const HomomorphicFactorization fr(terms, f.A(), f.eps(), true, "fit", range);
  fs::create_directories(dir.file("ranged"));
  const ExportedFiles rfiles = write_factorization(fr, dir.file("ranged"), "orient");
  for (int variant = 0; variant < 4; ++variant) {
    const bool exact = variant % 2 == 0, ranged = variant >= 2;
    const HomomorphicFactorization& fv = ranged ? fr : f;
    const ExportedFiles& fl = ranged ? rfiles : files;
    std::string cmd = runner.string() + " " + fl.glsl + " " + (dir.file("dirs.txt")) + " " + (dir.file("out.txt")) +
                      (exact ? " --exact" : "");
    for (const auto& t : fl.textures) cmd += " " + t;
    cmd += " > " + (dir.file("run.log")) + " 2>&1";
    const int rc = std::system(cmd.c_str());
    INFO((exact ? "texelFetch path" : "hardware bilinear path") << (ranged ? ", log range clamped" : "") << ": "
                                                                   << read_text(dir.file("run.log")));
    REQUIRE(rc == 0);
    std::ifstream out(dir.file("out.txt"));
    double worst = 0.0;
    size_t n = 0, clamped = 0;
    for (const auto& [wi, wo] : pairs) {
      Rgb gpu;
      REQUIRE(out >> gpu[0] >> gpu[1] >> gpu[2]);
      const Rgb cpu = fv.eval(wi, wo);
      clamped += (fv.eval(wi, wo) != f.eval(wi, wo)).any();
      worst = std::max(worst, ((gpu - cpu).abs() / cpu.abs()).maxCoeff());
      ++n;
    }
    CHECK(n == pairs.size());
    if (ranged) CHECK(clamped > pairs.size() / 4);  // the clamp binds: the GLSL must apply it
    // Measured 5.4e-7 on both paths (float arithmetic; llvmpipe's GL_LINEAR
    // weights are full float). A transposed or shifted lookup is off by
    // O(0.1) per texel in log space. (A GPU with 8-bit filter weights would
    // need about 3e-3 on the hardware path: glsl.h.)
    INFO("max relative |GLSL - eval| " << worst);
    CHECK(worst < 1e-5);
  }
}
