// The per-run sphere picture and shade_rmse.
#include "factor/image_io.h"

#include "brdfs/catalogue.h"
#include "experiments/report/render.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

TEST_CASE("render: the sphere is lit where the light sees it, and shade_rmse compares renders") {
  const BrdfPtr lambert = Catalogue::builtin().make("lambert:kd=0.5");
  SceneSettings scene;
  scene.size = 32;
  scene.light = Vec3(0.0, 0.0, 5.0);  // on the camera axis
  const SphereRender a = render_sphere(*lambert, scene);
  REQUIRE(a.L.size() == 32u * 32u);
  // Centre pixel: n = +z, wi = +z, d = 4: L = I * kd/pi * 1 / 16.
  const size_t centre = 16 * 32 + 16;
  CHECK(a.inside[centre] == 1);
  CHECK(near_rel(a.L[centre][0], scene.intensity * 0.5 / M_PI / 16.0, 0.02));
  CHECK(a.inside[0] == 0);
  CHECK(a.L[0].isZero());
  CHECK(shade_rmse(a, a) == 0.0);

  // A light to the side (+x): the left half of the sphere faces away from it.
  // Every pixel equals the closed form I kd/pi max(0, n.wi) / d^2 computed
  // here independently, so the clamp (pixels facing away are 0, never
  // negative) and the lit side are both checked.
  {
    SceneSettings side = scene;
    side.light = Vec3(3.0, 0.0, 0.5);
    const SphereRender s = render_sphere(*lambert, side);
    size_t dark = 0, lit = 0;
    double worst = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const size_t k = size_t(y) * 32 + x;
        const double px = -1.0 + (x + 0.5) / 16.0, py = 1.0 - (y + 0.5) / 16.0, rr = px * px + py * py;
        if (rr >= 1.0) continue;
        const Vec3 nrm(px, py, std::sqrt(1.0 - rr));
        const Vec3 to_light = side.light - nrm;
        const double cos_i = to_light.normalized().dot(nrm);
        const double want = side.intensity * 0.5 / M_PI * std::max(0.0, cos_i) / to_light.squaredNorm();
        (cos_i > 0.0 ? lit : dark) += 1;
        worst = std::max(worst, (s.L[k] - Rgb::Constant(want)).abs().maxCoeff() / (side.intensity * 0.5 / M_PI));
        if (cos_i <= 0.0) CHECK(s.L[k].isZero());
      }
    INFO(lit << " lit and " << dark << " dark pixels, max |L - closed form| / (I kd/pi) = " << worst);
    CHECK(dark > 100);
    CHECK(lit > 100);
    CHECK(worst < 1e-12);
  }

  const BrdfPtr brighter = Catalogue::builtin().make("lambert:kd=1");
  const SphereRender b = render_sphere(*brighter, scene);
  CHECK(shade_rmse(a, b) > 0.0);

  ScratchDir tmp;
  const std::string png = tmp / "sphere.png";
  write_comparison_png(a, b, png);
  int pw = 0, ph = 0;
  const std::vector<uint8_t> px = bf::read_png_rgb8(png, pw, ph);
  CHECK(pw == 3 * 32 + 2 * 4);
  CHECK(ph == 32);
  CHECK(px.size() == size_t(pw) * ph * 3);
  // Nothing but the picture is left in the folder (no temporary).
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(tmp.path)) files += e.is_regular_file();
  CHECK(files == 1);
  SceneSettings other = scene;
  other.size = 16;
  CHECK_THROWS(shade_rmse(a, render_sphere(*lambert, other)));
}
