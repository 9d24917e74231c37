// Linear projections of the 4D domain onto a texture, the projection mask
// (thesis 3.2.4) and bilinear texel weights (thesis 3.2.7).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "brdfs/directions.h"

namespace bf {

using Mat24 = Eigen::Matrix<double, 2, 4>;

// A term's projection: x in [-1,1]^4 (the point of (wi, wo) under `param`) maps
// to texture coordinates
//   u = P x (2-vector), s = (u_r / l1(P_r) + 1) / 2 * (res - 1)   per row r,
// so the image of the 4-cube fills [0, res-1]^2 exactly in each axis
// (l1 = sum of absolute entries of the row). Texel (i, j) sits at s = (i, j);
// texel index = j * res + i.
struct Projection {
  Parameterization param = Parameterization::WiWo;
  Mat24 P = Mat24::Zero();  // rows orthonormal (not checked here; see validate())
  int res = 16;             // texture is res x res

  // Conjugate projection of docs/design.md §2: wiwo swaps column pairs, halfdiff
  // negates the d columns. pi*(wi, wo) = pi(wo, wi).
  Projection conjugate() const;
  // Whether conjugate() equals this projection to 1e-12.
  bool self_conjugate() const;
  // Texture coordinates of a 4D point (see above).
  Eigen::Vector2d texel_coords(const Vec4& x) const;
  // Throws std::invalid_argument naming the field: res in 2..1024, rows of
  // unit length and orthogonal to 1e-6, no zero row.
  void validate() const;
  // Scale applied to each row before the affine map: 1 / l1(P_r).
  Eigen::Vector2d row_scale() const;
};

// Mask of the texels that can be reached (thesis 3.2.4): texels inside the convex
// hull of the 16 projected 4-cube corners plus their 8 neighbours. size res*res.
std::vector<uint8_t> projection_mask(const Projection& p);

// Bilinear weights of a point at texture coordinates s (clamped to [0, res-1]):
// indices of the 4 surrounding texels and their weights (sum 1).
struct Bilinear {
  std::array<int, 4> idx;
  std::array<double, 4> w;
};
Bilinear bilinear(const Eigen::Vector2d& s, int res);

// Standard projections. wi: rows (1,0,0,0),(0,1,0,0); wo: (0,0,1,0),(0,0,0,1).
Projection projection_first_pair(Parameterization param, int res);
Projection projection_second_pair(Parameterization param, int res);

}  // namespace bf
