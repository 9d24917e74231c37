// SplitMix64: a small, portable, well-mixed generator (std::shuffle's and
// std::uniform_*_distribution's algorithms are unspecified, so seeded draws
// that must be the same on every platform use this).
#pragma once

#include <cstdint>

namespace bf {

// Advances the state x and returns the next 64-bit value.
inline uint64_t splitmix(uint64_t& x) {
  uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace bf
