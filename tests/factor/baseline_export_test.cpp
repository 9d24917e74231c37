// Tests of the SVD / SH-K / SH-R export (factor/baseline_export.h): the
// catalogue's .json loader reloads each kind so that it evaluates as the
// factorization that was written (1e-6 relative; it is in fact exact), the
// EXR textures hold the documented layout, the GLSL of every kind compiles for
// GL 3.3, GL 4.5, GLES 3.0 and Vulkan and, run on Mesa's llvmpipe with the
// EXR textures, returns eval's values, and damaged exports are refused with a
// message naming the file and field.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/models.h"
#include "factor/baseline_export.h"
#include "factor/export.h"
#include "factor/glsl_compile.h"
#include "factor/glsl_run.h"
#include "factor/image_io.h"
#include "factor/sh_baseline.h"
#include "factor/svd_baseline.h"
#include "solvers/sh.h"
#include "test_common.h"

using namespace bf;
using bf_test::TempDir;
using Catch::Contains;

namespace {

Ward make_ward(double ax, double ay) {
  WardParams p;
  p.kd = Rgb(0.3, 0.25, 0.2);
  p.ks = Rgb(0.2, 0.25, 0.3);
  p.ax = ax;
  p.ay = ay;
  return Ward(p);
}

// Random direction pairs above the horizon, a fifth of them grazing (|wi + wo| < 1).
std::vector<std::pair<Vec3, Vec3>> pairs(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::pair<Vec3, Vec3>> out;
  while (int(out.size()) < n) {
    const Vec3 wi = from_spherical(std::acos(U(rng)) * 0.999, 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)) * 0.999, 2 * M_PI * U(rng));
    if (out.size() % 5 == 4 && (wi + wo).norm() >= 1.0) continue;
    out.emplace_back(wi, wo);
  }
  return out;
}

// Reloads the export through the catalogue and compares eval at 200 pairs.
void check_reload(const Factorization& f, const std::string& sidecar) {
  Catalogue cat;
  register_export_loader(cat);
  const BrdfPtr b = cat.make(sidecar);
  auto g = std::dynamic_pointer_cast<const Factorization>(b);
  REQUIRE(g);
  CHECK(g->method() == f.method());
  CHECK(g->storage_floats() == f.storage_floats());
  int nonzero = 0;
  double worst = 0.0;
  for (const auto& [wi, wo] : pairs(200)) {
    const Rgb a = f.eval(wi, wo), r = b->eval(wi, wo);
    for (int c = 0; c < 3; ++c) {
      if (a[c] != 0.0) ++nonzero;
      worst = std::max(worst, std::abs(a[c] - r[c]) / std::max(std::abs(a[c]), 1e-300));
    }
  }
  INFO(f.to_string() << ": worst relative difference " << worst);
  CHECK(nonzero > 300);
  CHECK(worst <= 1e-6);
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The export's GLSL compiles for the four targets, and executed on Mesa's
// llvmpipe (tests/glsl/glsl_run.cpp) with the EXR textures bound to the
// samplers the sidecar names, returns eval's values: worst |GLSL - eval|
// relative to max(|eval|, 1e-3 of the peak over the pairs) below tol (float32
// textures and arithmetic; the measured figures are at the call sites).
void check_glsl(const Factorization& f, const BaselineExportFiles& files, const std::filesystem::path& dir,
                double tol) {
  const std::string glsl = bf_test::slurp(files.glsl);
  CHECK_THAT(glsl, Contains("vec3 brdf_factor_eval(vec3 wi, vec3 wo)"));
  const std::string err = bf_test::compile_glsl_all_targets(glsl, dir);
  INFO(err);
  CHECK(err.empty());
  const auto textures = read_json(files.sidecar).at("textures");
  REQUIRE(textures.size() == files.textures.size());
  std::vector<std::pair<std::string, std::string>> samplers;
  for (size_t k = 0; k < files.textures.size(); ++k)
    samplers.emplace_back(textures[k].at("sampler").get<std::string>(), files.textures[k]);
  const double worst = bf_test::glsl_run_error(
      files.glsl, pairs(200), samplers, [&](const Vec3& wi, const Vec3& wo) { return f.eval(wi, wo); }, dir);
  INFO(f.to_string() << ": worst relative |GLSL - eval| " << worst);
  CHECK(worst < tol);
}

}  // namespace

TEST_CASE("baseline export: SVD reloads exactly, textures hold the factors, GLSL compiles and runs as eval") {
  const Ward brdf = make_ward(0.2, 0.35);
  for (const bool log : {false, true})
    for (const Parameterization param : {Parameterization::WiWo, Parameterization::HalfDiff}) {
      TempDir dir("svd_export");
      SvdOptions o;
      o.param = param;
      o.res = 10;
      o.rank = 3;
      o.log = log;
      o.subtract_eps = log;
      const auto f = fit_svd(brdf, o);
      const BaselineExportFiles files = write_baseline_export(*f, dir.path.string(), "factors");
      check_reload(*f, files.sidecar);
      // rows.exr pixel (k*R + i, j), channel c = float(u_ck(i, j)).
      const FloatImage rows = read_exr_rgb(files.textures.at(0));
      REQUIRE(rows.width == 3 * 10);
      REQUIRE(rows.height == 10);
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) {
          const auto u = f->row_texture(c, k);
          for (int t = 0; t < 100; ++t)
            REQUIRE(rows.pixels[(size_t(t / 10) * 30 + k * 10 + t % 10) * 3 + c] == float(u[t]));
        }
      const auto j = read_json(files.sidecar);
      CHECK(j.at("method") == "svd");
      CHECK(j.at("format") == "brdf-factor-factorization");
      check_glsl(*f, files, dir.path, 1e-4);  // measured at most 2.5e-6
    }
}

