// tests/test_photon_select.cpp — photon/temporal_select.h: the SIMD window
// search and the quickselect reference keep exactly the candidates that
// std::nth_element says are the `keep` nearest in time, ties at the cut all
// kept, for many input shapes, k_s in [1, 1024], f in (0, 1].
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/rng.h"
#include "math/simd.h"
#include "photon/temporal_select.h"

using namespace tdpm;
using namespace tdpm::photon;

namespace {

enum class Shape { Random, Sorted, Reverse, AllEqual, Correlated, TwoValues, Extremes };

std::vector<uint8_t> makeBins(Shape shape, int n, Rng& rng) {
  std::vector<uint8_t> b(size_t(n) + kSelectPadding, 0xAB);  // padding: junk on purpose
  int base = int(rng.below(256));
  for (int i = 0; i < n; ++i) {
    switch (shape) {
      case Shape::Random: b[size_t(i)] = uint8_t(rng.below(256)); break;
      case Shape::Sorted: b[size_t(i)] = uint8_t(i * 256 / n); break;
      case Shape::Reverse: b[size_t(i)] = uint8_t(255 - i * 256 / n); break;
      case Shape::AllEqual: b[size_t(i)] = uint8_t(base); break;
      case Shape::Correlated:  // a blurred caustic: time follows position
        b[size_t(i)] = uint8_t(std::clamp(base + int(float(i) / float(n) * 40.0f) + int(rng.below(5)) - 2, 0, 255));
        break;
      case Shape::TwoValues: b[size_t(i)] = uint8_t(rng.below(2) ? base : 255 - base); break;
      case Shape::Extremes: b[size_t(i)] = uint8_t(rng.below(2) ? 0 : 255); break;
    }
  }
  return b;
}

// Reference: keep-th smallest distance by std::nth_element, then everything
// within it (ties kept) and within the maximum distance.
std::vector<char> referenceKept(const std::vector<uint8_t>& bins, int n, float u, int keep, float maxDist) {
  std::vector<float> keys(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) keys[size_t(i)] = std::fabs((float(bins[size_t(i)]) + 0.5f) - u);
  std::vector<float> tmp = keys;
  std::nth_element(tmp.begin(), tmp.begin() + (keep - 1), tmp.end());
  float d = std::min(tmp[size_t(keep - 1)], maxDist);
  std::vector<char> kept(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) kept[size_t(i)] = keys[size_t(i)] <= d;
  return kept;
}

float randomQuery(Rng& rng, int mode) {
  switch (mode % 5) {
    case 0: return 256.0f * rng.uniform();
    case 1: return float(rng.below(257));         // exactly on a bin edge (0 and 256 included)
    case 2: return float(rng.below(256)) + 0.5f;  // exactly a bin centre
    case 3: return mode % 2 ? 0.0f : 256.0f;      // shutter open / close
    default: return float(rng.below(256)) + 0.25f;
  }
}

}  // namespace

TEST_CASE("temporal selection: SIMD and quickselect keep exactly the nth_element set (ties kept)") {
  Rng rng(2024);
  std::vector<float> scratch(2048);
  int cases = 0, mismatches = 0;
  const Shape shapes[] = {Shape::Random, Shape::Sorted, Shape::Reverse, Shape::AllEqual,
                          Shape::Correlated, Shape::TwoValues, Shape::Extremes};
  const float fractions[] = {1e-6f, 0.1f, 0.25f, 0.5f, 0.77f, 1.0f};
  for (int n = 1; n <= 1024; n += (n < 70 ? 1 : 37 + int(rng.below(20)))) {
    for (Shape shape : shapes) {
      for (int rep = 0; rep < 3; ++rep) {
        std::vector<uint8_t> bins = makeBins(shape, n, rng);
        float u = randomQuery(rng, rep + int(shape) + n);
        float f = fractions[rng.below(6)];
        float maxDist = rng.below(3) == 0 ? 0.5f + 40.0f * rng.uniform() : std::numeric_limits<float>::infinity();
        int keep = keptCount(f, n);
        std::vector<char> ref = referenceKept(bins, n, u, keep, maxDist);
        TimeWindow a = selectTimeWindow(bins.data(), n, u, keep, maxDist);
        TimeWindow b = selectTimeWindowQuickselect(bins.data(), n, u, keep, maxDist, scratch.data(), rng);
        int refCount = 0;
        bool ok = a.lo == b.lo && a.hi == b.hi && a.kept == b.kept;
        for (int i = 0; i < n; ++i) {
          refCount += ref[size_t(i)];
          ok &= bool(ref[size_t(i)]) == a.contains(bins[size_t(i)]);
          ok &= bool(ref[size_t(i)]) == b.contains(bins[size_t(i)]);
        }
        ok &= a.kept == refCount;
        // Without a time limit at least `keep` are kept; the window is the
        // interval of bins within the cut distance and holds the query.
        if (!std::isfinite(maxDist)) ok &= a.kept >= keep && !a.empty();
        if (!a.empty()) ok &= float(a.lo) <= u && u <= float(a.hi + 1);
        ++cases;
        if (!ok) {
          ++mismatches;
          if (mismatches < 5)
            MESSAGE("mismatch n=" << n << " shape=" << int(shape) << " u=" << u << " keep=" << keep << " maxDist="
                                  << maxDist << " simd=[" << a.lo << "," << a.hi << "]#" << a.kept << " qs=[" << b.lo
                                  << "," << b.hi << "]#" << b.kept << " ref#" << refCount);
        }
      }
    }
  }
  MESSAGE(cases << " selections compared");
  CHECK(mismatches == 0);
}

