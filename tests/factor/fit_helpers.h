// Shared BRDFs and helpers for the fitter tests: product-separable BRDFs with
// known factors (planted solutions) and random orthonormal projections.
#pragma once

#include <Eigen/QR>
#include <random>

#include "brdfs/directions.h"
#include "factor/projection.h"

namespace bf_test {

// A smooth positive function of a parabolic point: exp(c0 x + c1 y + c2 x^2 + c3 x y).
inline double smooth_factor(const Eigen::Vector2d& p, double c0, double c1, double c2, double c3) {
  return std::exp(c0 * p.x() + c1 * p.y() + c2 * p.x() * p.x() + c3 * p.x() * p.y());
}

// f = a(p(wi)) b(p(wo)) c(p(h)): exactly a sum of three log terms under the
// projections wiwo-first, wiwo-second and halfdiff-first.
class PlantedBrdf final : public bf::Brdf {
 public:
  bf::Rgb eval(const bf::Vec3& wi, const bf::Vec3& wo) const override {
    if (wi.z() <= 0 || wo.z() <= 0) return bf::Rgb::Zero();
    const bf::Vec3 h = (wi + wo).normalized();
    const double a = smooth_factor(bf::parabolic(wi), 0.4, -0.3, 0.5, 0.2);
    const double b = smooth_factor(bf::parabolic(wo), -0.2, 0.5, -0.4, 0.3);
    const double c = smooth_factor(bf::parabolic(h), 0.3, 0.2, -0.8, -0.5);
    return bf::Rgb(0.2, 0.3, 0.5) * (a * b * c);
  }
  std::string name() const override { return "planted"; }
  std::string to_string() const override { return "planted a(wi) b(wo) c(h)"; }
  bool reciprocal() const override { return false; }
};

// f = p(wi) q(h) p(wo): McCool's form, p shared between wi and wo.
class McCoolFormBrdf final : public bf::Brdf {
 public:
  bf::Rgb eval(const bf::Vec3& wi, const bf::Vec3& wo) const override {
    if (wi.z() <= 0 || wo.z() <= 0) return bf::Rgb::Zero();
    const bf::Vec3 h = (wi + wo).normalized();
    const double pi = smooth_factor(bf::parabolic(wi), 0.2, -0.1, -0.9, 0.1);
    const double po = smooth_factor(bf::parabolic(wo), 0.2, -0.1, -0.9, 0.1);
    const double q = smooth_factor(bf::parabolic(h), 0.1, 0.05, -2.0, 0.0) *
                     std::exp(-1.5 * bf::parabolic(h).squaredNorm());
    return bf::Rgb(0.6, 0.4, 0.3) * (pi * q * po);
  }
  std::string name() const override { return "mccool-form"; }
  std::string to_string() const override { return "p(wi) q(h) p(wo)"; }
};

// Random 2x4 projection with orthonormal rows (QR of a Gaussian matrix).
inline bf::Projection random_projection(std::mt19937_64& rng, bf::Parameterization param, int res) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Matrix4d G;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) G(i, j) = N(rng);
  const Eigen::Matrix4d Q = Eigen::HouseholderQR<Eigen::Matrix4d>(G).householderQ();
  bf::Projection p;
  p.param = param;
  p.res = res;
  p.P = Q.leftCols<2>().transpose();
  return p;
}

}  // namespace bf_test
