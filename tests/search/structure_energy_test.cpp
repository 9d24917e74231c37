// split_planes' energies as numbers (search/structure.h): on Hessians with a
// known, nonzero off-block part the reported off-block energy and plane A's
// share are their closed forms, and plane A is the one with more curvature
// even when the two planes' energies differ by less than the off-block energy.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "search/rotation4.h"
#include "search/structure.h"

using namespace bf;

namespace {

// 2 - |P_a P_b^T|_F^2: 0 for the same plane.
double plane_gap(const Mat24& a, const Mat24& b) { return 2 - (a * b.transpose()).squaredNorm(); }

Mat24 projection_plane(const Rotation4& R) { return R.projection(Parameterization::WiWo, 8).P; }

}  // namespace

TEST_CASE("structure: split_planes reports the closed-form off-block energy and plane shares") {
  // In a frame Q, H_k = Q [Da_k E_k; E_k^T Db_k] Q^T. Each Hessian comes with a
  // twin whose E is negated: for any frame the off-block parts of D +- E then
  // sum to 2|off(D)|^2 + 2|off(E)|^2, so Q's planes (where every D is block
  // diagonal) are the exact minimum and the energies there are
  //   off_block = sum_k |E_k|_F^2 * 2 / sum_k |H_k|_F^2,
  //   share_a   = sum_k |Da_k|_F^2 / sum_k |H_k|_F^2.
  // The parts are scaled so that sum |Db|^2 = 0.98 sum |Da|^2 and
  // 2 sum |E|^2 = 0.05 sum |Da|^2: total 2.03 sum |Da|^2, off_block =
  // 0.05 / 2.03, share_a = 1 / 2.03 (plane B: 0.98 / 2.03). Plane B's share plus
  // the off-block energy (1.03 / 2.03) exceeds plane A's, so a split that
  // compares A with everything but A swaps the planes; an off-block energy
  // counted once (not for both off-diagonal blocks) is half.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Matrix4d Q = Rotation4::random(rng).matrix();
    const int n = 50;
    std::vector<Eigen::Matrix2d> Da(n), Db(n), E(n);
    double ea = 0, eb = 0, ee = 0;
    for (int k = 0; k < n; ++k) {
      Da[k] << U(rng), U(rng), 0, U(rng);
      Da[k](1, 0) = Da[k](0, 1);
      Db[k] << U(rng), U(rng), 0, U(rng);
      Db[k](1, 0) = Db[k](0, 1);
      E[k] << U(rng), U(rng), U(rng), U(rng);
      ea += Da[k].squaredNorm();
      eb += Db[k].squaredNorm();
      ee += E[k].squaredNorm();
    }
    const double sb = std::sqrt(0.98 * ea / eb), se = std::sqrt(0.05 * ea / (2 * ee));
    std::vector<Eigen::Matrix4d> hs;
    for (int k = 0; k < n; ++k)
      for (const double sign : {1.0, -1.0}) {
        Eigen::Matrix4d B;
        B.block<2, 2>(0, 0) = Da[k];
        B.block<2, 2>(2, 2) = sb * Db[k];
        B.block<2, 2>(0, 2) = sign * se * E[k];
        B.block<2, 2>(2, 0) = sign * se * E[k].transpose();
        hs.push_back(Q * B * Q.transpose());
      }
    const PlaneSplit s = split_planes(hs);
    Mat24 A, Bp;
    A << Q.col(0).transpose(), Q.col(1).transpose();
    Bp << Q.col(2).transpose(), Q.col(3).transpose();
    INFO("trial " << trial << ": off-block " << s.off_block << " (closed form " << 0.05 / 2.03 << "), share of A "
                  << s.share_a << " (closed form " << 1 / 2.03 << ")");
    CHECK(s.off_block == Approx(0.05 / 2.03).epsilon(1e-4));
    CHECK(s.share_a == Approx(1.0 / 2.03).epsilon(1e-4));
    CHECK(plane_gap(projection_plane(s.first), A) < 1e-5);
    CHECK(plane_gap(projection_plane(s.second), Bp) < 1e-5);
  }
}