// Runtime dispatch (math/simd.h): the AVX-512 kernel must return exactly the
// windows of the xsimd (AVX2) one, so images and bench ratios do not depend
// on the CPU. On a CPU without AVX-512 the xsimd kernel is still checked
// against quickselect and the comparison is skipped (said in a message).
TEST_CASE("temporal selection: the AVX-512 and xsimd kernels return identical windows") {
  const bool has512 = simd::cpuHasAvx512();
  if (!has512) MESSAGE("this CPU has no AVX-512 (F+BW): only the xsimd kernel is checked");
  Rng rng(77);
  std::vector<float> scratch(20000);
  const Shape shapes[] = {Shape::Random, Shape::Correlated, Shape::TwoValues, Shape::Extremes, Shape::AllEqual};
  int cases = 0, mismatches = 0;
  for (int rep = 0; rep < 3000; ++rep) {
    // Mostly k_s-sized inputs; some long ones cross the xsimd byte-counter
    // chunk (255 batches) and every tail length modulo 64.
    int n = rep % 10 == 0 ? 1 + int(rng.below(20000)) : 1 + int(rng.below(300));
    std::vector<uint8_t> bins = makeBins(shapes[rng.below(5)], n, rng);
    for (int i = 0; i < kSelectPadding; ++i) bins[size_t(n + i)] = uint8_t(rng.below(256));  // junk padding
    float u = randomQuery(rng, rep);
    int keep = keptCount(rng.uniform(), n);
    float maxDist = rng.below(3) == 0 ? 0.5f + 40.0f * rng.uniform() : std::numeric_limits<float>::infinity();
    TimeWindow x = selectTimeWindowXsimd(bins.data(), n, u, keep, maxDist);
    TimeWindow q = selectTimeWindowQuickselect(bins.data(), n, u, keep, maxDist, scratch.data(), rng);
    bool ok = x.lo == q.lo && x.hi == q.hi && x.kept == q.kept;
    if (has512) {
      TimeWindow a = selectTimeWindowAvx512(bins.data(), n, u, keep, maxDist);
      ok &= a.lo == x.lo && a.hi == x.hi && a.kept == x.kept;
      if (!ok && mismatches < 5)
        MESSAGE("n=" << n << " u=" << u << " keep=" << keep << " avx512=[" << a.lo << "," << a.hi << "]#" << a.kept
                     << " xsimd=[" << x.lo << "," << x.hi << "]#" << x.kept);
    }
    ++cases;
    mismatches += !ok;
  }
  MESSAGE(cases << " selections compared, kernel in use: " << std::string(simd::kernelName(simd::activeKernel())));
  CHECK(mismatches == 0);
  // The dispatching entry point runs one of the two.
  std::vector<uint8_t> bins(20 + kSelectPadding, 7);
  TimeWindow w = selectTimeWindow(bins.data(), 20, 7.5f, 5, std::numeric_limits<float>::infinity());
  CHECK(w.lo == 7);
  CHECK(w.kept == 20);
}

TEST_CASE("temporal selection: ties at the cut are kept whole; window never splits a bin") {
  // 10 photons in bin 100, 10 in bin 101, query at the centre of bin 100:
  // keeping 5 keeps all 10 of bin 100 and none of 101.
  std::vector<uint8_t> bins(20 + kSelectPadding, 0);
  for (int i = 0; i < 20; ++i) bins[size_t(i)] = uint8_t(i < 10 ? 100 : 101);
  TimeWindow w = selectTimeWindow(bins.data(), 20, 100.5f, 5, std::numeric_limits<float>::infinity());
  CHECK(w.lo == 100);
  CHECK(w.hi == 100);
  CHECK(w.kept == 10);
  // Query on the edge between bins 100 and 101: both are at distance 0.5,
  // a tie, so both are kept.
  w = selectTimeWindow(bins.data(), 20, 101.0f, 5, std::numeric_limits<float>::infinity());
  CHECK(w.lo == 100);
  CHECK(w.hi == 101);
  CHECK(w.kept == 20);
  // Query a quarter bin above 100's centre: 101 is nearer than 99.
  w = selectTimeWindow(bins.data(), 20, 100.75f, 11, std::numeric_limits<float>::infinity());
  CHECK(w.lo == 100);
  CHECK(w.hi == 101);
  // A time limit smaller than the distance to any bin centre keeps nothing.
  bins[0] = 50;
  w = selectTimeWindow(bins.data(), 20, 10.1f, 5, 0.3f);
  CHECK(w.empty());
  CHECK(w.kept == 0);
}

TEST_CASE("temporal selection: kept count rule") {
  CHECK(keptCount(0.5f, 200) == 100);
  CHECK(keptCount(0.5f, 201) == 101);
  CHECK(keptCount(1e-9f, 7) == 1);
  CHECK(keptCount(1.0f, 7) == 7);
  CHECK(keptCount(0.5f, 0) == 0);
}
