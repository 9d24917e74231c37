// Tests of Gauss-Legendre rules and the spherical product rules.
#include <cmath>

#include "solvers/quadrature.h"
#include "test_common.h"

using namespace bf;

TEST_CASE("gauss_legendre: known nodes and symmetry") {
  const GaussLegendre g2 = gauss_legendre(2);
  CHECK(std::abs(g2.x[0] + 1.0 / std::sqrt(3.0)) < 1e-15);
  CHECK(std::abs(g2.x[1] - 1.0 / std::sqrt(3.0)) < 1e-15);
  CHECK(std::abs(g2.w[0] - 1.0) < 1e-15);
  const GaussLegendre g3 = gauss_legendre(3);
  CHECK(g3.x[1] == 0.0);
  CHECK(std::abs(g3.x[2] - std::sqrt(0.6)) < 1e-15);
  CHECK(std::abs(g3.w[1] - 8.0 / 9.0) < 1e-15);
  CHECK(std::abs(g3.w[2] - 5.0 / 9.0) < 1e-15);
  for (int n : {1, 7, 64, 301}) {
    const GaussLegendre g = gauss_legendre(n);
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
      sum += g.w[k];
      CHECK(g.x[k] == -g.x[n - 1 - k]);
      if (k > 0) CHECK(g.x[k] > g.x[k - 1]);
    }
    INFO("n = " << n);
    CHECK(std::abs(sum - 2.0) < 1e-13);
  }
}

TEST_CASE("gauss_legendre: exact for polynomials of degree <= 2n-1 on [a, b]") {
  for (int n : {1, 2, 5, 16, 40}) {
    const double a = -0.3, b = 1.7;
    const GaussLegendre g = gauss_legendre(n, a, b);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double q = 0.0;
      for (int i = 0; i < n; ++i) q += g.w[i] * std::pow(g.x[i], k);
      const double exact = (std::pow(b, k + 1) - std::pow(a, k + 1)) / (k + 1);
      INFO("n = " << n << ", degree " << k << ": " << q << " vs " << exact);
      CHECK(bf_test::near_rel(q, exact, 1e-13));
    }
    // Degree 2n is not integrated exactly (the test is not vacuous); the
    // relative error shrinks fast with n, so check the small rules.
    if (n > 5) continue;
    double q = 0.0;
    for (int i = 0; i < n; ++i) q += g.w[i] * std::pow(g.x[i], 2 * n);
    const double exact = (std::pow(b, 2 * n + 1) - std::pow(a, 2 * n + 1)) / (2 * n + 1);
    CHECK(std::abs(q - exact) > 1e-6 * std::abs(exact));
  }
}

TEST_CASE("gauss_legendre: invalid arguments throw") {
  REQUIRE_THROWS_WITH(gauss_legendre(0), Catch::Contains("n <= 100000, found 0"));
  REQUIRE_THROWS_WITH(gauss_legendre(3, 1.0, 1.0), Catch::Contains("a < b"));
  REQUIRE_THROWS_WITH(sphere_rule(4, 0), Catch::Contains("n_phi must be >= 1"));
  REQUIRE_THROWS_WITH(sphere_rule(4, 8, 0.5, 0.2), Catch::Contains("z_min < z_max"));
}

TEST_CASE("sphere_rule: areas and unit directions") {
  const SphereRule full = sphere_rule(12, 25);
  const SphereRule upper = sphere_rule(12, 25, 0.0, 1.0);
  double a = 0.0, b = 0.0, zz = 0.0;
  for (size_t k = 0; k < full.size(); ++k) {
    a += full.w[k];
    CHECK(std::abs(full.dir[k].norm() - 1.0) < 1e-15);
  }
  for (size_t k = 0; k < upper.size(); ++k) {
    b += upper.w[k];
    zz += upper.w[k] * upper.dir[k].z();
    CHECK(upper.dir[k].z() > 0.0);
  }
  CHECK(std::abs(a - 4 * M_PI) < 1e-13);
  CHECK(std::abs(b - 2 * M_PI) < 1e-13);
  CHECK(std::abs(zz - M_PI) < 1e-13);  // projected solid angle of the hemisphere
}
