// Reading projection planes off the data (seeds for the structured search).
//
// If the log BRDF is g(x) = a(P1 x) + b(P2 x) with P1, P2 the two orthogonal
// planes of a 4D rotation R, every Hessian of g is block-diagonal in R's
// frame: H(x) = R [Ha 0; 0 Hb] R^T, the mixed second derivatives between the
// planes vanish everywhere. We estimate Hessians at scattered centres by local
// weighted quadratic regression (no grid needed, so both parameterizations
// work on any sample set), then look for the rotation that makes them all
// block-diagonal: the eigenvectors of sum H^2 (block-diagonal too) paired
// three ways, each pairing polished by Powell on the off-block energy.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "search/rotation4.h"

namespace bf {

struct StructureOptions {
  int centres = 1200;      // Hessians estimated (random samples as centres), >= 1
  double radius = 0.35;    // neighbourhood radius in the 4D point space, > 0
  int min_neighbours = 30; // centres with fewer neighbours are skipped, >= 15
  uint64_t seed = 1;       // choice of the centres
};

// The neighbourhood radius for a set of n samples (the structured search's):
// StructureOptions' 0.35 at 40,000 samples or more (a 16^4 parabolic grid
// holds 43,264), growing as n^(-1/4) below, so that a ball holds about as many
// samples, at most 0.8. At 0.35 the local quadratic fits on a 10^4 grid (6,400
// samples) are too noisy to split the planes: 15 of the planted wiwo family's
// members 0..63 got mixed seed planes (off-block 0.07-0.21); at 0.55, none
// (grids 8 and 12 likewise).
double structure_radius(size_t samples);

// Hessians (4x4, symmetric) of y at up to opt.centres sample points, by a local
// quadratic least-squares fit with weights w_k (1 - (d/r)^2)^2 over the
// samples within opt.radius. x and y have one entry per sample; w may be empty
// (all 1). Centres whose fit is singular or under-populated are skipped.
std::vector<Eigen::Matrix4d> local_hessians(const std::vector<Vec4>& x, const std::vector<double>& y,
                                            const std::vector<double>& w, const StructureOptions& opt);

// local_hessians for many y on one sample set. The centres, their neighbours
// (sample indices) and each centre's factorized normal matrix depend only on
// x, w and opt, so they are found once here; each call then costs one pass
// over the neighbours per centre (the structured search reads the Hessians of
// every residual it seeds from: on W1's 5-term search the repeated neighbour
// search and normal matrices were about a third of its time). Results are
// those of local_hessians bit for bit (same neighbours, same order, same
// factorization). Keeps a copy of x and w, in its own (bucket) order.
class LocalHessians {
 public:
  LocalHessians(const std::vector<Vec4>& x, const std::vector<double>& w, const StructureOptions& opt);
  // y: one value per sample of x. Centres whose fit is not finite are skipped.
  std::vector<Eigen::Matrix4d> operator()(const std::vector<double>& y) const;

 private:
  using Mat15 = Eigen::Matrix<double, 15, 15>;
  struct Centre {
    size_t index;  // the centre's sample
    size_t first, count;  // its neighbours in neighbours_
    Eigen::LDLT<Mat15> ldlt;
  };
  std::vector<Vec4> x_;
  std::vector<double> w_;
  double r_;
  // Each centre's neighbours (sample indices; a weight is recomputed from the
  // distance when read: 4 bytes a neighbour, about 22,000 neighbours a centre
  // on 3 million samples).
  std::vector<uint32_t> neighbours_;
  // x_ and w_ are stored bucket by bucket (the constructor): stored sample k is input sample perm_[k].
  std::vector<uint32_t> perm_;
  std::vector<Centre> centres_;
};

struct PlaneSplit {
  // first: a rotation whose projection (columns 0, 1 of its matrix) is plane A;
  // second: the same frame with the planes swapped (projection = plane B).
  Rotation4 first, second;
  // Off-block energy sum |A^T H B|_F^2 / sum |H|_F^2 over the Hessians (0 for
  // an exact two-plane function; ~0.5 for unstructured data).
  double off_block = 1;
  // Share of sum |H|_F^2 in plane A's block (the plane carrying more curvature
  // is A, so share_a >= 1/2 up to the other terms).
  double share_a = 0.5;
};

// The plane pair that block-diagonalizes the Hessians best (see the file comment).
// Throws std::invalid_argument for an empty list.
PlaneSplit split_planes(const std::vector<Eigen::Matrix4d>& hessians);

}  // namespace bf
