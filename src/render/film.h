// render/film.h — per-pixel results of a render: mean radiance, the number
// of samples taken, and the per-pixel variance of the mean (the sample
// variance / n, per channel), row-major, row 0 at the top. Each pixel is
// written by exactly one tile, so no locks are needed.
#pragma once
#include <cfloat>
#include <cmath>
#include <vector>

#include "math/vec.h"

namespace tdpm {

struct Film {
  int width = 0, height = 0;
  std::vector<Rgb> color;
  std::vector<float> sampleCount;
  std::vector<Rgb> varianceOfMean;

  Film() = default;
  Film(int w, int h)
      : width(w), height(h), color(size_t(w) * size_t(h)), sampleCount(size_t(w) * size_t(h), 0.0f),
        varianceOfMean(size_t(w) * size_t(h)) {}
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};

// What a sample may put on a film: NaN -> 0, +-Inf -> +-FLT_MAX, per
// channel. A NaN sample is a bug upstream and never reaches the film; an
// infinite one is a finite scene overflowing float (a tiny emitter of huge
// power), which saturates as a sensor would.
inline Rgb saturateSample(Rgb L) {
  for (int c = 0; c < 3; ++c) {
    float& v = L[c];
    if (std::isnan(v)) v = 0.0f;
    else if (std::isinf(v)) v = v > 0 ? FLT_MAX : -FLT_MAX;
  }
  return L;
}

}  // namespace tdpm
