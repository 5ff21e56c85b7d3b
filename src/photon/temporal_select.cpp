// photon/temporal_select.cpp — SIMD (xsimd, and AVX-512 dispatched at run
// time) and quickselect temporal selection.
#include "photon/temporal_select.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "math/simd.h"

#if TDPM_HAVE_AVX512_KERNELS
#include <immintrin.h>
#endif

namespace tdpm::photon {

TimeWindow binsWithinKey(float u, float lim) {
  TimeWindow w;
  if (!(lim >= 0.0f)) return w;
  u = std::clamp(u, 0.0f, 256.0f);
  // The key is V-shaped in q with its minimum at the bin whose centre is
  // nearest to u (qt or qt - 1); on each side of it the key is monotone.
  int qc = std::min(int(u), 255);
  if (qc > 0 && timeKey(qc - 1, u) < timeKey(qc, u)) --qc;
  if (timeKey(qc, u) > lim) return w;
  if (!std::isfinite(lim)) {
    w.lo = 0;
    w.hi = 255;
    return w;
  }
  // Closed-form guesses, corrected with the exact key (float rounding of a
  // guess can be off by one bin).
  int lo = std::clamp(int(std::ceil(u - 0.5f - 0.5f * lim)), 0, qc);
  int hi = std::clamp(int(std::floor(u - 0.5f + 0.5f * lim)), qc, 255);
  while (lo > 0 && timeKey(lo - 1, u) <= lim) --lo;
  while (lo < qc && timeKey(lo, u) > lim) ++lo;
  while (hi < 255 && timeKey(hi + 1, u) <= lim) ++hi;
  while (hi > qc && timeKey(hi, u) > lim) --hi;
  w.lo = lo;
  w.hi = hi;
  return w;
}

namespace {

using B = simd::BatchU8;
constexpr int kLanes = int(simd::kBytesPerBatch);
static_assert(kSelectPadding % kLanes == 0, "padding must be whole batches");

struct alignas(64) LaneIota {
  uint8_t v[64];
  constexpr LaneIota() : v() {
    for (int i = 0; i < 64; ++i) v[i] = uint8_t(i);
  }
};
constexpr LaneIota kIota{};

// All-ones lanes where m is true. On SSE/AVX a byte mask already is that
// register; elsewhere (mask registers) fall back to a select.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"
inline B maskBytes(const typename B::batch_bool_type& m) {
  using BB = typename B::batch_bool_type;
  if constexpr (std::is_same_v<typename B::register_type, typename BB::register_type>)
    return B(typename B::register_type(m));
  else
    return xsimd::select(m, B(uint8_t(0xFF)), B(uint8_t(0)));
}
#pragma GCC diagnostic pop

// Sum of the byte lanes of acc (each <= 255) without overflow: widen pairs
// of bytes to 16 bits, then to 32, then one horizontal add.
inline int sumBytes(const B& acc) {
  using B32 = xsimd::batch<uint32_t, simd::Arch>;
  B32 x = xsimd::bitwise_cast<B32>(acc);
  B32 m8(0x00FF00FFu);
  B32 y = (x & m8) + ((x >> 8) & m8);
  B32 z = (y & B32(0xFFFFu)) + (y >> 16);
  return int(xsimd::hadd(z));
}

// Number of candidates with lo <= bin <= hi: (bin - lo) mod 256 <= hi - lo.
// One byte counter per lane; n <= 255 * kLanes keeps the lanes from
// overflowing, so larger inputs are counted in chunks.
inline int countInRange(const uint8_t* bins, int n, int lo, int hi, const B& tailMask, int fullBatches) {
  const B vlo = B(uint8_t(lo)), vw = B(uint8_t(hi - lo));
  int total = 0;
  int b = 0;
  while (b < fullBatches) {
    int end = std::min(fullBatches, b + 255);
    B acc(uint8_t(0));
    for (; b < end; ++b) {
      B d = B::load_unaligned(bins + b * kLanes) - vlo;
      acc -= maskBytes(xsimd::min(d, vw) == d);  // mask is 0xFF: subtract -1
    }
    total += sumBytes(acc);
  }
  if (fullBatches * kLanes < n) {
    B d = B::load_unaligned(bins + fullBatches * kLanes) - vlo;
    B in = maskBytes(xsimd::min(d, vw) == d) & tailMask;
    total += sumBytes(B(uint8_t(0)) - in);
  }
  return total;
}

// The interval after s merge steps outward from the query (see header).
// beta = u - qt in [0, 1]; exact comparisons with 0 and 0.5 pick the case.
inline void intervalAfter(int s, int qt, float beta, int& lo, int& hi) {
  int L, R;
  if (beta == 0.0f) {  // u on the lower edge of bin qt: qt and qt-1 tie
    L = s + 1;
    R = s;
  } else if (beta < 0.5f) {  // left neighbour nearer than the right one
    L = (s + 1) / 2;
    R = s / 2;
  } else if (beta == 0.5f) {  // u at the bin centre: both sides tie
    L = R = s;
  } else {
    L = s / 2;
    R = (s + 1) / 2;
  }
  lo = std::max(0, qt - L);
  hi = std::min(255, qt + R);
}

// The search shared by both kernels; count(lo, hi) is the number of
// candidates with lo <= bin <= hi.
template <class Count>
inline TimeWindow searchWindow(int n, float u, int keep, float maxDistBins, const Count& count) {
  TimeWindow w;
  if (n <= 0 || keep <= 0) return w;
  keep = std::min(keep, n);
  u = std::clamp(u, 0.0f, 256.0f);
  const int qt = std::min(int(u), 255);
  const float beta = u - float(qt);

  // Binary search for the first step whose interval holds >= keep
  // candidates; 513 steps always cover [0, 255] from any start.
  int sLo = 0, sHi = 513;
  int lo = 0, hi = 255, cnt = n;
  while (sLo < sHi) {
    int mid = (sLo + sHi) / 2;
    int l, h;
    intervalAfter(mid, qt, beta, l, h);
    int c = count(l, h);
    if (c >= keep) {
      sHi = mid;
      lo = l;
      hi = h;
      cnt = c;
    } else {
      sLo = mid + 1;
    }
  }
  intervalAfter(sHi, qt, beta, lo, hi);
  // ---- maximum time distance ----
  if (std::isfinite(maxDistBins)) {
    TimeWindow lim = binsWithinKey(u, 2.0f * maxDistBins);
    if (lim.empty() || lim.lo > hi || lim.hi < lo) return w;
    if (lim.lo > lo || lim.hi < hi) {
      lo = std::max(lo, lim.lo);
      hi = std::min(hi, lim.hi);
      cnt = count(lo, hi);
    }
  }
  w.lo = lo;
  w.hi = hi;
  w.kept = cnt;
  return w;
}

#if TDPM_HAVE_AVX512_KERNELS
// AVX-512 BW: 64 candidates per compare, straight into a mask register, and
// a popcount instead of byte counters. Only ever called where
// simd::cpuHasAvx512() (the target attribute keeps the rest of the build
// free of AVX-512). The padding (kSelectPadding = 64) makes the last load
// readable; the tail lanes are masked off.
struct Count512 {
  const uint8_t* bins;
  int n;
  __attribute__((target("avx512f,avx512bw,popcnt"))) int operator()(int lo, int hi) const {
    const __m512i vlo = _mm512_set1_epi8(char(lo)), vw = _mm512_set1_epi8(char(hi - lo));
    const int full = n / 64;
    int total = 0;
    for (int b = 0; b < full; ++b) {
      __m512i d = _mm512_sub_epi8(_mm512_loadu_si512(bins + b * 64), vlo);
      total += int(__builtin_popcountll(_mm512_cmple_epu8_mask(d, vw)));  // (bin - lo) mod 256 <= hi - lo
    }
    const int rest = n - full * 64;
    if (rest > 0) {
      __m512i d = _mm512_sub_epi8(_mm512_loadu_si512(bins + full * 64), vlo);
      unsigned long long m = _mm512_cmple_epu8_mask(d, vw) & ((1ull << rest) - 1ull);
      total += int(__builtin_popcountll(m));
    }
    return total;
  }
};
#endif

}  // namespace

TimeWindow selectTimeWindowXsimd(const uint8_t* bins, int n, float u, int keep, float maxDistBins) {
  if (n <= 0 || keep <= 0) return TimeWindow{};
  const int fullBatches = n / kLanes;
  const B tailMask = maskBytes(B::load_aligned(kIota.v) < B(uint8_t(n - fullBatches * kLanes)));
  return searchWindow(n, u, keep, maxDistBins, [&](int lo, int hi) {
    return countInRange(bins, n, lo, hi, tailMask, fullBatches);
  });
}

#if TDPM_HAVE_AVX512_KERNELS
// flatten: the search and Count512 inline into this AVX-512 function (a
// default-target function may not inline an AVX-512 one).
__attribute__((target("avx512f,avx512bw,popcnt"), flatten)) TimeWindow selectTimeWindowAvx512(
    const uint8_t* bins, int n, float u, int keep, float maxDistBins) {
  return searchWindow(n, u, keep, maxDistBins, Count512{bins, n});
}
#else
TimeWindow selectTimeWindowAvx512(const uint8_t* bins, int n, float u, int keep, float maxDistBins) {
  return selectTimeWindowXsimd(bins, n, u, keep, maxDistBins);
}
#endif

TimeWindow selectTimeWindow(const uint8_t* bins, int n, float u, int keep, float maxDistBins) {
  static const bool use512 = simd::activeKernel() == simd::Kernel::Avx512;
  return use512 ? selectTimeWindowAvx512(bins, n, u, keep, maxDistBins)
                : selectTimeWindowXsimd(bins, n, u, keep, maxDistBins);
}

namespace {
// k-th smallest (0-based) of a[0, n) by randomised quickselect with a
// three-way partition (linear also when many keys are equal).
float quickselect(float* a, int n, int k, Rng& rng) {
  int lo = 0, hi = n;  // [lo, hi)
  for (;;) {
    if (hi - lo == 1) return a[lo];
    float pivot = a[lo + int(rng.below(uint32_t(hi - lo)))];
    int lt = lo, i = lo, gt = hi;  // [lo,lt) < p, [lt,i) == p, [gt,hi) > p
    while (i < gt) {
      if (a[i] < pivot)
        std::swap(a[lt++], a[i++]);
      else if (a[i] > pivot)
        std::swap(a[i], a[--gt]);
      else
        ++i;
    }
    if (k < lt)
      hi = lt;
    else if (k >= gt)
      lo = gt;
    else
      return pivot;
  }
}
}  // namespace

TimeWindow selectTimeWindowQuickselect(const uint8_t* bins, int n, float u, int keep, float maxDistBins,
                                       float* scratch, Rng& rng) {
  TimeWindow w;
  if (n <= 0 || keep <= 0) return w;
  keep = std::min(keep, n);
  u = std::clamp(u, 0.0f, 256.0f);
  for (int i = 0; i < n; ++i) scratch[i] = timeKey(bins[i], u);
  float d = quickselect(scratch, n, keep - 1, rng);
  float lim = std::min(d, 2.0f * maxDistBins);
  w = binsWithinKey(u, lim);
  if (w.empty()) return w;
  int c = 0;
  for (int i = 0; i < n; ++i) c += timeKey(bins[i], u) <= lim;
  w.kept = c;
  return w;
}

}  // namespace tdpm::photon