TEST_CASE("baseline export: SH-K full and reduced reload exactly, GLSL compiles and runs as eval") {
  for (const bool reduced : {false, true}) {
    TempDir dir("shk_export");
    const Ward brdf = make_ward(0.25, reduced ? 0.25 : 0.4);
    ShkOptions o;
    o.order = 4;
    o.view_res = 8;
    o.reduced = reduced;
    const auto f = fit_shk(brdf, o);
    const BaselineExportFiles files = write_baseline_export(*f, dir.path.string(), "factors");
    check_reload(*f, files.sidecar);
    const FloatImage img = read_exr_rgb(files.textures.at(0));
    const int N = sh_count(4), T = read_json(files.sidecar).at("tiles_per_row").get<int>();
    CHECK(T == 5);
    if (!reduced) {
      // Coefficient i is the 8x8 tile at ((i % T) * 8, (i / T) * 8).
      for (int i = 0; i < N; ++i) {
        const auto tex = f->texture(1, i);
        for (int t = 0; t < 64; ++t) {
          const size_t x = size_t(i % T) * 8 + t % 8, y = size_t(i / T) * 8 + t / 8;
          REQUIRE(img.pixels[(y * img.width + x) * 3 + 1] == float(tex[t]));
        }
      }
    } else {
      REQUIRE(img.width == 8);
      REQUIRE(img.height == N);
      CHECK(img.pixels[(size_t(3) * 8 + 5) * 3 + 2] == float(f->coefficients(2)(3, 5)));
    }
    // Measured 1.6e-5 (full), 3.9e-4 (reduced: wi turned by -phi_v in float).
    check_glsl(*f, files, dir.path, 1e-3);
  }
}

TEST_CASE("baseline export: SH-R reloads exactly, GLSL compiles and runs as eval") {
  TempDir dir("shr_export");
  const Ward brdf = make_ward(0.3, 0.3);
  ShrOptions o;
  o.max_order = 12;
  o.max_view_order = 3;
  o.order = 10;
  o.view_order = 2;
  const auto f = fit_shr(brdf, o);
  const BaselineExportFiles files = write_baseline_export(*f, dir.path.string(), "factors");
  CHECK(files.textures.empty());
  check_reload(*f, files.sidecar);
  // The data block's order: q = 0..min(F, P), l = q..F, p = q..P.
  std::ifstream in(files.data, std::ios::binary);
  std::vector<double> v(3 * shr_coefficient_count(10, 2));
  in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * 8));
  REQUIRE(in);
  const size_t M = shr_coefficient_count(10, 2);
  // q = 0 block: l = 0..10, p = 0..2 (33 values); then q = 1: l = 1..10, p = 1..2.
  CHECK(v[0 * M + 3 * 4 + 1] == f->coefficient(0, 4, 1, 0));
  CHECK(v[1 * M + 33 + 2 * 2 + 1] == f->coefficient(1, 3, 2, 1));
  check_glsl(*f, files, dir.path, 3e-4);  // measured 3.5e-5 (float32 sum of the series)
}

TEST_CASE("baseline export: damaged exports are refused naming file and field") {
  TempDir dir("bad_export");
  SvdOptions o;
  o.res = 8;
  o.rank = 2;
  const auto f = fit_svd(make_ward(0.3, 0.3), o);
  const BaselineExportFiles files = write_baseline_export(*f, dir.path.string(), "factors");
  const std::string data = bf_test::slurp(files.data);
  {
    std::ofstream(files.data, std::ios::binary) << data.substr(0, data.size() - 8);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains("factors.f64") && Contains("bytes"));
  }
  {
    // A non-zero texel outside the disk grid's mask (texel 0 of u[0][0] is a corner).
    std::string bad = data;
    const auto j = read_json(files.sidecar);
    size_t off = 0;
    for (const auto& b : j.at("data").at("blocks"))
      if (b.at("name") == "u") off = b.at("offset").get<size_t>();
    const double one = 1.0;
    std::memcpy(&bad[off * 8], &one, 8);
    std::ofstream(files.data, std::ios::binary) << bad;
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains("u[0][0]") && Contains("mask"));
  }
  {
    std::ofstream(files.data, std::ios::binary) << data;
    auto j = read_json(files.sidecar);
    j["rank"] = 0;
    std::ofstream(files.sidecar) << j.dump();
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains("factors.json") && Contains("'rank'"));
    j["rank"] = 2;
    j["method"] = "svd2";
    std::ofstream(files.sidecar) << j.dump();
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains("'method'"));
  }
  CHECK_THROWS_WITH(write_baseline_export(*f, dir.path.string(), "a/b"), Contains("stem"));
}
