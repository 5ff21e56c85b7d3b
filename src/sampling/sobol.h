// sampling/sobol.h — the Sobol sequence (Joe & Kuo 2008 direction numbers)
// and hash-based Owen scrambling (Burley 2020, "Practical Hash-based Owen
// Scrambling", JCGT 9(4)), the building blocks of sampling/sampler.h.
//
// Points are 32-bit binary fractions (bit 31 = 1/2). sobolBits(i, d) is
// the plain (unscrambled) point of index i in dimension d, in index order
// (not Gray-code order): the first 2^m points of dimensions 0 and 1 form a
// (0,m,2)-net, every 2^m-aligned block of indices too; dimension 2 is
// stratified on its own and a (1,m,2)-net with either of the others
// (tests/test_sampler.cpp checks this). Only these three are needed: the
// sampler pads with independently scrambled copies instead of using higher
// dimensions.
//
// owenScramble(v, seed) is a nested uniform scramble: digit k of the
// fraction is flipped by a hash of the seed and the digits before it, so
// every elementary interval keeps its point count (nets stay nets) while the
// point set becomes uniformly distributed. shuffleIndex(i, seed) applies the
// same scramble to the index read as a reversed fraction: aligned blocks of
// 2^m indices map onto aligned blocks of 2^m indices, so the first 2^m
// samples of a shuffled sequence are still a net, and a sample count that
// grows (adaptive batches, progressive passes) keeps extending it.
#pragma once
#include <cstdint>

namespace tdpm {

// Dimensions with embedded direction numbers (dimension 0 is van der
// Corput; 1.. are Joe-Kuo's new-joe-kuo-6.21201 lines d = 2..).
constexpr int kSobolDims = 3;

// Bits within bytes, then the bytes with one bswap.
inline uint32_t reverseBits32(uint32_t v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
  return __builtin_bswap32(v);
}

// Lines d = 2..kSobolDims of Joe & Kuo's table new-joe-kuo-6.21201 (S. Joe
// and F. Y. Kuo, "Constructing Sobol sequences with better two-dimensional
// projections", SIAM J. Sci. Comput. 30, 2008): degree s, polynomial
// coefficients a, initial direction numbers m_1..m_s.
struct SobolDirectionNumbers {
  int s;
  uint32_t a;
  uint32_t m[3];
};
constexpr SobolDirectionNumbers kJoeKuo[kSobolDims - 1] = {
    {1, 0, {1, 0, 0}},
    {2, 1, {1, 3, 0}},
};

// Generator matrix columns: column k of dimension d is the point of index
// 2^k. v_k = m_k / 2^k, then the Bratley-Fox recurrence
// v_k = a_1 v_{k-1} ^ ... ^ a_{s-1} v_{k-s+1} ^ v_{k-s} ^ (v_{k-s} >> s).
struct SobolMatrices {
  uint32_t c[kSobolDims][32];
};
constexpr SobolMatrices makeSobolMatrices() {
  SobolMatrices r{};
  for (int k = 0; k < 32; ++k) r.c[0][k] = 1u << (31 - k);
  for (int d = 1; d < kSobolDims; ++d) {
    const SobolDirectionNumbers& dn = kJoeKuo[d - 1];
    uint32_t* v = r.c[d];
    for (int k = 0; k < dn.s; ++k) v[k] = dn.m[k] << (31 - k);
    for (int k = dn.s; k < 32; ++k) {
      uint32_t x = v[k - dn.s] ^ (v[k - dn.s] >> dn.s);
      for (int j = 1; j < dn.s; ++j)
        if ((dn.a >> (dn.s - 1 - j)) & 1u) x ^= v[k - j];
      v[k] = x;
    }
  }
  return r;
}
inline constexpr SobolMatrices kSobolMatrices = makeSobolMatrices();
inline const uint32_t* sobolMatrix(int d) { return kSobolMatrices.c[d]; }

// ---- the scrambled points in the reversed-bit form (Burley 2020, sec. 4)
// The scramble works on reversed bits (bit 0 = digit 1/2), and the index
// shuffle produces its result reversed too: r = LK(reverse(i)), shuffled
// index reverse(r). Staying in that form saves the bit reversals in
// between: a point costs one reversal (at the end) plus one per group for
// dimension 0, where the old composition took three per dimension.
// Dimensions 1 and 2 come from byte tables indexed by the bytes of r:
// entry [b][v] is reverse(XOR of the generator columns of index byte 3 - b
// with bit pattern reverse8(v)), so four loads give reverse(sobolBits(
// reverse(r), d)) without reversing r (and without a loop over the ~16 set
// bits of a shuffled index). 2 x 4 KB, read-only.
constexpr uint32_t reverseBits32Constexpr(uint32_t v) {
  uint32_t r = 0;
  for (int k = 0; k < 32; ++k) r |= ((v >> k) & 1u) << (31 - k);
  return r;
}
struct SobolReversedTables {
  uint32_t t[kSobolDims - 1][4][256];
};
constexpr SobolReversedTables makeSobolReversedTables() {
  SobolReversedTables r{};
  for (int d = 1; d < kSobolDims; ++d)
    for (int b = 0; b < 4; ++b)       // byte b of r (bits 8b..8b+7) ...
      for (uint32_t v = 0; v < 256; ++v) {
        uint32_t x = 0;
        for (int k = 0; k < 8; ++k)   // ... bit 8b+k of r is index bit 31-8b-k
          if ((v >> k) & 1u) x ^= kSobolMatrices.c[d][31 - 8 * b - k];
        r.t[d - 1][b][v] = reverseBits32Constexpr(x);
      }
  return r;
}
inline constexpr SobolReversedTables kSobolReversed = makeSobolReversedTables();

// reverse(sobolBits(reverse(r), d)): the Sobol point of the index whose
// reversed bits are r, itself reversed.
inline uint32_t sobolReversedOfReversedIndex(uint32_t r, int d) {
  if (d == 0) return reverseBits32(r);
  const uint32_t(*t)[256] = kSobolReversed.t[d - 1];
  return t[0][r & 0xFFu] ^ t[1][(r >> 8) & 0xFFu] ^ t[2][(r >> 16) & 0xFFu] ^ t[3][r >> 24];
}

// Plain Sobol point, dimension d, index i.
inline uint32_t sobolBits(uint32_t i, int d) {
  if (d == 0) return reverseBits32(i);
  const uint32_t* m = sobolMatrix(d);
  uint32_t v = 0;
  for (; i; i &= i - 1) v ^= m[__builtin_ctz(i)];
  return v;
}

// Laine-Karras style hash: bit k of the result depends only on bits <= k
// of x (multiplications and additions carry upwards only), so reversed it
// flips a fraction's digit by the digits above it: Owen scrambling.
inline uint32_t laineKarrasPermutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

inline uint32_t owenScramble(uint32_t v, uint32_t seed) {
  return reverseBits32(laineKarrasPermutation(reverseBits32(v), seed));
}

inline uint32_t shuffleIndex(uint32_t i, uint32_t seed) { return owenScramble(i, seed); }

// owenScramble(sobolBits(shuffleIndex(i, shuffleSeed), d), seed), given
// reversedShuffled = laineKarrasPermutation(reverseBits32(i), shuffleSeed).
inline uint32_t scrambledSobolReversed(uint32_t reversedShuffled, int d, uint32_t seed) {
  return reverseBits32(laineKarrasPermutation(sobolReversedOfReversedIndex(reversedShuffled, d), seed));
}

// 32-bit fraction -> float in [0, 1) (24 bits; never rounds up to 1).
inline float bitsToFloat01(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

}  // namespace tdpm
