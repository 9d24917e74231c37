// The renderer's check of importance sampling (experiments/report/mc_render.h):
// the Monte Carlo sphere converges to the deterministic render as 1/sqrt(N),
// a sampler whose pdf is off is caught, and sampling the BRDF beats cosine
// sampling on a glossy Cook-Torrance.
#include <catch2/catch.hpp>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "experiments/report/mc_render.h"
#include "experiments_helpers.h"
#include "factor/lighting.h"

using namespace bf;

namespace {

SceneSettings lit_scene(int size, int order) {
  SceneSettings s;
  s.size = size;
  s.lighting_nodes = 64;  // the deterministic render's quadrature error far below the noise
  s.lighting = std::make_shared<const ShLighting>(
      directional_lighting(s.light.normalized(), Rgb(1.0, 0.8, 0.6), order));
  return s;
}

// Mean over sphere pixels of (mean-over-RGB difference)^2.
double mse_mean_rgb(const SphereRender& a, const SphereRender& b) {
  double s = 0;
  size_t n = 0;
  for (size_t k = 0; k < a.L.size(); ++k)
    if (a.inside[k]) {
      const double d = a.L[k].mean() - b.L[k].mean();
      s += d * d;
      ++n;
    }
  return s / n;
}

// A sampler whose reported pdf is `scale` times the density it draws from.
class ScaledPdf final : public BrdfSampler {
 public:
  ScaledPdf(std::shared_ptr<const BrdfSampler> s, double scale) : s_(std::move(s)), k_(scale) {}
  DirectionSample sample(const Vec3& wo, double u1, double u2) const override {
    DirectionSample d = s_->sample(wo, u1, u2);
    d.pdf *= k_;
    return d;
  }
  double pdf(const Vec3& wi, const Vec3& wo) const override { return k_ * s_->pdf(wi, wo); }
  size_t storage_floats() const override { return 0; }
  std::string method() const override { return "scaled"; }

 private:
  std::shared_ptr<const BrdfSampler> s_;
  double k_;
};

// The ratio of the image's squared error to the variance the render
// estimates for itself: ~1 for an unbiased render at every N.
double error_to_variance(const Brdf& f, const BrdfSampler& s, const SceneSettings& scene, int spp) {
  const SphereRender det = render_sphere(f, scene);
  const McRender mc = render_sphere_mc(f, s, scene, spp, 7);
  return mse_mean_rgb(det, mc.image) / mc.pixel_variance();
}

}  // namespace

TEST_CASE("mc render: unbiased against the deterministic render with error falling as 1 over sqrt N") {
  const auto f = Catalogue::global().make("blinn-phong:n=5");
  const SceneSettings scene = lit_scene(20, 3);
  const auto cos = cosine_sampler();
  const SphereRender det = render_sphere(*f, scene);
  std::vector<double> mse;
  for (int spp : {8, 32, 128, 512}) {
    const McRender mc = render_sphere_mc(*f, *cos, scene, spp, 3);
    REQUIRE(mc.no_sample == 0);
    const double e = mse_mean_rgb(det, mc.image);
    mse.push_back(e);
    // Tolerance: ~300 pixels, so the ratio's sampling spread is ~10%; a bias
    // of 3% of the mean radiance would already push the ratio at 512 spp far out.
    INFO("spp " << spp << " mse " << e << " variance " << mc.pixel_variance());
    CHECK(e / mc.pixel_variance() > 0.6);
    CHECK(e / mc.pixel_variance() < 1.6);
  }
  // 64x the samples: ~64x smaller squared error (RMSE 8x smaller).
  CHECK(mse[0] / mse[3] > 64.0 / 2.0);
  CHECK(mse[0] / mse[3] < 64.0 * 2.0);
}

TEST_CASE("mc render: a sampler whose pdf is 10 percent off is caught as bias") {
  const auto f = Catalogue::global().make("blinn-phong:n=5");
  const SceneSettings scene = lit_scene(12, 3);
  const ScaledPdf off(cosine_sampler(), 1.1);
  CHECK(error_to_variance(*f, off, scene, 2048) > 3.0);
  CHECK(error_to_variance(*f, *cosine_sampler(), scene, 2048) < 1.6);
}

TEST_CASE("mc render: the model and tabulated samplers beat cosine sampling on Cook-Torrance m 0.2") {
  const auto f = Catalogue::global().make("cook-torrance:m=0.2");
  REQUIRE(dynamic_cast<const CookTorrance*>(f.get()));
  const SceneSettings scene = lit_scene(14, 8);
  const double v_cos = render_sphere_mc(*f, *cosine_sampler(), scene, 64, 1).pixel_variance();
  const McRender model = render_sphere_mc(*f, *make_sampler(*f), scene, 64, 1);
  SamplerOptions tab;
  tab.method = "tabulated";
  const McRender table = render_sphere_mc(*f, *make_sampler(*f, tab), scene, 64, 1);
  INFO("cosine " << v_cos << " model " << model.pixel_variance() << " tabulated " << table.pixel_variance());
  // Under this broad light the cosine factor already does much of the work
  // (about 0.77x at 16 x 16 pixels); docs/results.md has the environment-lit figures.
  CHECK(model.pixel_variance() < 0.9 * v_cos);
  CHECK(table.pixel_variance() < 0.9 * v_cos);
  // Both still converge to the same image.
  const SphereRender det = render_sphere(*f, scene);
  CHECK(mse_mean_rgb(det, model.image) / model.pixel_variance() < 2.0);
  CHECK(mse_mean_rgb(det, table.image) / table.pixel_variance() < 2.0);
}

