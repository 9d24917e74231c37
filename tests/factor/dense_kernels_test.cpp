// Tests of the runtime-dispatched dense kernels (factor/dense_kernels.h).
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <random>

#include "factor/dense_kernels.h"

using namespace bf;

namespace {
// A random symmetric positive definite n x n matrix (G G^T + n I).
Eigen::MatrixXd random_spd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd G(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) G(i, j) = nd(rng);
  return G * G.transpose() + n * Eigen::MatrixXd::Identity(n, n);
}
}  // namespace

TEST_CASE("dense kernels: every supported variant solves an SPD system like Eigen's LLT") {
  const std::vector<std::string> variants = kernels::supported_variants();
  REQUIRE(!variants.empty());
  CHECK(variants.front() == "generic");
  bool active_listed = false;
  for (const std::string& v : variants) active_listed |= v == kernels::active_variant();
  CHECK(active_listed);
  // Sizes below, at and above the LLT's block of 48 columns (one block, a
  // whole number of blocks, a remainder); 3 right-hand sides (the fit's
  // channels, a kernel of its own) and other counts (Eigen's solves).
  for (int n : {1, 7, 48, 64, 97, 300})
    for (int nrhs : {1, 3, 5}) {
      const Eigen::MatrixXd A = random_spd(n, 17u + n);
      Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, nrhs);
      const Eigen::MatrixXd ref = A.llt().solve(B);
      for (const std::string& v : variants) {
        INFO("variant " << v << ", n = " << n << ", right-hand sides " << nrhs);
        Eigen::MatrixXd a = A;
        a.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);  // only the lower triangle is read
        Eigen::MatrixXd x = B;
        REQUIRE(kernels::llt_solve_with(v, a.data(), n, x.data(), nrhs));
        CHECK((x - ref).norm() <= 1e-12 * ref.norm());
        CHECK((A * x - B).norm() <= 1e-10 * B.norm());
      }
    }
}

TEST_CASE("dense kernels: a matrix that is not positive definite is reported, not solved") {
  Eigen::MatrixXd A = random_spd(40, 3);
  A(20, 20) = -1.0;
  for (const std::string& v : kernels::supported_variants()) {
    INFO("variant " << v);
    Eigen::MatrixXd a = A, x = Eigen::MatrixXd::Ones(40, 2);
    CHECK_FALSE(kernels::llt_solve_with(v, a.data(), 40, x.data(), 2));
  }
}

TEST_CASE("dense kernels: an unknown variant is refused with the known ones named") {
  double a = 1, b = 1;
  CHECK_THROWS_WITH(kernels::llt_solve_with("sse9", &a, 1, &b, 1),
                    Catch::Contains("expected one of generic") && Catch::Contains("found \"sse9\""));
}

namespace {
// A random SPD matrix whose leading n1 x n1 block has bandwidth bw (zero
// beyond), the rest dense: B B^T + diagonal with B of that sparsity pattern
// does not keep the band, so the head block is built as a banded SPD matrix
// and the coupling kept small enough for positive definiteness.
Eigen::MatrixXd banded_head_spd(int n, int n1, int bw, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ud(-1.0, 1.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i < n; ++i)
      if (i >= n1 || i - j <= bw) A(i, j) = A(j, i) = ud(rng);
  for (int j = 0; j < n; ++j) A(j, j) = (j < n1 ? 2 * bw + 2 : n) + 1.0;  // diagonally dominant
  return A;
}
}  // namespace

