// The report's WebGL2 viewer, run in headless Chromium (Debian's chromium,
// software rendering through SwiftShader): for every method kind with GLSL,
// the viewer's sphere radiance of the approximation equals the CPU sphere
// render of the run's export, its slices equal `eval` of the export, and its
// original panel (the page's tabulation) is close to the CPU render and eval
// of the BRDF; under SH lighting the page shades as render_sphere, also with
// the environment turned by a dragged light. Kinds: every registered kind
// with a viewer (MethodKind::has_viewer) from its example, and svd (halfdiff,
// log), sh-k (reduced and full), model-fit (lafortune).
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <nlohmann/json.hpp>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "experiments/config/config.h"
#include "experiments/methods/method_kind.h"
#include "experiments/report/render.h"
#include "factor/lighting.h"
#include "experiments_helpers.h"
#include "solvers/quadrature.h"

using namespace bf;
using namespace bf_test;

namespace {

// Every registered kind with a viewer, from its example, plus variants that
// take other paths through the shaders (halfdiff log SVD, both SH-K layouts,
// Lafortune lobes).
std::string viewer_config() {
  std::string cfg = R"(
[experiment]
name = "viewer"
seed = 3

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[scene]
size = 40
)";
  for (const auto& kind : method_kinds())
    if (kind->has_viewer()) cfg += "\n[[method]]\nkind = \"" + kind->name() + "\"\n" + kind->example();
  return cfg + R"(
[[method]]
kind = "svd"
parameterization = "halfdiff"
log = true
terms = 2
texture_size = 10

[[method]]
kind = "sh-k"
order = 4
texture_size = 8
reduce_isotropic = [true, false]

[[method]]
kind = "model-fit"
model = "lafortune"
starts = 1
max_iterations = 30
threads = 1
)";
}

// Directional albedo by the page's rule (Gauss-Legendre 64 x 128 on the
// upper hemisphere, solvers/quadrature.h): sum_k w_k z_k f(s_k, wo), wo at
// theta_o in the x-z plane (phi_o = 0). The page's theta_o checked: 0.5, 45.5
// and 89.5 deg (normal, middle, grazing).
constexpr int kAlbedoChecked[] = {0, 45, 89};
Rgb albedo(const Brdf& f, double theta_o) {
  static const SphereRule rule = sphere_rule(64, 128, 0.0, 1.0);
  const Vec3 wo(std::sin(theta_o), 0, std::cos(theta_o));
  Rgb a = Rgb::Zero();
  for (size_t k = 0; k < rule.size(); ++k) a += rule.w[k] * rule.dir[k].z() * f.eval(rule.dir[k], wo);
  return a;
}