TEST_CASE("mc render: a point-lit scene or too few samples is refused with the key to set") {
  const auto f = Catalogue::global().make("lambert");
  SceneSettings point;
  CHECK_THROWS_WITH(render_sphere_mc(*f, *cosine_sampler(), point, 16, 1), Catch::Contains("lighting_order"));
  CHECK_THROWS_WITH(render_sphere_mc(*f, *cosine_sampler(), lit_scene(8, 2), 1, 1), Catch::Contains("spp"));
}

TEST_CASE("mc render: the light sampler's pdf integrates to 1 and is the density it draws") {
  const ShLighting light = directional_lighting(Vec3(0.3, 0.2, 0.9).normalized(), Rgb(1.0, 0.9, 0.8), 12);
  const LightSampler ls(light, 16, 32);
  // Integral over the sphere by a fine midpoint rule (uniform in z and phi).
  double sum = 0;
  const int nz = 256, np = 512;
  for (int i = 0; i < nz; ++i)
    for (int j = 0; j < np; ++j) {
      const double z = -1 + (i + 0.5) * 2.0 / nz, s = std::sqrt(1 - z * z), ph = (j + 0.5) * 2 * M_PI / np;
      sum += ls.pdf(Vec3(s * std::cos(ph), s * std::sin(ph), z));
    }
  CHECK(std::abs(sum * 4 * M_PI / (nz * np) - 1.0) < 1e-9);
  // A sample's pdf is pdf() at its direction; the peak cell holds the light.
  double best = 0;
  Vec3 at = Vec3::Zero();
  for (double u1 : {0.05, 0.3, 0.5, 0.77, 0.99})
    for (double u2 : {0.1, 0.6, 0.95}) {
      const DirectionSample d = ls.sample(u1, u2);
      CHECK(std::abs(d.wi.norm() - 1) < 1e-12);
      CHECK(d.pdf == Approx(ls.pdf(d.wi)).epsilon(1e-12));
      if (d.pdf > best) best = d.pdf, at = d.wi;
    }
  CHECK(at.dot(Vec3(0.3, 0.2, 0.9).normalized()) > 0.9);
  CHECK_THROWS_WITH(LightSampler(light, 0, 8), Catch::Contains("rows and cols"));
  CHECK_THROWS_WITH(LightSampler(light, 8, 8, 0.0), Catch::Contains("uniform"));
}

TEST_CASE("mc render: with light sampling the render stays unbiased and a narrow light's variance falls") {
  const auto f = Catalogue::global().make("blinn-phong:n=5");
  const SceneSettings scene = lit_scene(12, 16);
  const LightSampler ls(*scene.lighting);
  const SphereRender det = render_sphere(*f, scene);
  const McRender mis = render_sphere_mc(*f, *cosine_sampler(), scene, 256, 5, &ls);
  const McRender plain = render_sphere_mc(*f, *cosine_sampler(), scene, 256, 5);
  INFO("cosine " << plain.pixel_variance() << " cosine+light " << mis.pixel_variance());
  const double r = mse_mean_rgb(det, mis.image) / mis.pixel_variance();
  CHECK(r > 0.6);
  CHECK(r < 1.6);
  CHECK(mis.pixel_variance() < 0.5 * plain.pixel_variance());
}

TEST_CASE("mc render: mc-variance prints one row per sampler and with --mis one more per sampler") {
  auto rows = [](const std::string& out) {
    std::vector<std::string> names;
    std::istringstream in(out);
    std::string integrand, sampler, rest;
    while (in >> integrand >> sampler && std::getline(in, rest))
      if (integrand != "integrand") names.push_back(integrand + " " + sampler);
    return names;
  };
  std::string out;
  REQUIRE(bf_test::run_cli("mc-variance --brdf cook-torrance:m=0.2 --order 2 --spp 4 --size 8", &out) == 0);
  CHECK(rows(out) == std::vector<std::string>{"original cosine", "original tabulated", "original model"});
  REQUIRE(bf_test::run_cli("mc-variance --brdf cook-torrance:m=0.2 --order 2 --spp 4 --size 8 --mis", &out) == 0);
  CHECK(rows(out) == std::vector<std::string>{"original cosine", "original tabulated", "original model",
                                              "original cosine+light", "original tabulated+light",
                                              "original model+light"});
  CHECK(bf_test::run_cli("mc-variance --brdf lambert --order 2 --view-phi-bins 300", &out) == 2);
  CHECK_THAT(out, Catch::Contains("--view-phi-bins") && Catch::Contains("300"));
}
