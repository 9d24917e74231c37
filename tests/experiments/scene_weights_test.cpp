// Scene-weighted fits: [[method]] weight_fit / weight_floor, the weight rule of
// experiments/report/scene_weights.h, and the scene_rel_mse column.
#include <catch2/catch.hpp>

#include "experiments/report/scene_weights.h"
#include "factor/lighting.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

std::string with_method(const std::string& extra) {
  return std::string(kConfigHead) + "\n[[method]]\nkind = \"mccool\"\ntexture_size = 4\n" + extra + "\n";
}

}  // namespace

TEST_CASE("scene weights: weight_fit none keeps the run ids and image changes them") {
  register_loaders();
  const Plan plain = parse_plan(with_method(""), "cfg.toml", {});
  const Plan none = parse_plan(with_method("weight_fit = \"none\""), "cfg.toml", {});
  const Plan image = parse_plan(with_method("weight_fit = \"image\""), "cfg.toml", {});
  REQUIRE(plain.runs.size() == 1);
  CHECK(none.runs[0].run_id == plain.runs[0].run_id);
  CHECK(image.runs[0].run_id != plain.runs[0].run_id);
  const Plan floor = parse_plan(with_method("weight_fit = \"image\"\nweight_floor = 0.5"), "cfg.toml", {});
  CHECK(floor.runs[0].run_id != image.runs[0].run_id);
  // A sweep puts the weighted and the unweighted fit side by side.
  const Plan both = parse_plan(with_method("weight_fit = [\"none\", \"image\"]"), "cfg.toml", {});
  REQUIRE(both.runs.size() == 2);
  CHECK(both.runs[0].run_id == plain.runs[0].run_id);
  CHECK(both.runs[1].run_id == image.runs[0].run_id);
}

TEST_CASE("scene weights: a bad weight_fit or weight_floor names the key and what was found") {
  require_one_config_error(with_method("weight_fit = \"pixels\""), {"weight_fit", "pixels", "image"});
  require_one_config_error(with_method("weight_fit = \"image\"\nweight_floor = 1.5"), {"weight_floor", "1.5"});
  require_one_config_error(with_method("weight_floor = 0.2"), {"weight_floor", "weight_fit"});
}

TEST_CASE("scene weights: the pairs the sphere reads get the weight and the factors average 1") {
  const auto brdf = Catalogue::global().make("bluepaint");
  const SampleSet s = sample_grid(*brdf, 8);
  SceneSettings scene;
  scene.size = 32;
  const std::vector<ScenePair> pairs = scene_pairs(*brdf, scene);
  REQUIRE(pairs.size() > 100);
  for (const ScenePair& p : pairs) {
    REQUIRE(p.wi.z() > 0.0);
    REQUIRE(p.wo.z() > 0.0);
    REQUIRE(p.a > 0.0);
  }
  const double floor = 0.1;
  const SampleSet w = scene_weighted(s, pairs, floor);
  REQUIRE(w.size() == s.size());
  double mean = 0, lo = 1e300, hi = 0;
  size_t n = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    const double f = w.weight[k] / s.weight_of(k);
    mean += f;
    lo = std::min(lo, f);
    hi = std::max(hi, f);
    ++n;
  }
  mean /= n;
  CHECK(mean == Approx(1.0).epsilon(1e-9));
  CHECK(lo >= floor - 1e-12);
  CHECK(hi > 5.0);  // concentrated where the picture is
  // The sample nearest the brightest pair carries more than the average, the
  // sample farthest from every pair only the floor.
  const ScenePair* top = &pairs[0];
  for (const ScenePair& p : pairs)
    if (p.a > top->a) top = &p;
  size_t nearest = 0, farthest = 0;
  double dn = 1e300, df = -1;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    const double d = (s.wi[k] - top->wi).squaredNorm() + (s.wo[k] - top->wo).squaredNorm();
    if (d < dn) dn = d, nearest = k;
    double dmin = 1e300;
    for (const ScenePair& p : pairs)
      dmin = std::min(dmin, (s.wi[k] - p.wi).squaredNorm() + (s.wo[k] - p.wo).squaredNorm());
    if (dmin > df) df = dmin, farthest = k;
  }
  CHECK(w.weight[nearest] > 1.0);
  CHECK(w.weight[farthest] == Approx(floor).margin(1e-9));
  // floor 1: the weights are the samples' own.
  const SampleSet same = scene_weighted(s, pairs, 1.0);
  for (size_t k = 0; k < s.size(); ++k) CHECK(same.weight[k] == Approx(s.weight_of(k)));
  CHECK_THROWS_WITH(scene_weighted(s, pairs, -0.1), Catch::Contains("weight_floor"));
}

TEST_CASE("scene weights: the environment-lit scene weights pairs by the light they see") {
  const auto brdf = Catalogue::global().make("bluepaint");
  auto total = [&](const Vec3& from) {
    SceneSettings scene;
    scene.size = 16;
    scene.lighting = std::make_shared<const ShLighting>(directional_lighting(from, Rgb::Ones(), 2));
    const std::vector<ScenePair> pairs = scene_pairs(*brdf, scene);
    double t = 0;
    for (const ScenePair& p : pairs) {
      REQUIRE(p.a >= 0.0);
      t += p.a;
    }
    return std::make_pair(pairs.size(), t);
  };
  const auto front = total(Vec3(0, 0, 1)), back = total(Vec3(0, 0, -1));
  CHECK(front.first > 16 * 16 / 2);  // several quadrature pairs per pixel
  CHECK(front.second > 0.0);
  // Lit from behind the sphere, the camera's side sees little of the light.
  CHECK(back.second < 0.3 * front.second);
}

TEST_CASE("scene weights: a scene-weighted run reports scene_rel_mse beside the unweighted rel_mse") {
  ScratchDir d;
  const std::string cfg =
      write_text(d / "w.toml", std::string(kConfigHead) + "\n[scene]\nsize = 24\n" + "\n[[method]]\nkind = \"mccool\"\n" +
                                   "texture_size = 4\nweight_fit = \"image\"\n");
  const RunSummary s = run_quiet(cfg, d / "out");
  const std::string csv = read_text(d / "out/results.csv");
  INFO(csv);
  REQUIRE(csv.find("scene_rel_mse") != std::string::npos);
  // The row's scene_rel_mse cell is filled, and differs from rel_mse.
  std::istringstream in(csv);
  std::string head, row;
  std::getline(in, head);
  std::getline(in, row);
  auto cell = [](const std::string& line, size_t i) {
    std::stringstream ss(line);
    std::string c;
    for (size_t k = 0; k <= i; ++k) std::getline(ss, c, ',');
    return c;
  };
  auto index = [&](const std::string& name) {
    std::stringstream ss(head);
    std::string c;
    size_t i = 0;
    while (std::getline(ss, c, ',')) {
      if (c == name) return i;
      ++i;
    }
    return size_t(-1);
  };
  const std::string scene_cell = cell(row, index("scene_rel_mse")), rel = cell(row, index("rel_mse"));
  REQUIRE(!scene_cell.empty());
  CHECK(std::stod(scene_cell) > 0.0);
  CHECK(scene_cell != rel);
  (void)s;
}
