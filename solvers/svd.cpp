// Truncated SVD helpers (see svd.h).
#include "solvers/svd.h"

#include <Eigen/SVD>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace bf {

Eigen::MatrixXd TruncatedSvd::reconstruct() const { return reconstruct(rank()); }

Eigen::MatrixXd TruncatedSvd::reconstruct(int K) const {
  if (K < 0 || K > rank())
    throw std::invalid_argument("svd reconstruct: expected 0 <= K <= " + std::to_string(rank()) +
                                ", found " + std::to_string(K));
  return U.leftCols(K) * sigma.head(K).asDiagonal() * V.leftCols(K).transpose();
}

TruncatedSvd truncated_svd(const Eigen::MatrixXd& A, int rank) {
  if (rank < 1) throw std::invalid_argument("svd: rank must be >= 1, found " + std::to_string(rank));
  if (A.size() == 0) throw std::invalid_argument("svd: the matrix is empty");
  if (!A.allFinite()) throw std::invalid_argument("svd: the matrix has non-finite entries");
  // SVD is homogeneous: decompose A / max|A| and scale the singular values back,
  // so tables of denormal (or huge) values never meet 1/norm overflow inside the SVD.
  const double amax = A.cwiseAbs().maxCoeff();
  const double scale = amax > 0.0 ? amax : 1.0;
  Eigen::BDCSVD<Eigen::MatrixXd> svd(A / scale, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const int K = std::min<int>(rank, int(svd.singularValues().size()));
  TruncatedSvd r;
  r.sigma = svd.singularValues() * scale;
  r.U = svd.matrixU().leftCols(K);
  r.V = svd.matrixV().leftCols(K);
  for (int k = 0; k < K; ++k)
    if (r.U.col(k).sum() < 0.0) {
      r.U.col(k) *= -1.0;
      r.V.col(k) *= -1.0;
    }
  return r;
}

double eckart_young_error(const Eigen::VectorXd& sigma, int K) {
  if (K < 0) throw std::invalid_argument("eckart_young_error: K must be >= 0");
  if (K >= sigma.size()) return 0.0;
  return sigma.tail(sigma.size() - K).norm();
}

int rank_for_energy(const Eigen::VectorXd& sigma, double eps) {
  if (!(eps >= 0.0 && eps < 1.0))
    throw std::invalid_argument("rank_for_energy: eps must be in [0, 1), found " + std::to_string(eps));
  const double total = sigma.squaredNorm();
  if (total == 0.0) return 0;
  double acc = 0.0;
  for (int k = 0; k < sigma.size(); ++k) {
    acc += sigma[k] * sigma[k];
    if (acc >= (1.0 - eps) * total) return k + 1;
  }
  return int(sigma.size());
}

}  // namespace bf
