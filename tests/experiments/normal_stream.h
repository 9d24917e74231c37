// A portable standard normal stream for planted noisy samples (SplitMix64 +
// Box-Muller): the same numbers on every platform, unlike std::normal_distribution.
#pragma once

#include <cmath>
#include <cstdint>

#include "experiments/common/splitmix.h"

namespace bf_test {

struct Normal {
  uint64_t x;
  double uniform() { return (double(bf::splitmix(x) >> 11) + 0.5) / 9007199254740992.0; }
  double operator()() { return std::sqrt(-2 * std::log(uniform())) * std::cos(6.283185307179586 * uniform()); }
};

}  // namespace bf_test
