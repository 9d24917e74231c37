// Gauss-Legendre quadrature (nodes by Newton's method on P_n) and the product
// rules on the sphere built from it: Gauss-Legendre in z = cos(theta) times a
// uniform rule in phi. Exact for band-limited integrands (docs/design.md §9); a
// sin(theta)-weighted midpoint rule converges only as N^-2 (notes P9).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace bf {

// n-point Gauss-Legendre rule on [a, b]: nodes x (ascending) and weights w.
// Exact for polynomials of degree <= 2n - 1.
struct GaussLegendre {
  std::vector<double> x, w;
};
// n in 1..100000; throws std::invalid_argument otherwise, or if a <= b fails.
GaussLegendre gauss_legendre(int n, double a = -1.0, double b = 1.0);

// Product rule on the spherical zone z_min <= z <= z_max (z = cos theta):
// n_z Gauss-Legendre nodes in z times n_phi uniform nodes
// phi_j = 2 pi (j + 1/2) / n_phi. Node k = iz * n_phi + jphi.
// Over the full sphere (z in [-1, 1]) it integrates y_i y_j exactly when
// n_z >= F + 1 and n_phi >= 2F + 1 (both of order <= F); over the upper
// hemisphere (z in [0, 1]) the same holds, because for equal |m| the product
// is a polynomial in z of degree <= 2F after the exact phi integration.
struct SphereRule {
  std::vector<Eigen::Vector3d> dir;  // unit directions
  std::vector<double> w;             // weights in sr (sum = 2 pi (z_max - z_min))
  int n_z = 0, n_phi = 0;
  size_t size() const { return dir.size(); }
};
// Throws std::invalid_argument unless n_z >= 1, n_phi >= 1, -1 <= z_min < z_max <= 1.
SphereRule sphere_rule(int n_z, int n_phi, double z_min = -1.0, double z_max = 1.0);

}  // namespace bf
