// The SVD's default rim inset against the value docs/design.md §3.6 states
// ("texels beyond radius 1 - rim_inset are evaluated at the same azimuth at
// that radius (default: half a grid spacing, 1/(R - 1))"), worked out by hand
// here, not read from the code under test.
#include <catch2/catch.hpp>
#include <cmath>

#include "factor/svd_baseline.h"

using namespace bf;

namespace {

// f = (cos theta_i, cos theta_o, 1 + wi.x): the table shows where each texel
// was evaluated.
class Where final : public Brdf {
 public:
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    return Rgb(wi.z(), wo.z(), 1.0 + wi.x());
  }
  std::string name() const override { return "where"; }
  std::string to_string() const override { return "where"; }
};

}  // namespace

TEST_CASE("svd: the default rim inset is half a grid spacing, 1/(R-1), at most 0.5") {
  struct Case {
    int res;
    double inset;
  };
  // Grid spacing 2/(R - 1); half of it, capped at 0.5.
  for (const Case c : {Case{2, 0.5}, Case{3, 0.5}, Case{5, 0.25}, Case{11, 0.1}, Case{16, 1.0 / 15},
                       Case{32, 1.0 / 31}, Case{256, 1.0 / 255}}) {
    INFO("texture_size " << c.res);
    SvdOptions opt;
    opt.res = c.res;
    CHECK(opt.effective_rim_inset() == Approx(c.inset).epsilon(1e-15));
    opt.rim_inset = 0.01;  // an explicit inset is kept
    CHECK(opt.effective_rim_inset() == 0.01);
  }
}

TEST_CASE("svd: rim texels are tabulated at radius 1 - 1/(R-1), interior texels where they are") {
  // R = 5: texel points -1, -0.5, 0, 0.5, 1 per axis; inset 1/4, so texels
  // beyond radius 0.75 are evaluated at radius 0.75 of the same azimuth. The
  // parabolic point at radius 0.75 is the direction with
  //   z = (1 - 0.75^2) / (1 + 0.75^2) = 0.4375 / 1.5625 = 0.28,
  //   |(x, y)| = 2 * 0.75 / 1.5625 = 0.96.
  // Interior: point (0.5, 0) (radius 0.5 < 0.75) is the direction
  //   z = 0.75 / 1.25 = 0.6, x = 1 / 1.25 = 0.8.
  SvdOptions opt;
  opt.res = 5;
  opt.rank = 1;
  const SvdTable t = tabulate_svd(Where(), opt);
  const DiskGrid& g = t.grid;
  auto slot = [&](int i, int j) {
    const int s = g.slot[size_t(j) * 5 + i];
    REQUIRE(s >= 0);
    return s;
  };
  const int centre = slot(2, 2);                     // point (0, 0): straight up
  const int west_edge = slot(0, 2);                  // point (-1, 0): on the disk edge
  const int corner = slot(0, 0);                     // point (-1, -1): outside the disk
  const int east_half = slot(3, 2);                  // point (0.5, 0): interior
  const int north_out = slot(1, 4);                  // point (-0.5, 1): radius 1.118
  // Row texel = wi (channel 0 = wi.z, channel 2 = 1 + wi.x); column = wo (channel 1 = wo.z).
  CHECK(t.M[0](west_edge, centre) == Approx(0.28).epsilon(1e-14));
  CHECK(t.M[2](west_edge, centre) == Approx(1.0 - 0.96).epsilon(1e-13));
  CHECK(t.M[1](centre, west_edge) == Approx(0.28).epsilon(1e-14));
  CHECK(t.M[0](corner, centre) == Approx(0.28).epsilon(1e-14));
  CHECK(t.M[2](corner, centre) == Approx(1.0 - 0.96 / std::sqrt(2.0)).epsilon(1e-13));
  CHECK(t.M[0](north_out, centre) == Approx(0.28).epsilon(1e-14));
  CHECK(t.M[0](east_half, centre) == Approx(0.6).epsilon(1e-14));
  CHECK(t.M[2](east_half, centre) == Approx(1.8).epsilon(1e-14));
  CHECK(t.M[0](centre, centre) == Approx(1.0).epsilon(1e-15));
  CHECK(t.M[1](east_half, east_half) == Approx(0.6).epsilon(1e-14));
}

TEST_CASE("svd: log mode's A is the mean over texel pairs inside the closed disk, rim texels included") {
  // R = 5: the 13 texel points with |p| <= 1 are (0, 0) (z = 1), four at
  // radius 0.5 (z = 0.75 / 1.25 = 0.6), four at radius sqrt(0.5)
  // (z = 0.5 / 1.5 = 1/3) and four on the edge (radius 1, evaluated at 0.75:
  // z = 0.28). Channel 0 is wi.z, so A_0 = (1 + 4 * 0.6 + 4/3 + 4 * 0.28) / 13
  // (the mean over the 13 x 13 inside pairs); leaving out the edge texels
  // would give (1 + 2.4 + 4/3) / 9.
  SvdOptions opt;
  opt.res = 5;
  opt.rank = 1;
  opt.log = true;
  const SvdTable t = tabulate_svd(Where(), opt);
  CHECK(t.A[0] == Approx((1.0 + 4 * 0.6 + 4.0 / 3.0 + 4 * 0.28) / 13.0).epsilon(1e-13));
  CHECK(t.A[1] == Approx((1.0 + 4 * 0.6 + 4.0 / 3.0 + 4 * 0.28) / 13.0).epsilon(1e-13));
}

TEST_CASE("svd: halfdiff pairs below the horizon are read at the pulled-in rim's elevation") {
  // R = 5: the rim is pulled in to radius 0.75, elevation z = 0.28 (above).
  // A (h, d) pair whose wi falls below the horizon is lifted to that
  // elevation, so channel 0 (wi.z) holds 0.28 there; likewise wo and channel 1.
  SvdOptions opt;
  opt.res = 5;
  opt.rank = 1;
  opt.param = Parameterization::HalfDiff;
  const SvdTable t = tabulate_svd(Where(), opt);
  const DiskGrid& g = t.grid;
  const double inset = 0.25;
  int below_i = 0, below_o = 0;
  for (size_t r = 0; r < g.count(); ++r)
    for (size_t c = 0; c < g.count(); ++c) {
      Vec3 wi, wo;
      half_diff_inverse(g.direction(g.texels[r], inset), g.direction(g.texels[c], inset), wi, wo);
      if (wi.z() <= 0.0) {
        ++below_i;
        CHECK(t.M[0](r, c) == Approx(0.28).epsilon(1e-12));
      }
      if (wo.z() <= 0.0) {
        ++below_o;
        CHECK(t.M[1](r, c) == Approx(0.28).epsilon(1e-12));
      }
    }
  CHECK(below_i > 10);
  CHECK(below_o > 10);
}
