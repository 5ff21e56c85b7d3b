// core/rng.h — deterministic random numbers.
// PCG32 (O'Neill 2014): small state, good quality, cheap to seed per pixel or
// per photon path, so results never depend on thread scheduling. hashCombine
// derives independent stream seeds from (seed, index, ...).
#pragma once
#include <cstdint>

namespace tdpm {

// SplitMix64 finaliser: a bijective 64-bit mix, used to derive seeds.
inline uint64_t mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline uint64_t hashCombine(uint64_t a, uint64_t b) { return mix64(a ^ mix64(b)); }
inline uint64_t hashCombine(uint64_t a, uint64_t b, uint64_t c) { return hashCombine(hashCombine(a, b), c); }

class Rng {
 public:
  Rng() = default;
  explicit Rng(uint64_t seed, uint64_t stream = 0) { reseed(seed, stream); }

  void reseed(uint64_t seed, uint64_t stream = 0) {
    state_ = 0;
    inc_ = (mix64(stream) << 1u) | 1u;
    nextU32();
    state_ += mix64(seed);
    nextU32();
  }

  uint32_t nextU32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1): 24 random mantissa bits, never returns 1.
  float uniform() { return float(nextU32() >> 8) * 0x1p-24f; }

  // Uniform integer in [0, n), n > 0 (Lemire's nearly divisionless method).
  uint32_t below(uint32_t n) {
    uint64_t m = uint64_t(nextU32()) * uint64_t(n);
    uint32_t l = uint32_t(m);
    if (l < n) {
      uint32_t t = (0u - n) % n;
      while (l < t) {
        m = uint64_t(nextU32()) * uint64_t(n);
        l = uint32_t(m);
      }
    }
    return uint32_t(m >> 32);
  }

 private:
  uint64_t state_ = 0x853c49e6748fea9bull;
  uint64_t inc_ = 0xda3e39cb94b95bdbull;
};

}  // namespace tdpm
