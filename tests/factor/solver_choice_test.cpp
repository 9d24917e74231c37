// Tests of choose_linear_solver (factor/solver_choice.h): Auto's dense/sparse
// switch at each threshold, and that an explicit choice is never overridden.
#include <catch2/catch.hpp>

#include "factor/solver_choice.h"

using namespace bf;
using S = FitOptions::Solver;

TEST_CASE("Auto solves dense up to kDenseMaxUnknowns with few samples", "[solver_choice]") {
  const size_t few = kManySamples - 1;
  CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknowns - 1, few) == S::Dense);
  CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknowns, few) == S::Dense);
  CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknowns + 1, few) == S::Sparse);
  CHECK(choose_linear_solver(S::Auto, 1, 0) == S::Dense);
  CHECK(choose_linear_solver(S::Auto, 0, 0) == S::Dense);
}

TEST_CASE("Auto solves dense up to kDenseMaxUnknownsManySamples with many samples", "[solver_choice]") {
  for (const size_t many : {kManySamples, kManySamples + 1, size_t(10) * kManySamples}) {
    CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknownsManySamples - 1, many) == S::Dense);
    CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknownsManySamples, many) == S::Dense);
    CHECK(choose_linear_solver(S::Auto, kDenseMaxUnknownsManySamples + 1, many) == S::Sparse);
  }
}

TEST_CASE("Auto's sample threshold switches at kManySamples", "[solver_choice]") {
  // Between the two unknown thresholds the number of samples decides.
  const size_t between = (kDenseMaxUnknowns + kDenseMaxUnknownsManySamples) / 2;
  REQUIRE(between > kDenseMaxUnknowns);
  REQUIRE(between < kDenseMaxUnknownsManySamples);
  CHECK(choose_linear_solver(S::Auto, between, kManySamples - 1) == S::Sparse);
  CHECK(choose_linear_solver(S::Auto, between, kManySamples) == S::Dense);
  CHECK(choose_linear_solver(S::Auto, between, kManySamples + 1) == S::Dense);
}

TEST_CASE("An explicit solver is never overridden by the size", "[solver_choice]") {
  const size_t unknowns[] = {0, 1, kDenseMaxUnknowns, kDenseMaxUnknowns + 1, kDenseMaxUnknownsManySamples + 1,
                             size_t(1) << 30};
  const size_t samples[] = {0, 1, kManySamples - 1, kManySamples, size_t(1) << 30};
  for (const S s : {S::Dense, S::Sparse, S::ReferenceQR})
    for (const size_t m : unknowns)
      for (const size_t n : samples) CHECK(choose_linear_solver(s, m, n) == s);
}

TEST_CASE("Auto never returns Auto", "[solver_choice]") {
  for (const size_t m : {size_t(0), kDenseMaxUnknowns, kDenseMaxUnknownsManySamples + 1})
    for (const size_t n : {size_t(0), kManySamples}) CHECK(choose_linear_solver(S::Auto, m, n) != S::Auto);
}