TEST_CASE("dense kernels: the banded-head Cholesky solves like Eigen's LLT, for every variant") {
  // (n, n1, bw): band used (4 bw <= n1), a full band (falls back), the head
  // being everything but one unknown or everything (a banded matrix), a band
  // of width 0; head sizes that are
  // and are not multiples of the 4-column blocks of L21, tails of 8 rows, 4
  // rows and single rows.
  const int cases[][3] = {{60, 30, 5}, {300, 150, 20}, {100, 40, 30}, {50, 49, 3}, {40, 20, 0},
                          {442, 221, 17}, {103, 64, 16}, {77, 33, 1}, {221, 221, 17}, {30, 30, 2}};
  for (const auto& c : cases)
    for (int nrhs : {1, 3, 4}) {
      const int n = c[0], n1 = c[1], bw = c[2];
      const Eigen::MatrixXd A = banded_head_spd(n, n1, bw, 7u + n + bw);
      const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, nrhs);
      const Eigen::MatrixXd ref = A.llt().solve(B);
      for (const std::string& v : kernels::supported_variants()) {
        INFO("variant " << v << ", n = " << n << ", n1 = " << n1 << ", bw = " << bw << ", right-hand sides "
                        << nrhs);
        Eigen::MatrixXd a = A;
        a.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);  // only the lower triangle is read
        Eigen::MatrixXd x = B;
        REQUIRE(kernels::llt_solve_banded_head_with(v, a.data(), n, n1, x.data(), nrhs));
        CHECK((x - ref).norm() <= 1e-12 * ref.norm());
        CHECK((A * x - B).norm() <= 1e-10 * B.norm());
      }
    }
}

namespace {
// As banded_head_spd, but each tail row couples only to head columns from a
// random first one on (a third of the rows to none): the staircase the
// kernel orders the tail by (a fit's cross block is sparse this way).
Eigen::MatrixXd staircase_spd(int n, int n1, int bw, unsigned seed) {
  Eigen::MatrixXd A = banded_head_spd(n, n1, bw, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_int_distribution<int> first(0, n1 + n1 / 2);  // > n1 - 1: no coupling
  for (int i = n1; i < n; ++i) {
    const int f = first(rng);
    for (int k = 0; k < std::min(f, n1); ++k) A(i, k) = A(k, i) = 0.0;
  }
  return A;
}
}  // namespace

TEST_CASE("dense kernels: the banded-head Cholesky with a staircase coupling solves like Eigen's LLT") {
  // Tail rows reordered by their first coupled head column, rows with none
  // skipped; tail sizes around the 8- and 4-row chunks and the 32-row blocks
  // of the Schur update.
  const int cases[][3] = {{442, 221, 17}, {90, 60, 6}, {133, 64, 8}, {41, 20, 2}, {300, 100, 10}};
  for (const auto& c : cases)
    for (int nrhs : {3, 2}) {
      const int n = c[0], n1 = c[1], bw = c[2];
      const Eigen::MatrixXd A = staircase_spd(n, n1, bw, 5u + n);
      const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, nrhs);
      const Eigen::MatrixXd ref = A.llt().solve(B);
      for (const std::string& v : kernels::supported_variants()) {
        INFO("variant " << v << ", n = " << n << ", n1 = " << n1 << ", right-hand sides " << nrhs);
        Eigen::MatrixXd a = A;
        a.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);
        Eigen::MatrixXd x = B;
        REQUIRE(kernels::llt_solve_banded_head_with(v, a.data(), n, n1, x.data(), nrhs));
        CHECK((x - ref).norm() <= 1e-12 * ref.norm());
        CHECK((A * x - B).norm() <= 1e-10 * B.norm());
      }
    }
  // No coupling at all: the tail is solved on its own.
  Eigen::MatrixXd A = banded_head_spd(80, 40, 4, 3u);
  A.block(40, 0, 40, 40).setZero();
  A.block(0, 40, 40, 40).setZero();
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(80, 3);
  Eigen::MatrixXd a = A, x = B;
  REQUIRE(kernels::llt_solve_banded_head(a.data(), 80, 40, x.data(), 3));
  CHECK((A * x - B).norm() <= 1e-10 * B.norm());
}

TEST_CASE("dense kernels: the banded-head Cholesky reports a matrix that is not positive definite") {
  // Once in the banded head, once in the Schur complement.
  for (int bad : {10, 45}) {
    Eigen::MatrixXd A = banded_head_spd(60, 30, 4, 11u);
    A(bad, bad) = -1.0;
    for (const std::string& v : kernels::supported_variants()) {
      INFO("variant " << v << ", negative diagonal at " << bad);
      Eigen::MatrixXd a = A, x = Eigen::MatrixXd::Ones(60, 2);
      CHECK_FALSE(kernels::llt_solve_banded_head_with(v, a.data(), 60, 30, x.data(), 2));
    }
  }
}
