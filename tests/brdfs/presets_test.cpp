// Tests of the named presets: presence, pbrt-v1 bluepaint against its formula
// (also through the CLI), the Ngan 2005 tables as data/params/README.md reads
// them, and robustness to missing or malformed parameter tables.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/models.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

constexpr double kPresetDeg = M_PI / 180.0;

// pbrt-v1 Lafortune::f with bluepaint's numbers, typed from
// pbrt_v1_lafortune_materials.csv (per channel):
//   f = rho_d/pi + sum_k pow+(Cxy_k (wo.x wi.x + wo.y wi.y) + Cz_k wo.z wi.z, n_k).
Rgb bluepaint_by_hand(const Vec3& wi, const Vec3& wo) {
  const double rho_d[3] = {0.3094, 0.39667, 0.70837};
  const double cxy[3][3] = {{0.870567, 0.857255, 0.670982},
                            {-0.451218, -0.406681, -0.477976},
                            {-1.031545, -1.029426, -1.026588}};
  const double cz[3][3] = {{0.803624, 0.774290, 0.586674},
                           {0.023123, 0.017625, 0.227295},
                           {0.706734, 0.696530, 0.687715}};
  const double n[3][3] = {{21.820103, 18.597755, 7.472717},
                          {2.774499, 2.581499, 3.677653},
                          {66.899060, 63.767912, 57.489181}};
  Rgb f;
  for (int c = 0; c < 3; ++c) {
    f[c] = rho_d[c] / M_PI;
    for (int k = 0; k < 3; ++k) {
      const double v = cxy[k][c] * (wo.x() * wi.x() + wo.y() * wi.y()) + cz[k][c] * wo.z() * wi.z();
      if (v > 0) f[c] += std::pow(v, n[k][c]);
    }
  }
  return f;
}

// Pairs: normal, retro-reflective (wi = wo) at two angles, mirror, generic, grazing.
std::vector<std::pair<Vec3, Vec3>> test_pairs() {
  return {{from_spherical(0, 0), from_spherical(0, 0)},
          {from_spherical(60 * kPresetDeg, 0.5), from_spherical(60 * kPresetDeg, 0.5)},
          {from_spherical(80 * kPresetDeg, 2.0), from_spherical(80 * kPresetDeg, 2.0)},
          {from_spherical(35 * kPresetDeg, 1.0), from_spherical(35 * kPresetDeg, 1.0 + M_PI)},
          {from_spherical(20 * kPresetDeg, 0.3), from_spherical(55 * kPresetDeg, 2.1)},
          {from_spherical(89.99 * kPresetDeg, 0.0), from_spherical(70 * kPresetDeg, M_PI)}};
}

bool rel_equal_rgb(const Rgb& a, const Rgb& b, double tol) {
  return ((a - b).abs() <= tol * a.abs().max(b.abs())).all();
}

std::string params_dir() {
  return data_dir() + "/params";
}


std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

TEST_CASE("presets: pbrt-v1 and Ngan presets exist when the data folder is present") {
  const Catalogue& cat = Catalogue::builtin();
  CHECK(cat.presets().count("cole-cook-torrance"));
  if (!fs::exists(params_dir() + "/pbrt_v1_lafortune_materials.csv")) {
    WARN("no " << params_dir() << "/pbrt_v1_lafortune_materials.csv: pbrt-v1 presets not checked");
  } else {
    for (const char* name : {"bluepaint", "clay", "felt", "primer", "skin", "brushedmetal"}) {
      INFO(name);
      REQUIRE(cat.presets().count(name));
      CHECK(cat.presets().at(name).model == "lafortune");
    }
  }
  const std::vector<std::pair<std::string, std::string>> ngan = {
      {"ngan2005_ward.csv", "ngan-ward/"},
      {"ngan2005_wardduer.csv", "ngan-ward-duer/"},
      {"ngan2005_blinnphong.csv", "ngan-blinn-phong/"},
      {"ngan2005_cooktorrance.csv", "ngan-cook-torrance/"},
      {"ngan2005_ashikhminshirley.csv", "ngan-ashikhmin-shirley/"},
      {"ngan2005_lafortune.csv", "ngan-lafortune/"}};
  for (const auto& [file, prefix] : ngan) {
    if (!fs::exists(params_dir() + "/" + file)) {
      WARN("no " << params_dir() << "/" << file << ": " << prefix << "* not checked");
      continue;
    }
    int count = 0;
    for (const auto& [name, p] : cat.presets()) count += name.rfind(prefix, 0) == 0;
    INFO(prefix);
    CHECK(count == 86);
    CHECK(cat.presets().count(prefix + "blue-acrylic"));
  }
}

