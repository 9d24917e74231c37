// BRDFs that are exactly a product of a few projected textures (planted
// structure for testing and benchmarking projection searches):
//   f(wi, wo) = c * exp(sum_t a_t(P_t x_t)),
// x_t the point of (wi, wo) in term t's parameterization, P_t a 2x4 projection
// with orthonormal rows, a_t a smooth function of the plane (a few Gaussian
// bumps plus linear and quadratic terms); c = (1, 0.8, 0.6) per channel.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "brdfs/brdf.h"
#include "factor/homomorphic_fit.h"
#include "search/rotation4.h"

namespace bf {

// A smooth function of the plane: scale * (l.u + u^T Q u / 2 + sum_i A_i exp(-|u - m_i|^2 / (2 s_i^2))).
struct PlaneFunction {
  Eigen::Vector2d linear = Eigen::Vector2d::Zero();
  Eigen::Matrix2d quadratic = Eigen::Matrix2d::Zero();
  std::vector<std::array<double, 4>> bumps;  // {A, m_x, m_y, s}
  double scale = 1;
  double operator()(const Eigen::Vector2d& u) const;
  // A random function (a few bumps, low-order terms), scale 1.
  static PlaneFunction random(std::mt19937_64& rng);
};

struct PlantedTerm {
  Parameterization param = Parameterization::WiWo;
  Mat24 P = Mat24::Zero();  // orthonormal rows
  PlaneFunction a;
};

class PlantedProductBrdf final : public Brdf {
 public:
  explicit PlantedProductBrdf(std::vector<PlantedTerm> terms, std::string label = "planted");
  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  std::string name() const override { return "planted"; }
  std::string to_string() const override { return label_; }
  bool reciprocal() const override { return false; }
  bool isotropic() const override { return false; }
  const std::vector<PlantedTerm>& terms() const { return terms_; }
  // The true projections as fit specs at texture res (for the floor: fit at them).
  std::vector<TermSpec> specs(int res) const;
  // The distance 2 - |P P_true^T|_F^2 from plane P (orthonormal rows) to the
  // nearest true plane of parameterization `param`: 0 for a true plane, 2 when
  // no term reads `param`.
  double nearest_plane_distance(Parameterization param, const Mat24& P) const;

 private:
  std::vector<PlantedTerm> terms_;
  std::string label_;
};

// Member `index` of the planted-rotation family: a random 4D rotation R (seeded
// by index) and, for terms = 2, the textures a(plane A of R) + b(plane B of R),
// both in `param`; for terms = 3, a third texture on the first plane of a
// second random rotation in the other parameterization (a mixture, like
// McCool's form); for terms = 4, a fourth texture on that rotation's second
// plane (two planes in each parameterization). Each a_t is scaled so its range
// over the grid points is 10^1.25..10^1.5 times 2 / terms, so f spans about
// 10^2.5..10^3. Throws std::invalid_argument for terms other than 2, 3 or 4.
PlantedProductBrdf planted_rotation_brdf(int index, int terms, Parameterization param);

// Member `index` of the planted pairs across parameterizations: the texture
// a(plane A of a random rotation) read through `first` times b(plane A of a
// second random rotation) read through the other parameterization, each
// scaled as a 2-term member of planted_rotation_brdf. The mixed family's
// 2-term members (`bench planted --family mixed`).
PlantedProductBrdf planted_mixed_pair_brdf(int index, Parameterization first);

// A BRDF of exact McCool form p(wi) q(h) p(wo) (random smooth p and q, seeded):
// p on the wi and wo planes of wiwo, q on the h plane of halfdiff.
PlantedProductBrdf planted_mccool_brdf(int index);

}  // namespace bf
