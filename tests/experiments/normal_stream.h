// A portable standard normal stream for planted noisy samples (SplitMix64 +
// Box-Muller): the same numbers on every platform, unlike std::normal_distribution.
#pragma once

#include <cmath>
#include <cstdint>

namespace bf_test {

struct Normal {
  uint64_t x;
  double uniform() {
    uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return (double((z ^ (z >> 31)) >> 11) + 0.5) / 9007199254740992.0;
  }
  double operator()() { return std::sqrt(-2 * std::log(uniform())) * std::cos(6.283185307179586 * uniform()); }
};

}  // namespace bf_test