TEST_CASE("presets: bluepaint evaluates pbrt-v1's Lafortune::f exactly") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  // wi = wo = n by hand: rho_d/pi + Cz0^n0 + Cz1^n1 + Cz2^n2.
  CHECK(rel_equal_rgb(b->eval(Vec3(0, 0, 1), Vec3(0, 0, 1)),
                  Rgb(0.10699103296563059, 0.13488097049596426, 0.24837474482344285), 1e-14));
  for (const auto& [wi, wo] : test_pairs()) {
    INFO("wi = " << wi.transpose() << ", wo = " << wo.transpose());
    CHECK(rel_equal_rgb(b->eval(wi, wo), bluepaint_by_hand(wi, wo), 1e-13));
    CHECK(rel_equal_rgb(b->eval(wo, wi), bluepaint_by_hand(wi, wo), 1e-13));
  }
  // Retro-reflection: lobe 0 (Cxy > 0) contributes v0^n0 ~ 0.03 at wi = wo.
  const Vec3 w = from_spherical(60 * kPresetDeg, 0.5);
  const double v0 = 0.870567 * (w.x() * w.x() + w.y() * w.y()) + 0.803624 * w.z() * w.z();
  CHECK(std::pow(v0, 21.820103) > 0.02);
  CHECK(b->eval(w, w)[0] >= (0.3094 / M_PI + std::pow(v0, 21.820103)) * (1 - 1e-12));
}

TEST_CASE("presets: brdf-factor eval --brdf bluepaint matches pbrt-v1's formula") {
  for (const auto& [wi, wo] : test_pairs()) {
    char cmd[512];
    std::snprintf(cmd, sizeof cmd,
                  "\"%s\" eval --brdf bluepaint --wi=%.17g,%.17g,%.17g --wo=%.17g,%.17g,%.17g",
                  BF_CLI_PATH, wi.x(), wi.y(), wi.z(), wo.x(), wo.y(), wo.z());
    INFO(cmd);
    FILE* p = popen(cmd, "r");
    REQUIRE(p != nullptr);
    double r = -1, g = -1, b = -1;
    const int got = std::fscanf(p, "%lf %lf %lf", &r, &g, &b);
    const int status = pclose(p);
    REQUIRE(status == 0);
    REQUIRE(got == 3);
    // The CLI prints 10 significant digits.
    CHECK(rel_equal_rgb(Rgb(r, g, b), bluepaint_by_hand(wi, wo), 1e-9));
  }
}

