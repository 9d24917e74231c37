// Shared by the bounded-extrapolation tests (extrapolation_test.cpp,
// log_range_test.cpp): sparse sample sets as measurements give, and the
// largest approx/original ratio over the whole domain.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"
#include "fit_helpers.h"

namespace bf_test {

using namespace bf;

// Directions at the centres of a g x g grid of equal-solid-angle cells
// (cos theta, phi), the whole hemisphere, grazing included.
inline std::vector<Vec3> hemisphere_grid(int g) {
  std::vector<Vec3> out;
  for (int t = 0; t < g; ++t)
    for (int p = 0; p < g; ++p) {
      const double ct = (t + 0.5) / g, st = std::sqrt(1 - ct * ct), ph = 2 * M_PI * (p + 0.5) / g;
      out.emplace_back(st * std::cos(ph), st * std::sin(ph), ct);
    }
  return out;
}

// max over a 12^4 grid of direction pairs and the channels of
// approx_c / (max of the original's channel c over the same grid).
inline double max_ratio(const Brdf& approx, const Brdf& original) {
  const std::vector<Vec3> dirs = hemisphere_grid(12);
  Rgb omax = Rgb::Zero(), amax = Rgb::Zero();
  for (const Vec3& wi : dirs)
    for (const Vec3& wo : dirs) {
      omax = omax.max(original.eval(wi, wo));
      amax = amax.max(approx.eval(wi, wo));
    }
  return (amax / omax).maxCoeff();
}

// A sparse sample set as measurements give: wi only in the plane phi_i = 0
// (as the Cornell gonioreflectometer, data/cornell), theta_i and theta_o up to
// `max_theta` degrees, each value times exp(noise * N(0, 1)) (measurement
// noise). A 3D slice of part of the 4D domain.
inline SampleSet sparse_samples(const Brdf& b, size_t n, double max_theta, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> Z(0.0, 1.0);
  SampleSet s;
  const double cmin = std::cos(max_theta * M_PI / 180.0);
  for (size_t k = 0; k < n; ++k) {
    const double ti = std::acos(cmin + (1 - cmin) * U(rng));
    const double co = cmin + (1 - cmin) * U(rng), so = std::sqrt(1 - co * co), po = 2 * M_PI * U(rng);
    const Vec3 wi(std::sin(ti), 0.0, std::cos(ti)), wo(so * std::cos(po), so * std::sin(po), co);
    s.wi.push_back(wi);
    s.wo.push_back(wo);
    s.value.push_back(b.eval(wi, wo) * std::exp(noise * Z(rng)));
    s.valid.push_back(1);
  }
  return s;
}

inline std::vector<TermSpec> random_wiwo_terms(int res, uint64_t seed) {
  std::mt19937_64 rng(seed);
  return {{bf_test::random_projection(rng, Parameterization::WiWo, res), false, std::nullopt},
          {bf_test::random_projection(rng, Parameterization::WiWo, res), false, std::nullopt}};
}


}  // namespace bf_test
