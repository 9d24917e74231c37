// Tests of the parabolic map and the wiwo / halfdiff parameterizations.
#include <random>

#include "brdfs/directions.h"
#include "brdfs/sampleset.h"
#include "brdfs/models.h"
#include "test_common.h"

using namespace bf;

namespace {
Vec3 random_upper(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double z = U(rng), phi = 2 * M_PI * U(rng);
  return from_spherical(std::acos(z), phi);
}
}  // namespace

TEST_CASE("parabolic: inverse is exact on the hemisphere") {
  std::mt19937_64 rng(7);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 w = random_upper(rng);
    const Vec2 p = parabolic(w);
    CHECK(p.norm() <= 1.0 + 1e-15);
    CHECK((parabolic_inverse(p) - w).norm() < 1e-14);
  }
  // Grazing direction lands on the circle, the normal at the centre.
  CHECK(parabolic(Vec3(1, 0, 0)).isApprox(Vec2(1, 0)));
  CHECK(parabolic(Vec3(0, 0, 1)).norm() == 0.0);
}

TEST_CASE("halfdiff: round trip including n = h, grazing and wi = wo") {
  std::mt19937_64 rng(11);
  std::vector<std::pair<Vec3, Vec3>> cases;
  for (int k = 0; k < 2000; ++k) cases.push_back({random_upper(rng), random_upper(rng)});
  // n ~ h: mirror pairs, exactly and nearly.
  for (double th : {0.0, 1e-9, 0.3, 1.2, M_PI / 2 - 1e-9}) {
    cases.push_back({from_spherical(th, 0.4), from_spherical(th, 0.4 + M_PI)});
    cases.push_back({from_spherical(th, 0.0), from_spherical(th + 1e-12, M_PI)});
  }
  // Grazing and wi = wo.
  cases.push_back({from_spherical(M_PI / 2 - 1e-12, 0.1), from_spherical(M_PI / 2 - 1e-12, 2.0)});
  cases.push_back({from_spherical(0.7, 1.0), from_spherical(0.7, 1.0)});
  cases.push_back({Vec3(0, 0, 1), Vec3(0, 0, 1)});
  cases.push_back({from_spherical(1.0, 0.0), from_spherical(1.0, 0.0)});  // h along x-z plane
  for (const auto& [wi, wo] : cases) {
    for (auto param : {Parameterization::WiWo, Parameterization::HalfDiff}) {
      const Vec4 x = to_point(param, wi, wo);
      INFO(to_string(param) << " wi=" << bf_test::str(wi) << " wo=" << bf_test::str(wo));
      REQUIRE(x.allFinite());
      CHECK(x.head<2>().norm() <= 1.0 + 1e-12);
      CHECK(x.tail<2>().norm() <= 1.0 + 1e-12);
      Vec3 a, b;
      from_point(param, x, a, b);
      // h = normalize(wi + wo) is ill-conditioned when wi ~ -wo: rounding of
      // order 1e-16 in the sum is amplified by 1 / |wi + wo|.
      const double tol = std::max(1e-9, 1e-15 / (wi + wo).norm());
      CHECK((a - wi).norm() < tol);
      CHECK((b - wo).norm() < tol);
    }
  }
}

TEST_CASE("halfdiff: swapping wi and wo negates d (reciprocity conjugate)") {
  std::mt19937_64 rng(3);
  for (int k = 0; k < 500; ++k) {
    const Vec3 wi = random_upper(rng), wo = random_upper(rng);
    const Vec4 x = to_point(Parameterization::HalfDiff, wi, wo);
    const Vec4 y = to_point(Parameterization::HalfDiff, wo, wi);
    CHECK((x.head<2>() - y.head<2>()).norm() < 1e-12);
    CHECK((x.tail<2>() + y.tail<2>()).norm() < 1e-12);
  }
}

TEST_CASE("sampleset: the 16^4 grid has 208 directions per disk and 43,264 pairs") {
  CHECK(grid_directions(16).size() == 208);
  const SampleSet s = sample_grid(Lambert(LambertParams{}), 16);
  CHECK(s.size() == 43264);
  CHECK(s.valid_count() == 43264);
  CHECK_THROWS_WITH(grid_directions(1), Catch::Contains("expected 2..256"));
}

TEST_CASE("sampleset: invalid samples are masked and counted") {
  SampleSet s;
  s.push(Vec3(0, 0, 1), Vec3(0, 0, 1), Rgb(1, 1, 1));
  s.push(Vec3(0, 0, 1), Vec3(0, 0, 1), Rgb(-1, 1, 1));
  s.push(Vec3(0, 0, 1), Vec3(0, 0, 1), Rgb(NAN, 1, 1));
  s.push(Vec3(1, 0, 0), Vec3(0, 0, 1), Rgb(1, 1, 1));
  s.validate();
  CHECK(s.valid_count() == 1);
  CHECK(s.invalid_value == 2);
  CHECK(s.invalid_horizon == 1);
  CHECK(s.compacted().size() == 1);
}

TEST_CASE("sampleset: stratified sampling is deterministic per seed and on the hemisphere") {
  const Lambert l{LambertParams{}};
  const SampleSet a = sample_stratified(l, 1000, 5), b = sample_stratified(l, 1000, 5),
                  c = sample_stratified(l, 1000, 6);
  REQUIRE(a.size() == 1000);
  CHECK(a.wi[17] == b.wi[17]);
  CHECK(a.wi[17] != c.wi[17]);
  CHECK(a.valid_count() == 1000);
}