TEST_CASE("presets: Ngan 2005 tables evaluate as data/params/README.md states") {
  const Catalogue& cat = Catalogue::builtin();
  if (!fs::exists(params_dir() + "/ngan2005_ward.csv")) {
    WARN("no Ngan tables in " << params_dir());
    return;
  }
  // blue-acrylic rows, typed from the CSVs. Mirror pair at 30 deg: h = n.
  const double t = 30 * kPresetDeg, c = std::cos(t);
  const Vec3 wi = from_spherical(t, 0.4), wo = from_spherical(t, 0.4 + M_PI);
  auto schlick = [](double f0, double cd) { return f0 + (1 - f0) * std::pow(1 - cd, 5); };
  {
    const Rgb kd(0.0138, 0.0326, 0.0636), rho(0.00774, 0.00547, 0.00339);
    const double a = 0.0162;
    CHECK(rel_equal_rgb(cat.make("ngan-ward/blue-acrylic")->eval(wi, wo),
                    kd / M_PI + rho / (4 * M_PI * a * a * c), 1e-13));
  }
  {
    const Rgb kd(0.0137, 0.0326, 0.0637), rho(0.00534, 0.00364, 0.00224);
    const double a = 0.0162;
    CHECK(rel_equal_rgb(cat.make("ngan-ward-duer/blue-acrylic")->eval(wi, wo),
                    kd / M_PI + rho / (4 * M_PI * a * a * c * c), 1e-13));
  }
  {
    // Half vector, (n+2)/(2 pi): at h = n, and with h tilted by 0.005 rad
    // (the mirror-vector reading would give cos^n(0.01) = 0.50 instead of 0.84).
    const Rgb kd(0.0147, 0.0332, 0.064), rho(0.0016, 0.00115, 0.000709);
    const double n = 13700.0;
    const BrdfPtr b = cat.make("ngan-blinn-phong/blue-acrylic");
    CHECK(rel_equal_rgb(b->eval(wi, wo), kd / M_PI + rho * (n + 2) / (2 * M_PI), 1e-13));
    const Vec3 a1 = from_spherical(0.305, 0.0), a2 = from_spherical(0.295, M_PI);
    CHECK(rel_equal_rgb(b->eval(a1, a2),
                    kd / M_PI + rho * (n + 2) / (2 * M_PI) * std::pow(std::cos(0.005), n), 1e-9));
  }
  {
    // eta column = Schlick F0; D = 1/(pi m^2) at h = n, G = 1: rho F / (pi^2 m^2 c^2).
    const Rgb kd(0.0143, 0.033, 0.0639), rho(0.0291, 0.0193, 0.0118);
    const double m = 0.0137, F = schlick(0.117, c);
    CHECK(rel_equal_rgb(cat.make("ngan-cook-torrance/blue-acrylic")->eval(wi, wo),
                    kd / M_PI + rho * F / (M_PI * M_PI * m * m * c * c), 1e-12));
  }
  {
    const Rgb kd(0.0143, 0.0331, 0.0639), rho(0.0366, 0.0241, 0.0147);
    const double n = 11600.0, F = schlick(0.0949, c);
    CHECK(rel_equal_rgb(cat.make("ngan-ashikhmin-shirley/blue-acrylic")->eval(wi, wo),
                    kd / M_PI + rho * (n + 1) / (8 * M_PI) * F / (c * c), 1e-12));
  }
  {
    // Cxy = -0.577, Cz = 0.577: at the mirror pair the lobe argument is 0.577,
    // and Ngan's 1/max(Cz^2, Cxy^2)^(n/2) makes it (n+2)/(2 pi).
    const Rgb kd(0.0145, 0.0332, 0.064), rho(0.0238, 0.0164, 0.01);
    const double n = 4060.0;
    CHECK(rel_equal_rgb(cat.make("ngan-lafortune/blue-acrylic")->eval(wi, wo),
                    kd / M_PI + rho * (n + 2) / (2 * M_PI), 1e-12));
  }
}

TEST_CASE("presets: cole-cook-torrance is Foley's Cook-Torrance with the thesis parameters") {
  const BrdfPtr b = Catalogue::builtin().make("cole-cook-torrance");
  CHECK(b->to_string() ==
        "cook-torrance(kd=0.1, ks=0.9, m=0.3, fresnel=schlick, f0=0.1, form=foley)");
  // Preset values can be overridden like any model's.
  const BrdfPtr rough = Catalogue::builtin().make("cole-cook-torrance:m=0.5");
  CHECK(rough->to_string() ==
        "cook-torrance(kd=0.1, ks=0.9, m=0.5, fresnel=schlick, f0=0.1, form=foley)");
}

