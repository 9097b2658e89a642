#pragma once
// Seeds derived from seeds: the one rule every seeded part of the project uses to give each of many things (a
// session's trials, a plan's studies and participants) its own stream from one recorded number. splitmix64 of
// seed + golden-ratio step x (index + 1): neighbouring indices give unrelated seeds, the same on every platform.
#include <cstdint>

namespace blurcue {

// The seed of item `index` (0-based) of whatever `seed` seeds.
inline uint64_t DeriveSeed(uint64_t seed, uint64_t index) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (index + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace blurcue
