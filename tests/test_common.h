// Small helpers shared by the tests.
#pragma once

#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "brdfs/brdf.h"

namespace bf_test {

// |a - b| <= tol * max(1, |a|, |b|)
inline bool near_rel(double a, double b, double tol) {
  return std::abs(a - b) <= tol * std::max({1.0, std::abs(a), std::abs(b)});
}

inline std::string str(const bf::Vec3& v) {
  return "(" + std::to_string(v.x()) + ", " + std::to_string(v.y()) + ", " +
         std::to_string(v.z()) + ")";
}

}  // namespace bf_test