TEST_CASE("presets: a missing data folder leaves the catalogue working") {
  Catalogue cat;
  register_analytic_models(cat);
  REQUIRE_NOTHROW(register_presets_from(cat, "/nonexistent/brdf-factor/params"));
  CHECK(cat.presets().size() == 1);  // cole-cook-torrance only
  CHECK(cat.make("cole-cook-torrance")->eval(Vec3(0, 0, 1), Vec3(0, 0, 1))[0] ==
        Approx(0.35 / M_PI));
  CHECK_THROWS_WITH(cat.make("bluepaint"), Contains("unknown BRDF 'bluepaint'"));
  // One table present, the others missing.
  const bf_test::TempDir dir("presets");
  dir.write("ngan2005_ward.csv",
            "material,kd_r,kd_g,kd_b,albedo_r,albedo_g,albedo_b,roughness\n"
            "test-mat,0.1,0.2,0.3,0.01,0.02,0.03,0.1\n");
  Catalogue cat2;
  register_analytic_models(cat2);
  register_presets_from(cat2, dir.path.string());
  CHECK(cat2.presets().size() == 2);
  CHECK(cat2.make("ngan-ward/test-mat")->to_string() ==
        "ward(kd=0.1/0.2/0.3, ks=0.01/0.02/0.03, ax=0.1, ay=0.1, variant=ward)");
}

TEST_CASE("presets: a malformed table is an error naming file, line and rule") {
  const bf_test::TempDir dir("presets");
  const std::string ward_header = "material,kd_r,kd_g,kd_b,albedo_r,albedo_g,albedo_b,roughness\n";
  auto load = [&] {
    Catalogue cat;
    register_presets_from(cat, dir.path.string());
  };
  const std::string path = (dir.path / "ngan2005_ward.csv").string();

  dir.write("ngan2005_ward.csv", ward_header + "a,0.1,0.2,0.3,0.01,0.02,0.03,0.1\nb,0.1,0.2\n");
  CHECK_THAT(error_of(load), Contains(path + ":3: expected 8 fields as in the header, found 3"));

  dir.write("ngan2005_ward.csv", ward_header + "a,0.1,0.2,0.3,0.01,0.02,0.03,rough\n");
  CHECK_THAT(error_of(load),
             Contains(path + ":2: column 'roughness': expected a finite number, found 'rough'"));

  dir.write("ngan2005_ward.csv",
            "material,kd_r,kd_g,kd_b,albedo_r,albedo_g,albedo_b,alpha\n"
            "a,0.1,0.2,0.3,0.01,0.02,0.03,0.1\n");
  CHECK_THAT(error_of(load), Contains(path + ":1: expected a column 'roughness' in the header"));

  dir.write("ngan2005_ward.csv", ward_header +
                                     "a,0.1,0.2,0.3,0.01,0.02,0.03,0.1\n"
                                     "a,0.1,0.2,0.3,0.01,0.02,0.03,0.2\n");
  CHECK_THAT(error_of(load), Contains(path + ":3: second row for material 'a'"));
  fs::remove(dir.path / "ngan2005_ward.csv");

  const std::string pbrt = (dir.path / "pbrt_v1_lafortune_materials.csv").string();
  dir.write("pbrt_v1_lafortune_materials.csv",
            "material,lobe,param,r,g,b\nm,diffuse,rho_d,0.1,0.1,0.1\nm,0,Cxy,-1,-1,-1\n"
            "m,0,Cz,1,1,1\n");
  CHECK_THAT(error_of(load), Contains(pbrt + ":2: m lobe 0 has no n row"));
  dir.write("pbrt_v1_lafortune_materials.csv",
            "material,lobe,param,r,g,b\nm,diffuse,rho_d,0.1,0.1,0.1\nm,1,Cxy,-1,-1,-1\n"
            "m,1,Cz,1,1,1\nm,1,n,2,2,2\n");
  CHECK_THAT(error_of(load), Contains("missing lobe 0"));
  // A well-formed long table builds a preset whose values pbrt-v1 would compute.
  dir.write("pbrt_v1_lafortune_materials.csv",
            "material,lobe,param,r,g,b\nm,diffuse,rho_d,0.1,0.2,0.3\nm,0,Cxy,-1,-1,-1\n"
            "m,0,Cz,1,1,1\nm,0,n,2,3,4\n");
  Catalogue cat;
  register_analytic_models(cat);
  register_presets_from(cat, dir.path.string());
  CHECK(cat.make("m")->to_string() ==
        "lafortune(rho_d=0.1/0.2/0.3, cxy0=-1, cz0=1, n0=2/3/4, normalization=none)");
}
