// Truncated singular value decomposition helpers for separable approximations
// (Kautz-McCool SVD baseline): thin SVD with a sign convention, Eckart-Young
// error of a truncation, rank for an energy fraction.
#pragma once

#include <Eigen/Core>

namespace bf {

// A = U diag(sigma) V^T truncated to `rank` terms.
struct TruncatedSvd {
  Eigen::MatrixXd U;      // rows(A) x rank, orthonormal columns
  Eigen::VectorXd sigma;  // ALL min(rows, cols) singular values, descending, >= 0
  Eigen::MatrixXd V;      // cols(A) x rank, orthonormal columns
  int rank() const { return int(U.cols()); }
  // U_K diag(sigma_K) V_K^T for K = rank() (or the given K <= rank()).
  Eigen::MatrixXd reconstruct() const;
  Eigen::MatrixXd reconstruct(int K) const;
};

// Thin SVD of A (Eigen::BDCSVD, which switches to Jacobi for small matrices),
// keeping min(rank, min(rows, cols)) singular vector pairs. Sign convention:
// each u_k is flipped (with v_k) so that the sum of its entries is >= 0, which
// makes the rank-1 factors of a non-negative matrix non-negative. Throws
// std::invalid_argument for rank < 1, an empty A or non-finite entries.
TruncatedSvd truncated_svd(const Eigen::MatrixXd& A, int rank);

// Eckart-Young: the Frobenius error of the best rank-K approximation,
// sqrt(sum_{k >= K} sigma_k^2) (0-based k).
double eckart_young_error(const Eigen::VectorXd& sigma, int K);

// Smallest K with sum_{k < K} sigma_k^2 >= (1 - eps) sum_k sigma_k^2 (0 for a
// zero matrix). eps in [0, 1).
int rank_for_energy(const Eigen::VectorXd& sigma, double eps);

}  // namespace bf