// The torus of the viewer's shape menu, found here independently of the
// page's sphere tracing: ring radius 0.62, tube 0.32, its axis the camera's z
// turned 30 deg about x. The orthographic ray through (px, py) towards -z is
// stepped in t = 0..4 by 1e-3 until the implicit function changes sign, then
// bisected. Returns false on a miss; else the point and outward normal.
bool torus_hit(double px, double py, Vec3& pos, Vec3& nrm) {
  const double R = 0.62, T = 0.32, c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const auto to_local = [&](const Vec3& p) { return Vec3(p.x(), c * p.y() + s * p.z(), -s * p.y() + c * p.z()); };
  const auto from_local = [&](const Vec3& p) { return Vec3(p.x(), c * p.y() - s * p.z(), s * p.y() + c * p.z()); };
  const auto F = [&](double t) {
    const Vec3 q = to_local(Vec3(px, py, 2.0 - t));
    return std::hypot(std::hypot(q.x(), q.y()) - R, q.z()) - T;
  };
  double a = 0, fa = F(0);
  for (double t = 1e-3; t <= 4.0; t += 1e-3) {
    const double ft = F(t);
    if (fa > 0 && ft <= 0) {
      double lo = a, hi = t;
      for (int k = 0; k < 60; ++k) (F(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
      const Vec3 q = to_local(Vec3(px, py, 2.0 - hi));
      const double rho = std::hypot(q.x(), q.y());
      const Vec3 core(q.x() * R / rho, q.y() * R / rho, 0.0);
      pos = from_local(q);
      nrm = from_local((q - core).normalized());
      return true;
    }
    a = t;
    fa = ft;
  }
  return false;
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

TEST_CASE("viewer: headless Chromium renders every kind as the CPU does") {
  const std::string browser = chromium_browser();
  // Installed by scripts/install-deps.sh: missing, the test fails.
  INFO("chromium not installed (scripts/install-deps.sh installs it)");
  REQUIRE(!browser.empty());
  ScratchDir dir;
  const std::string cfg = write_text(dir / "viewer.toml", viewer_config());
  const RunSummary s = run_quiet(cfg, dir / "out");
  REQUIRE(s.failed == 0);
  const std::string page = dir / "out/report.html";
  const std::string html = read_text(page);
  REQUIRE(html.find("id=\"viewer\"") != std::string::npos);
  const std::string out = viewer_test_output(browser, page, dir.path.string());
  REQUIRE(!out.empty());
  std::istringstream lines(out);
  std::string line;
  int runs = 0, drags = 0, phids = 0, carts = 0;
  std::set<std::string> shown;  // kinds the page drew
  std::map<std::string, std::string> kind_of;  // run id -> the results' method column
  for (const Row& row : read_results_csv(dir / "out/results.csv")) kind_of[row.at("run_id")] = row.at("method");
  register_loaders();
  const BrdfPtr original = Catalogue::global().make("bluepaint");
  SceneSettings scene;
  scene.size = 40;
  const SphereRender orig_cpu = render_sphere(*original, scene);
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    if (j.contains("drag")) {
      // The drag through the page's handlers (point light: no environment).
      const auto& d = j.at("drag");
      INFO(d.dump());
      CHECK(d.at("status").get<std::string>().empty());  // draw() ran without error
      const Vec3 light(d.at("light")[0].get<double>(), d.at("light")[1].get<double>(), d.at("light")[2].get<double>());
      const double dist = SceneSettings{}.light.norm();
      CHECK((light - dist * Vec3(0.3, 0.4, std::sqrt(0.75))).norm() < 1e-3 * dist);
      CHECK(d.at("info").get<std::string>().find("point light") != std::string::npos);
      ++drags;
      continue;
    }
    if (j.contains("phid")) {
      // The phi_d slider moved to 30 deg through its handler: the label and
      // the slice canvas change, and the page's slice is eval of the export
      // at phi_d = 30 deg (the same 16 x 16 nodes as the phi_d = 90 check).
      const auto& p = j.at("phid");
      CHECK(p.at("status").get<std::string>().empty());
      CHECK(p.at("label").get<std::string>() == "30");
      CHECK(p.at("phi_d").get<double>() == Approx(M_PI / 6).epsilon(1e-9));
      CHECK(p.at("canvas_after").get<double>() != p.at("canvas_before").get<double>());
      const std::string run_dir = dir / ("out/runs/" + p.at("run").get<std::string>());
      const BrdfPtr approx = Catalogue::global().make(run_dir + (std::filesystem::exists(run_dir + "/model.json")
                                                                     ? "/model.json"
                                                                     : "/factors.json"));
      const auto gv = p.at("slice").get<std::vector<double>>();
      std::vector<double> ref, ref90;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          for (const double pd : {M_PI / 6, M_PI / 2}) {
            const double th = M_PI / 2 * (x + 0.5) / 16, td = M_PI / 2 * (15 - y + 0.5) / 16;
            const Vec3 h(std::sin(th), 0, std::cos(th));
            const Vec3 d(std::sin(td) * std::cos(pd), std::sin(td) * std::sin(pd), std::cos(td));
            const Vec3 wi(std::cos(th) * d.x() + std::sin(th) * d.z(), d.y(),
                          -std::sin(th) * d.x() + std::cos(th) * d.z());
            const Vec3 wo = 2 * wi.dot(h) * h - wi;
            const Rgb f = approx->eval(wi.normalized(), wo.normalized());
            for (int c = 0; c < 3; ++c) (pd < 1 ? ref : ref90).push_back(f[c]);
          }
      REQUIRE(gv.size() == ref.size());
      double w = 0, moved = 0;
      for (size_t i = 0; i < ref.size(); ++i) {
        w = std::max(w, std::abs(gv[i] - ref[i]));
        moved = std::max(moved, std::abs(ref[i] - ref90[i]));
      }
      INFO("phi_d slice: worst |gpu - eval| = " << w << " of peak " << max_abs(ref) << "; phi_d 90 -> 30 moves eval by "
                                               << moved);
      CHECK(moved > 0.01 * max_abs(ref));  // the slider's change is visible in eval
      CHECK(w <= 3e-3 * max_abs(ref));
      ++phids;
      continue;
    }
    if (j.contains("compare") || j.contains("torus")) continue;  // checked in the compare test below
    if (j.contains("cart")) {
      // The theta_i slider moved to 50 deg and the channel to G through their
      // handlers: the Cartesian slices as plotted (the canvases' data-series)
      // are eval of the export (approximation) and of the BRDF (original,
      // from the page's tabulation) at theta_i = 50 deg, in the incidence
      // plane (wo along x) and normal to it (wo along y); the albedo plot's
      // curves are the G channel of the quadrature.
      const auto& c = j.at("cart");
      CHECK(c.at("status").get<std::string>().empty());
      CHECK(c.at("label").get<std::string>() == "50");
      const double ti = c.at("theta_i").get<double>();
      CHECK(ti == Approx(50 * M_PI / 180).epsilon(1e-9));
      const std::string run_dir = dir / ("out/runs/" + c.at("run").get<std::string>());
      const BrdfPtr approx = Catalogue::global().make(run_dir + (std::filesystem::exists(run_dir + "/model.json")
                                                                     ? "/model.json"
                                                                     : "/factors.json"));
      const Vec3 wi(std::sin(ti), 0, std::cos(ti));
      for (const auto& [key, out] : {std::pair{"in_plane", false}, std::pair{"out_of_plane", true}}) {
        const auto& series = c.at(key);
        REQUIRE(series.size() == 2);
        for (const auto& sr : series) {
          const bool orig = sr.at("label").get<std::string>() == "original";
          CHECK((orig || sr.at("label").get<std::string>() == "approximation"));
          const auto xs = sr.at("x").get<std::vector<double>>(), ys = sr.at("y").get<std::vector<double>>();
          REQUIRE(xs.size() == ys.size());
          REQUIRE(xs.size() > 100);
          std::vector<double> ref;
          double w = 0;
          for (size_t k = 0; k < xs.size(); ++k) {
            const double to = xs[k] * M_PI / 180;
            const Vec3 wo = out ? Vec3(0, std::sin(to), std::cos(to)) : Vec3(std::sin(to), 0, std::cos(to));
            ref.push_back((orig ? *original : *approx).eval(wi, wo)[1]);
            w = std::max(w, std::abs(ys[k] - ref.back()));
          }
          INFO(key << " " << sr.at("label") << ": worst |page - eval| = " << w << " of peak " << max_abs(ref));
          CHECK(max_abs(ref) > 0);
          // The original is the page's tabulation: 1% of its peak (as the lobe above).
          CHECK(w <= (orig ? 1e-2 : 3e-3) * max_abs(ref));
        }
      }
      const auto& ap = c.at("albedo_plot");
      REQUIRE(ap.size() == 2);
      for (const auto& sr : ap) {
        const bool orig = sr.at("label").get<std::string>() == "original";
        const auto xs = sr.at("x").get<std::vector<double>>(), ys = sr.at("y").get<std::vector<double>>();
        REQUIRE(xs.size() == 90);
        REQUIRE(ys.size() == 90);
        double w = 0;
        for (const int k : kAlbedoChecked) {
          CHECK(xs[k] == Approx((k + 0.5)).epsilon(1e-9));
          w = std::max(w, std::abs(ys[k] - albedo(orig ? *original : *approx, xs[k] * M_PI / 180)[1]));
        }
        INFO("albedo plot " << sr.at("label") << ": worst |page - quadrature| = " << w);
        CHECK(w <= (orig ? 1e-2 : 1e-3));
      }
      CHECK(c.at("albedo_note").get<std::string>().find("albedo") != std::string::npos);
      ++carts;
      continue;
    }
    const std::string id = j.at("run");
    INFO("run " << id << " " << (j.contains("error") ? j["error"].get<std::string>() : ""));
    REQUIRE(!j.contains("error"));
    ++runs;
    shown.insert(kind_of.at(id));
    // The run's export: factors.json, or model.json for a model fit.
    const std::string run_dir = dir / ("out/runs/" + id);
    const BrdfPtr approx = Catalogue::global().make(run_dir + (std::filesystem::exists(run_dir + "/model.json")
                                                                   ? "/model.json"
                                                                   : "/factors.json"));
    INFO(approx->to_string());
    // Sphere radiance: every pixel within 1e-3 of the render's peak radiance.
    const SphereRender cpu = render_sphere(*approx, scene);
    const auto gpu = j.at("approx").get<std::vector<double>>();
    REQUIRE(gpu.size() == size_t(40 * 40 * 3));
    std::vector<double> ref(gpu.size());
    for (size_t k = 0; k < cpu.L.size(); ++k)
      for (int c = 0; c < 3; ++c) ref[3 * k + c] = cpu.L[k][c];
    const double peak = max_abs(ref);
    REQUIRE(peak > 0);
    double worst = 0;
    for (size_t i = 0; i < ref.size(); ++i) worst = std::max(worst, std::abs(gpu[i] - ref[i]));
    INFO("sphere: worst |gpu - cpu| = " << worst << " of peak " << peak);
    CHECK(worst <= 1e-3 * peak);
    // Original panel: the 16^4 tabulation against the BRDF itself (mean error).
    const auto go = j.at("original").get<std::vector<double>>();
    double err = 0, sum = 0;
    for (size_t k = 0; k < orig_cpu.L.size(); ++k)
      for (int c = 0; c < 3; ++c) {
        err += std::abs(go[3 * k + c] - orig_cpu.L[k][c]);
        sum += std::abs(orig_cpu.L[k][c]);
      }
    INFO("original: mean |tabulated - exact| / mean = " << err / sum);
    CHECK(err <= 0.02 * sum);
    // theta_h - theta_d slice (16 x 16, phi_d = 90 deg) and in-plane lobe
    // (theta_i = 30 deg, 32 theta_o) against eval of the export.
    const auto slice = j.at("slice").get<std::vector<double>>();
    std::vector<double> sref;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const double th = M_PI / 2 * (x + 0.5) / 16, td = M_PI / 2 * (15 - y + 0.5) / 16;
        const Vec3 h(std::sin(th), 0, std::cos(th));
        const Vec3 d(0, std::sin(td), std::cos(td));  // phi_d = 90 deg
        const Vec3 wi(std::cos(th) * d.x() + std::sin(th) * d.z(), d.y(), -std::sin(th) * d.x() + std::cos(th) * d.z());
        const Vec3 wo = 2 * wi.dot(h) * h - wi;
        const Rgb f = approx->eval(wi.normalized(), wo.normalized());
        for (int c = 0; c < 3; ++c) sref.push_back(f[c]);
      }
    const auto lobe = j.at("lobe").get<std::vector<double>>();
    std::vector<double> lref;
    for (int x = 0; x < 32; ++x) {
      const double to = -M_PI / 2 + M_PI * (x + 0.5) / 32;
      const Rgb f = approx->eval(Vec3(std::sin(M_PI / 6), 0, std::cos(M_PI / 6)), Vec3(std::sin(to), 0, std::cos(to)));
      for (int c = 0; c < 3; ++c) lref.push_back(f[c]);
    }
    // The original's lobe from the page's tabulation against eval of the BRDF.
    {
      const auto lo = j.at("lobe_original").get<std::vector<double>>();
      std::vector<double> oref;
      for (int x = 0; x < 32; ++x) {
        const double to = -M_PI / 2 + M_PI * (x + 0.5) / 32;
        const Rgb f = original->eval(Vec3(std::sin(M_PI / 6), 0, std::cos(M_PI / 6)), Vec3(std::sin(to), 0, std::cos(to)));
        for (int c = 0; c < 3; ++c) oref.push_back(f[c]);
      }
      REQUIRE(lo.size() == oref.size());
      double w = 0;
      for (size_t i = 0; i < oref.size(); ++i) w = std::max(w, std::abs(lo[i] - oref[i]));
      INFO("original lobe: worst |tabulated - eval| = " << w << " of peak " << max_abs(oref));
      CHECK(w <= 0.01 * max_abs(oref));
    }
    // Directional albedo (90 theta_o at (k + 1/2) deg, phi_o = 0) against the
    // same quadrature of the export on the CPU, at kAlbedoChecked: 1e-3
    // (albedo is dimensionless, about 0..1). The original's curve from the
    // page's tabulation against the BRDF itself: 1e-2.
    // The page records them for its first run only (each curve is 0.7M
    // evaluations in software WebGL2).
    for (const auto& [key, brdf, tol] : {std::make_tuple("albedo", approx.get(), 1e-3),
                                         std::make_tuple("albedo_original", original.get(), 1e-2)}) {
      if (runs > 1) {
        CHECK(!j.contains(key));
        continue;
      }
      REQUIRE(j.contains(key));
      const auto a = j.at(key).get<std::vector<double>>();
      REQUIRE(a.size() == 90 * 3);
      double w = 0;
      for (const int k : kAlbedoChecked) {
        const Rgb ref = albedo(*brdf, (k + 0.5) * M_PI / 180);
        for (int c = 0; c < 3; ++c) w = std::max(w, std::abs(a[3 * k + c] - ref[c]));
      }
      INFO(kind_of.at(id) << " " << key << ": worst |page - CPU quadrature| = " << w);
      CHECK(w <= tol);
    }
    for (const auto& [gv, rv, what] : {std::make_tuple(slice, sref, "slice"), std::make_tuple(lobe, lref, "lobe")}) {
      REQUIRE(gv.size() == rv.size());
      const double pk = max_abs(rv);
      double w = 0;
      for (size_t i = 0; i < rv.size(); ++i) w = std::max(w, std::abs(gv[i] - rv[i]));
      INFO(what << ": worst |gpu - eval| = " << w << " of peak " << pk);
      // float32 sums on the GPU: SH-R's series (F 16, P 3) is off by 1.8e-3 of
      // its peak along the lobe, every other kind and slice by < 4e-4.
      CHECK(w <= 3e-3 * pk);
    }
  }
  CHECK(runs == int(s.executed));
  for (const auto& kind : method_kinds())
    if (kind->has_viewer()) {
      INFO(kind->name());
      CHECK(shown.count(kind->name()) == 1);
    }
  CHECK(drags == 1);
  CHECK(phids == 1);
  CHECK(carts == 1);
}

TEST_CASE("viewer: under the scene's SH lighting the page shades as render_sphere") {
  const std::string browser = chromium_browser();
  // Installed by scripts/install-deps.sh: missing, the test fails.
  INFO("chromium not installed (scripts/install-deps.sh installs it)");
  REQUIRE(!browser.empty());
  ScratchDir dir;
  const std::string cfg = write_text(dir / "env.toml", R"(
[experiment]
name = "viewer-env"
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 24
lighting_order = 4
[[method]]
kind = "mccool"
texture_size = 8
[[method]]
kind = "svd"
terms = 2
texture_size = 10
)");
  const RunSummary s = run_quiet(cfg, dir / "out");
  REQUIRE(s.failed == 0);
  const Plan plan = load_plan(cfg);
  REQUIRE(plan.scene.lighting);
  const std::string out = viewer_test_output(browser, dir / "out/report.html", dir.path.string());
  REQUIRE(!out.empty());
  std::istringstream lines(out);
  std::string line;
  int runs = 0, drags = 0;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    if (j.contains("drag")) {
      // The drag through the page's handlers: the light moves to
      // |light| (0.3, 0.4, sqrt(0.75)) and the environment turns by the
      // rotation taking the scene light's direction to it.
      const auto& d = j.at("drag");
      INFO(d.dump());
      CHECK(d.at("status").get<std::string>().empty());
      const Vec3 b = Vec3(0.3, 0.4, std::sqrt(0.75)), a = plan.scene.light.normalized();
      const Vec3 light(d.at("light")[0].get<double>(), d.at("light")[1].get<double>(), d.at("light")[2].get<double>());
      CHECK((light - plan.scene.light.norm() * b).norm() < 1e-3 * plan.scene.light.norm());
      const auto rv = d.at("env_rot").get<std::vector<double>>();
      REQUIRE(rv.size() == 9);
      Eigen::Matrix3d R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = rv[3 * r + c];
      CHECK((R * a - b).norm() < 1e-3);
      const int degrees = int(std::lround(std::acos(a.dot(b)) * 180 / M_PI));
      CHECK(d.at("info").get<std::string>().find("turned " + std::to_string(degrees) + " deg") != std::string::npos);
      ++drags;
      continue;
    }
    if (j.contains("phid") || j.contains("cart") || j.contains("compare") || j.contains("torus"))
      continue;  // checked in the tests above and below
    INFO("run " << j.at("run").get<std::string>());
    REQUIRE(!j.contains("error"));
    REQUIRE(j.contains("approx_env"));
    ++runs;
    const BrdfPtr approx = Catalogue::global().make(dir / ("out/runs/" + j.at("run").get<std::string>() + "/factors.json"));
    const SphereRender cpu = render_sphere(*approx, plan.scene);
    const auto gpu = j.at("approx_env").get<std::vector<double>>();
    REQUIRE(gpu.size() == cpu.L.size() * 3);
    double worst = 0, peak = 0;
    for (size_t k = 0; k < cpu.L.size(); ++k)
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(gpu[3 * k + c] - cpu.L[k][c]));
        peak = std::max(peak, std::abs(cpu.L[k][c]));
      }
    INFO(approx->to_string() << ": worst |gpu - cpu| = " << worst << " of peak " << peak);
    REQUIRE(peak > 0);
    // The page reads the band-limited lighting from a 128 x 64 lat-long grid
    // (bilinear) where the CPU evaluates the SH series: 2e-3 of the peak.
    CHECK(worst <= 2e-3 * peak);

    // The light dragged to direction b: the page turns the environment by the
    // smallest rotation R taking the scene light's direction a to b. Check R
    // (R a = b, a rotation about a x b), then the page's radiance against the
    // CPU render under the lighting rotated by R (L'(s) = L(R^T s), sh_rotate).
    REQUIRE(j.contains("env_rot"));
    const auto rv = j.at("env_rot").get<std::vector<double>>();
    REQUIRE(rv.size() == 9);
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = rv[3 * r + c];
    const Vec3 a = plan.scene.light.normalized(), b = Vec3(-0.4, 0.5, 0.75).normalized();
    CHECK((R * a - b).norm() < 1e-6);
    CHECK((R * a.cross(b) - a.cross(b)).norm() < 1e-6);
    CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6);
    CHECK(R.determinant() == Approx(1.0).epsilon(1e-6));
    ShLighting turned = *plan.scene.lighting;
    for (int c = 0; c < 3; ++c) turned.coeffs[c] = sh_rotate(R, turned.coeffs[c]);
    SceneSettings scene = plan.scene;
    scene.lighting = std::make_shared<const ShLighting>(turned);
    const SphereRender cpu_t = render_sphere(*approx, scene);
    const auto gpu_t = j.at("approx_env_turned").get<std::vector<double>>();
    REQUIRE(gpu_t.size() == cpu_t.L.size() * 3);
    double worst_t = 0, peak_t = 0, moved = 0;
    for (size_t k = 0; k < cpu_t.L.size(); ++k)
      for (int c = 0; c < 3; ++c) {
        worst_t = std::max(worst_t, std::abs(gpu_t[3 * k + c] - cpu_t.L[k][c]));
        peak_t = std::max(peak_t, std::abs(cpu_t.L[k][c]));
        moved = std::max(moved, std::abs(cpu_t.L[k][c] - cpu.L[k][c]));
      }
    INFO("turned environment: worst |gpu - cpu| = " << worst_t << " of peak " << peak_t
                                                     << "; the turn changes the render by " << moved);
    CHECK(moved > 0.1 * peak);  // the turn is visible
    CHECK(worst_t <= 2e-3 * peak_t);
  }
  CHECK(runs == 2);
  CHECK(drags == 1);
}

