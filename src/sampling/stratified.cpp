// sampling/stratified.cpp — Latin-hypercube camera samples.
#include "sampling/stratified.h"

#include <numeric>

namespace tdpm {

namespace {
void shuffle(uint32_t* v, int n, Rng& rng) {
  for (int i = n - 1; i > 0; --i) std::swap(v[i], v[rng.below(uint32_t(i + 1))]);
}
}  // namespace

void stratifiedCameraSamples(int n, Rng& rng, CameraSample* out, std::vector<uint32_t>& scratch) {
  scratch.resize(size_t(3 * n));
  uint32_t* px = scratch.data();
  uint32_t* py = px + n;
  uint32_t* pt = py + n;
  std::iota(px, px + n, 0u);
  std::iota(py, py + n, 0u);
  std::iota(pt, pt + n, 0u);
  shuffle(px, n, rng);
  shuffle(py, n, rng);
  shuffle(pt, n, rng);
  float inv = 1.0f / float(n);
  for (int i = 0; i < n; ++i) {
    out[i].pixelOffset = {(float(px[i]) + rng.uniform()) * inv, (float(py[i]) + rng.uniform()) * inv};
    out[i].time01 = (float(pt[i]) + rng.uniform()) * inv;
    // Guard against rounding up to 1.0 (strata are half-open).
    if (out[i].time01 >= 1.0f) out[i].time01 = 0x1.fffffep-1f;
  }
}

}  // namespace tdpm
