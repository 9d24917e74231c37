// Tests of the real orthonormal SH basis and the normalized Legendre recurrence.
#include <cmath>
#include <random>

#include "solvers/quadrature.h"
#include "solvers/sh.h"
#include "test_common.h"

using namespace bf;

namespace {
Eigen::Vector3d random_dir(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Vector3d v(N(rng), N(rng), N(rng));
  return v.normalized();
}

// max |G - I| of the Gram matrix of the order-F basis under the rule.
double orthonormality_error(int F, const SphereRule& rule) {
  const ShBasis basis(F);
  const int n = basis.size();
  Eigen::MatrixXd Y(rule.size(), n), Yw(rule.size(), n);
  Eigen::VectorXd y(n);
  for (size_t k = 0; k < rule.size(); ++k) {
    basis.eval(rule.dir[k], y.data());
    Y.row(k) = y.transpose();
    Yw.row(k) = rule.w[k] * y.transpose();
  }
  const Eigen::MatrixXd G = Y.transpose() * Yw;
  return (G - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff();
}
}  // namespace

TEST_CASE("sh: closed forms of bands 0..2 (no Condon-Shortley phase)") {
  std::mt19937_64 rng(1);
  const double c0 = 1.0 / std::sqrt(4 * M_PI), c1 = std::sqrt(3.0 / (4 * M_PI));
  const double c2 = std::sqrt(15.0 / (4 * M_PI)), c20 = std::sqrt(5.0 / (16 * M_PI));
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d w = random_dir(rng);
    const double x = w.x(), y = w.y(), z = w.z();
    const Eigen::VectorXd s = sh_eval(2, w);
    CHECK(std::abs(s[0] - c0) < 1e-15);
    CHECK(std::abs(s[sh_index(1, -1)] - c1 * y) < 1e-15);
    CHECK(std::abs(s[sh_index(1, 0)] - c1 * z) < 1e-15);
    CHECK(std::abs(s[sh_index(1, 1)] - c1 * x) < 1e-15);
    CHECK(std::abs(s[sh_index(2, -2)] - c2 * x * y) < 1e-14);
    CHECK(std::abs(s[sh_index(2, -1)] - c2 * y * z) < 1e-14);
    CHECK(std::abs(s[sh_index(2, 0)] - c20 * (3 * z * z - 1)) < 1e-14);
    CHECK(std::abs(s[sh_index(2, 1)] - c2 * x * z) < 1e-14);
    CHECK(std::abs(s[sh_index(2, 2)] - 0.5 * c2 * (x * x - y * y)) < 1e-14);
  }
  // Poles: only m = 0 survives; a non-unit argument is normalized.
  const Eigen::VectorXd n = sh_eval(6, Eigen::Vector3d(0, 0, 2));
  for (int l = 0; l <= 6; ++l)
    for (int m = -l; m <= l; ++m)
      if (m == 0)
        CHECK(std::abs(n[sh_index(l, 0)] - std::sqrt((2 * l + 1) / (4 * M_PI))) < 1e-14);
      else
        CHECK(n[sh_index(l, m)] == 0.0);
}

TEST_CASE("sh: zonal terms equal sqrt((2l+1)/4pi) P_l and the table paths agree") {
  const int L = 40;
  std::vector<double> tri(legendre_index(L, L) + 1), col(L + 1);
  for (double x : {-1.0, -0.73, 0.0, 0.2, 0.999999, 1.0}) {
    legendre_normalized(L, x, tri.data());
    for (int l = 0; l <= L; ++l)
      CHECK(bf_test::near_rel(tri[legendre_index(l, 0)],
                              std::sqrt((2 * l + 1) / (4 * M_PI)) * legendre_p(l, x), 1e-12));
    for (int m = 0; m <= L; m += 7) {
      legendre_normalized_column(m, L, x, col.data());
      for (int l = m; l <= L; ++l) CHECK(col[l - m] == tri[legendre_index(l, m)]);
    }
  }
  REQUIRE_THROWS_WITH(legendre_normalized_column(5, 3, 0.1, col.data()),
                      Catch::Contains("0 <= m <= lmax"));
  REQUIRE_THROWS_WITH(ShBasis(-1), Catch::Contains("expected 0..2000"));
}

TEST_CASE("sh: orthonormal to 1e-12 up to F = 30 with the exact product rule") {
  for (int F : {0, 1, 4, 10, 30}) {
    const double err = orthonormality_error(F, sphere_rule(F + 1, 2 * F + 1));
    INFO("F = " << F << ": max |G - I| = " << err);
    CHECK(err < 1e-12);
  }
  // One node fewer in z is no longer exact at F = 10 (the test is not vacuous).
  CHECK(orthonormality_error(10, sphere_rule(10, 21)) > 1e-6);
}

TEST_CASE("sh: normalized Legendre columns stay orthonormal to l = 200") {
  // 2 pi sum_k w_k p_lm(x_k) p_l'm(x_k) = delta_ll' for every m (exact rule: 201 nodes).
  const int L = 200;
  const GaussLegendre g = gauss_legendre(L + 1);
  double worst = 0.0;
  std::vector<double> col(L + 1);
  for (int m : {0, 1, 17, 60, 100, 150, 199}) {
    Eigen::MatrixXd P(g.x.size(), L - m + 1);
    for (size_t k = 0; k < g.x.size(); ++k) {
      legendre_normalized_column(m, L, g.x[k], col.data());
      for (int l = m; l <= L; ++l) P(k, l - m) = col[l - m] * std::sqrt(2 * M_PI * g.w[k]);
    }
    const Eigen::MatrixXd G = P.transpose() * P;
    worst = std::max(worst, (G - Eigen::MatrixXd::Identity(G.rows(), G.cols())).cwiseAbs().maxCoeff());
  }
  INFO("max |G - I| over l, l' <= 200 = " << worst);
  CHECK(worst < 1e-12);
}

TEST_CASE("sh: orthonormal to 1e-12 at F = 60", "[slow]") {
  const double err = orthonormality_error(60, sphere_rule(61, 121));
  INFO("F = 60: max |G - I| = " << err);
  CHECK(err < 1e-12);
}