TEST_CASE("viewer: compare mode and a loaded .hdr map draw runs of two BRDFs as the CPU renders them") {
  const std::string browser = chromium_browser();
  INFO("chromium not installed (scripts/install-deps.sh installs it)");
  REQUIRE(!browser.empty());
  ScratchDir dir;
  const std::string cfg = write_text(dir / "cmp.toml", R"(
[experiment]
name = "viewer-compare"
[[brdf]]
preset = "bluepaint"
[[brdf]]
model = "blinn-phong"
n = 30
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 24
[[method]]
kind = "mccool"
texture_size = 8
)");
  const RunSummary s = run_quiet(cfg, dir / "out");
  REQUIRE(s.failed == 0);
  REQUIRE(s.executed == 2);
  const Plan plan = load_plan(cfg);
  register_loaders();
  // A small lat-long map beside the page: a smooth warm lobe towards
  // (0.3, -0.5, 0.8) over a dim blue sky (W = 32 x H = 16, RGBE).
  const Vec3 sun = Vec3(0.3, -0.5, 0.8).normalized();
  write_latlong(dir / "out/sky.hdr", make_latlong(32, 16, [&](const Vec3& w) {
                  const double d = std::pow(std::max(0.0, w.dot(sun)), 4.0);
                  return Rgb(0.2 + 3.0 * d, 0.25 + 2.0 * d, 0.4 + 1.0 * d);
                }));
  // The page loads it as a picked file (test hook "?hdr=sky.hdr": the bytes
  // read by a synchronous XMLHttpRequest, which a file:// page may do only
  // with --allow-file-access-from-files, go to the function the file input's
  // change handler calls with the FileReader's bytes; the FileReader itself is
  // asynchronous and would race the DOM dump).
  const std::string out = viewer_test_output(browser, dir / "out/report.html", dir.path.string(), "?hdr=sky.hdr",
                                             "--allow-file-access-from-files");
  REQUIRE(!out.empty());
  std::istringstream lines(out);
  std::string line;
  int compares = 0, hdrs = 0, tori = 0;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    if (j.contains("hdr")) {
      // Under the loaded map, band-limited at SH order 8 as the toolkit's
      // scene lighting: the CPU render with the map read by read_latlong and
      // projected by project_latlong at order 8 (LitShader's rule), against
      // the page's spheres: 2e-3 of the peak (the page reads the lighting from
      // a 128 x 64 grid, bilinearly, as under the scene's SH lighting).
      const auto& h = j.at("hdr");
      INFO(h.dump().substr(0, 400));
      CHECK(h.at("status").get<std::string>().empty());
      REQUIRE(h.at("loaded").get<bool>());
      CHECK(h.at("info").get<std::string>().find("lit by sky.hdr (32 x 16, SH order 8") != std::string::npos);
      SceneSettings scene = plan.scene;
      scene.lighting = std::make_shared<const ShLighting>(project_latlong(read_latlong(dir / "out/sky.hdr"), 8));
      int n = 0;
      for (const auto& [id, v] : h.at("runs").items()) {
        const BrdfPtr approx = Catalogue::global().make(dir / ("out/runs/" + id + "/factors.json"));
        const SphereRender cpu = render_sphere(*approx, scene);
        const auto gpu = v.get<std::vector<double>>();
        REQUIRE(gpu.size() == cpu.L.size() * 3);
        double worst = 0, peak = 0;
        for (size_t k = 0; k < cpu.L.size(); ++k)
          for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(gpu[3 * k + c] - cpu.L[k][c]));
            peak = std::max(peak, std::abs(cpu.L[k][c]));
          }
        INFO("run " << id << " under sky.hdr: worst |page - cpu| = " << worst << " of peak " << peak);
        REQUIRE(peak > 0);
        CHECK(worst <= 2e-3 * peak);
        ++n;
      }
      CHECK(n == 2);
      ++hdrs;
      continue;
    }
    if (j.contains("torus")) {
      // The shape menu set to the torus through its handler: the first run's
      // approximation on it under the scene's point light against the CPU:
      // the torus hit found by stepping and bisection, shaded with eval of
      // the export as render_sphere shades (I f(wi, wo) cos theta_i / d^2,
      // tangent x - (n.x) n). Pixels whose ray grazes the surface (|n.z| <
      // 0.1: the two hits disagree most there) are skipped; the mask may
      // differ on at most 2% of the torus's pixels (its silhouette).
      const auto& t = j.at("torus");
      CHECK(t.at("status").get<std::string>().empty());
      CHECK(t.at("info").get<std::string>().find("torus") != std::string::npos);
      const int n = t.at("size");
      const auto L = t.at("radiance").get<std::vector<double>>(), mask = t.at("mask").get<std::vector<double>>();
      REQUIRE(L.size() == size_t(n) * n * 3);
      const BrdfPtr approx = Catalogue::global().make(dir / ("out/runs/" + t.at("run").get<std::string>() + "/factors.json"));
      int hits = 0, differ = 0, compared = 0, holes = 0;
      double worst = 0, peak = 0;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const size_t k = size_t(y) * n + x;
          const double px = -1.0 + 2.0 * (x + 0.5) / n, py = 1.0 - 2.0 * (y + 0.5) / n;
          Vec3 P, N;
          const bool hit = torus_hit(px, py, P, N);
          holes += !hit && std::hypot(px, py) < 0.25;  // the ring's hole: the view passes through
          hits += hit;
          if (hit != (mask[k] > 0)) ++differ;
          if (!hit || mask[k] == 0 || std::abs(N.z()) < 0.1) continue;
          Vec3 tg = Vec3(1, 0, 0) - N.x() * N;
          tg.normalize();
          const Vec3 bt = N.cross(tg), tl = plan.scene.light - P;
          const Vec3 wiw = tl.normalized(), wow(0, 0, 1);
          Rgb ref = Rgb::Zero();
          if (wiw.dot(N) > 0)
            ref = plan.scene.intensity *
                  approx->eval(Vec3(wiw.dot(tg), wiw.dot(bt), wiw.dot(N)), Vec3(wow.dot(tg), wow.dot(bt), wow.dot(N))) *
                  wiw.dot(N) / tl.squaredNorm();
          for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(L[3 * k + c] - ref[c]));
            peak = std::max(peak, std::abs(ref[c]));
          }
          ++compared;
        }
      INFO("torus: " << hits << " pixels hit, mask differs on " << differ << ", compared " << compared
                     << ", worst |page - cpu| = " << worst << " of peak " << peak << ", hole pixels " << holes);
      CHECK(hits > n * n / 5);
      CHECK(holes > 0);  // a torus, not a disc
      CHECK(differ <= hits / 50);
      CHECK(compared > hits / 2);
      REQUIRE(peak > 0);
      CHECK(worst <= 1e-3 * peak);
      ++tori;
      continue;
    }
    if (!j.contains("compare")) continue;
    // The page ticked run 1's and run 2's approximations and run 2's BRDF
    // (blinn-phong, tabulated) through the checkboxes, after the drag moved
    // the shared light.
    const auto& c = j.at("compare");
    INFO(c.at("status").get<std::string>());
    CHECK(c.at("status").get<std::string>().empty());
    CHECK(!c.at("hidden").get<bool>());
    CHECK(c.at("spheres_drawn").get<int>() == 3);
    const auto& entries = c.at("entries");
    REQUIRE(entries.size() == 3);
    SceneSettings scene = plan.scene;
    scene.light = Vec3(c.at("light")[0].get<double>(), c.at("light")[1].get<double>(), c.at("light")[2].get<double>());
    CHECK((scene.light - plan.scene.light).norm() > 0.1);  // the dragged light, not the scene's
    const double ti = c.at("theta_i").get<double>();
    std::vector<BrdfPtr> brdfs;
    std::vector<std::vector<double>> cpu;
    for (size_t e = 0; e < entries.size(); ++e) {
      const std::string id = entries[e].at("id");
      const int which = entries[e].at("which");
      const std::string run_dir = dir / ("out/runs/" + id);
      size_t brdf = plan.brdfs.size();
      for (const Row& row : read_results_csv(dir / "out/results.csv"))
        if (row.at("run_id") == id)
          for (size_t b = 0; b < plan.brdfs.size(); ++b)
            if (plan.brdfs[b].label == row.at("brdf")) brdf = b;
      REQUIRE(brdf < plan.brdfs.size());
      CHECK(brdf == (e == 0 ? 0u : 1u));  // the page lists runs in plan order
      brdfs.push_back(which == 1 ? Catalogue::global().make(run_dir + "/factors.json") : plan.brdfs[brdf].brdf);
      CHECK(which == (e < 2 ? 1 : 0));
      const SphereRender r = render_sphere(*brdfs.back(), scene);
      std::vector<double> L;
      for (const Rgb& v : r.L)
        for (int ch = 0; ch < 3; ++ch) L.push_back(v[ch]);
      cpu.push_back(L);
      const auto gpu = c.at("spheres")[e].get<std::vector<double>>();
      REQUIRE(gpu.size() == L.size());
      double worst = 0, err = 0, sum = 0;
      for (size_t k = 0; k < L.size(); ++k) {
        worst = std::max(worst, std::abs(gpu[k] - L[k]));
        err += std::abs(gpu[k] - L[k]);
        sum += std::abs(L[k]);
      }
      INFO("entry " << e << " (" << id << ", which " << which << "): worst |page - cpu| = " << worst << " of peak "
                    << max_abs(L) << ", mean relative " << err / sum);
      REQUIRE(max_abs(L) > 0);
      // Approximations: the existing 1e-3 of the peak; the BRDF: its
      // tabulation, 2% mean (as the original panel).
      if (which == 1) CHECK(worst <= 1e-3 * max_abs(L));
      else CHECK(err <= 0.02 * sum);
    }
    // Two different BRDFs: their renders differ visibly.
    double apart = 0;
    for (size_t k = 0; k < cpu[0].size(); ++k) apart = std::max(apart, std::abs(cpu[0][k] - cpu[1][k]));
    CHECK(apart > 0.1 * max_abs(cpu[0]));
    // The difference image A - B (entries a = 0, b = 1) is the difference of
    // the two CPU renders: within the sum of both renders' tolerances.
    CHECK(c.at("a").get<int>() == 0);
    CHECK(c.at("b").get<int>() == 1);
    const auto diff = c.at("diff").get<std::vector<double>>();
    REQUIRE(diff.size() == cpu[0].size());
    double wd = 0;
    for (size_t k = 0; k < diff.size(); ++k) wd = std::max(wd, std::abs(diff[k] - (cpu[0][k] - cpu[1][k])));
    INFO("difference: worst |page - (cpu A - cpu B)| = " << wd);
    CHECK(wd <= 1e-3 * (max_abs(cpu[0]) + max_abs(cpu[1])));
    // The overlaid in-plane slice: one curve per entry, labelled A, B, C, each
    // eval of its BRDF at the page's theta_i (mean RGB).
    const auto& series = c.at("in_plane");
    REQUIRE(series.size() == 3);
    const Vec3 wi(std::sin(ti), 0, std::cos(ti));
    for (size_t e = 0; e < 3; ++e) {
      const std::string label = series[e].at("label");
      CHECK(label.rfind(std::string(1, char('A' + e)) + ": " + entries[e].at("id").get<std::string>(), 0) == 0);
      const auto xs = series[e].at("x").get<std::vector<double>>(), ys = series[e].at("y").get<std::vector<double>>();
      REQUIRE(xs.size() == ys.size());
      REQUIRE(xs.size() > 100);
      std::vector<double> ref;
      double w = 0;
      for (size_t k = 0; k < xs.size(); ++k) {
        const double to = xs[k] * M_PI / 180;
        ref.push_back(brdfs[e]->eval(wi, Vec3(std::sin(to), 0, std::cos(to))).mean());
        w = std::max(w, std::abs(ys[k] - ref.back()));
      }
      INFO(label << ": worst |page - eval| = " << w << " of peak " << max_abs(ref));
      CHECK(w <= (e < 2 ? 3e-3 : 1e-2) * max_abs(ref));
    }
    ++compares;
  }
  CHECK(compares == 1);
  CHECK(hdrs == 1);
  CHECK(tori == 1);
}
