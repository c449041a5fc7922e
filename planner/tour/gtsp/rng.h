// Small, fast, portable pseudo-random generator for the GTSP search
// (xoshiro256** seeded through splitmix64). Unlike <random> distributions, the
// sequences it produces are identical on every platform and standard library,
// which keeps seeded runs reproducible.
//
//   Rng rng(SeedFor(seed, trial));
//   int i = rng.UniformInt(10);      // 0..9
//   double u = rng.Uniform();        // [0, 1)
//
// Thread-safety: not thread-safe; use one instance per thread.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_RNG_H_
#define COVPLAN_PLANNER_TOUR_GTSP_RNG_H_

#include <cstdint>

namespace covplan::gtsp_internal {

inline uint64_t SplitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// Seed of trial `index` derived from the user seed, so trials are independent.
inline uint64_t SeedFor(uint64_t seed, uint64_t index) {
  uint64_t s = seed ^ (0xD1B54A32D192ED03ULL * (index + 1));
  return SplitMix64(s);
}

class Rng {
 public:
  explicit Rng(uint64_t seed) {
    uint64_t s = seed;
    for (uint64_t& w : s_) w = SplitMix64(s);
  }

  uint64_t Next() {
    const uint64_t result = Rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = Rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }

  // Uniform in [0, n); n > 0. Lemire's multiply-shift (bias < 2^-32 for our n).
  int UniformInt(int n) {
    return static_cast<int>(((Next() >> 32) * static_cast<uint64_t>(n)) >> 32);
  }

  // Uniform in [lo, hi].
  int UniformInt(int lo, int hi) { return lo + UniformInt(hi - lo + 1); }

 private:
  static uint64_t Rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

}  // namespace covplan::gtsp_internal

#endif  // COVPLAN_PLANNER_TOUR_GTSP_RNG_H_
