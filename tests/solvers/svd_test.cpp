// Tests of the truncated SVD helpers.
#include <random>

#include "solvers/svd.h"
#include "test_common.h"

using namespace bf;

TEST_CASE("truncated_svd: rank-K error equals Eckart-Young") {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd A(40, 25);
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j) A(i, j) = N(rng);
  for (int K : {1, 3, 10, 24, 25}) {
    const TruncatedSvd s = truncated_svd(A, K);
    REQUIRE(s.rank() == K);
    REQUIRE(s.sigma.size() == 25);
    const double err = (A - s.reconstruct()).norm();
    const double ey = eckart_young_error(s.sigma, K);
    INFO("K = " << K << ": " << err << " vs " << ey);
    CHECK(std::abs(err - ey) <= 1e-12 * A.norm());
    CHECK((s.U.transpose() * s.U - Eigen::MatrixXd::Identity(K, K)).cwiseAbs().maxCoeff() < 1e-13);
    for (int k = 0; k < K; ++k) CHECK(s.U.col(k).sum() >= 0.0);
  }
  CHECK(truncated_svd(A, 100).rank() == 25);  // capped at min(rows, cols)
}

TEST_CASE("truncated_svd: rank-1 factors of a positive separable matrix are positive") {
  Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(30, 0.5, 2.0);
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(20, 1.0, 3.0);
  const Eigen::MatrixXd A = a * b.transpose();
  const TruncatedSvd s = truncated_svd(A, 2);
  CHECK((s.U.col(0).array() > 0).all());
  CHECK((s.V.col(0).array() > 0).all());
  CHECK((A - s.reconstruct(1)).norm() < 1e-13 * A.norm());
  CHECK(s.sigma[1] < 1e-13 * s.sigma[0]);
}

TEST_CASE("rank_for_energy and invalid input") {
  Eigen::VectorXd sig(4);
  sig << 3, 2, 1, 0;
  CHECK(rank_for_energy(sig, 0.0) == 3);
  CHECK(rank_for_energy(sig, 0.1) == 2);   // 13/14 = 0.93 >= 0.9
  CHECK(rank_for_energy(sig, 0.4) == 1);   // 9/14 = 0.64 >= 0.6
  CHECK(eckart_young_error(sig, 1) == Approx(std::sqrt(5.0)));
  Eigen::MatrixXd bad = Eigen::MatrixXd::Ones(2, 2);
  bad(0, 1) = std::nan("");
  REQUIRE_THROWS_WITH(truncated_svd(bad, 1), Catch::Contains("non-finite"));
  REQUIRE_THROWS_WITH(truncated_svd(Eigen::MatrixXd::Ones(2, 2), 0), Catch::Contains("rank must be >= 1"));
}
