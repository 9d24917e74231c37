// Tests of the fork-join parallel loop.
#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

#include "solvers/parallel.h"
#include "test_common.h"

using namespace bf;

TEST_CASE("parallel_for: covers the range exactly once, any thread count") {
  for (int threads : {0, 1, 2, 3, 7}) {
    for (int64_t n : {0, 1, 5, 1000}) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(n));
      parallel_for(n, [&](int64_t a, int64_t b) {
        for (int64_t k = a; k < b; ++k) hits[size_t(k)]++;
      }, threads);
      for (const auto& h : hits) CHECK(h.load() == 1);
    }
  }
}

TEST_CASE("parallel_for: an exception in a chunk is rethrown after joining") {
  REQUIRE_THROWS_WITH(parallel_for(100, [](int64_t a, int64_t b) {
                        for (int64_t k = a; k < b; ++k)
                          if (k == 77) throw std::invalid_argument("bad index 77");
                      }, 4),
                      "bad index 77");
}

TEST_CASE("parallel_for_each: every index exactly once at any thread count and an exception is rethrown") {
  for (int threads : {0, 1, 2, 3, 7}) {
    for (int64_t n : {-1, 0, 1, 5, 1000}) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(std::max<int64_t>(n, 0)));
      parallel_for_each(n, [&](int64_t i) { hits[size_t(i)]++; }, threads);
      for (const auto& h : hits) CHECK(h.load() == 1);
    }
  }
  REQUIRE_THROWS_WITH(parallel_for_each(100, [](int64_t i) {
                        if (i == 77) throw std::invalid_argument("bad index 77");
                      }, 4),
                      "bad index 77");
}
