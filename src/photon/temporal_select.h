// photon/temporal_select.h — the second pass of the two-pass time-dependent
// search (method.md section 4): among the k_s spatial candidates, keep the
// `keep` nearest in time to the query, also bounded by a maximum time
// distance. Works on the candidates' 8-bit time bins.
//
// What is kept, exactly (the tie rule):
//  A photon's time is the centre of its bin, c_q = q + 0.5 (in bin units),
//  and the query u is continuous. Let D be the keep-th smallest |c_q - u|
//  among the candidates. Kept are ALL candidates with |c_q - u| <= D (and
//  <= maxDist): photons tied at the cut are all kept, never split. Since
//  every photon of a bin has the same distance, the kept set is always whole
//  bins, and the window is the contiguous bin interval [lo, hi] of all bins
//  (empty or not) whose centre lies within D of u. Splitting a bin would
//  count part of the bin's photons over the whole bin's length (an
//  underestimate); keeping all of them keeps count and window consistent,
//  so the estimate stays unbiased for a density constant over the window.
//  Keeping more than `keep` photons is harmless: the estimate divides by the
//  window that holds exactly the kept photons.
//
// Two implementations that return identical results:
//  * selectTimeWindow: SIMD (xsimd through math/simd.h, or AVX-512 BW with
//    one mask compare + popcount per 64 candidates, chosen at run time). The bins in order of
//    distance from u form a merge of the two sides (with exact ties merged
//    into one step), so the interval after s steps is closed-form, and the
//    number of candidates inside an interval is a byte range test + count
//    over 32 candidates per instruction. A binary search on s (<= 10 steps)
//    finds the first interval holding >= keep candidates.
//  * selectTimeWindowQuickselect: scalar reference, randomised quickselect on
//    the distances (2|c_q - u| in float, exact for these values).
#pragma once
#include <cstdint>

#include "core/rng.h"

namespace tdpm::photon {

struct TimeWindow {
  int lo = 0, hi = -1;  // kept bins [lo, hi], inclusive; empty if hi < lo
  int kept = 0;         // candidates inside
  bool empty() const { return hi < lo; }
  bool contains(uint8_t q) const { return int(q) >= lo && int(q) <= hi; }
};

// The number of photons to keep from n candidates: ceil(f n) in [1, n].
inline int keptCount(float fraction, int n) {
  if (n <= 0) return 0;
  double m = double(fraction) * double(n);
  int k = int(m);
  if (double(k) < m) ++k;
  return k < 1 ? 1 : (k > n ? n : k);
}

// Twice the distance, in bins, from the centre of bin q to u (exact).
inline float timeKey(int q, float u) {
  float d = float(2 * q + 1) - 2.0f * u;
  return d < 0.0f ? -d : d;
}

// bins: the candidates' time bins; the buffer must be readable (any
// contents) up to n rounded up to a multiple of kSelectPadding.
// u: query time in bin units, in [0, 256]. maxDistBins: the maximum time
// distance |c_q - u| in bins (infinity for none).
// Dispatches to the AVX-512 kernel where the CPU has it (math/simd.h:
// simd::activeKernel(), TDPM_SIMD=avx2 forces the xsimd one); both return
// identical windows.
constexpr int kSelectPadding = 64;
TimeWindow selectTimeWindow(const uint8_t* bins, int n, float u, int keep, float maxDistBins);
// The two kernels by name (tests and benchmarks). The AVX-512 one may only be
// called where simd::cpuHasAvx512(); without AVX-512 kernels in the build it
// is the xsimd one.
TimeWindow selectTimeWindowXsimd(const uint8_t* bins, int n, float u, int keep, float maxDistBins);
TimeWindow selectTimeWindowAvx512(const uint8_t* bins, int n, float u, int keep, float maxDistBins);

// Scalar reference; scratch must hold n floats.
TimeWindow selectTimeWindowQuickselect(const uint8_t* bins, int n, float u, int keep, float maxDistBins,
                                       float* scratch, Rng& rng);

// The bins whose centre lies within key distance `lim` (= 2 * distance) of
// u, as an interval; empty if none. Shared by both implementations.
TimeWindow binsWithinKey(float u, float lim);

}  // namespace tdpm::photon
