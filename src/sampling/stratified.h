// sampling/stratified.h — stratified samples in (sub-pixel x, y, time).
// A batch of n samples is a Latin hypercube: each of the three dimensions is
// split into n strata, each stratum used once, the pairing shuffled, jittered
// inside the strata. Stratifying time on its own axis is what makes motion
// blur converge quickly (Cook et al. 1984). Deterministic given the Rng.
#pragma once
#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "math/vec.h"

namespace tdpm {

struct CameraSample {
  Vec2f pixelOffset;  // in [0,1)^2 within the pixel
  float time01;       // normalised shutter time in [0,1)
};

// Fills out[0..n) (out must hold n). `scratch` avoids allocation per pixel.
void stratifiedCameraSamples(int n, Rng& rng, CameraSample* out, std::vector<uint32_t>& scratch);

}  // namespace tdpm
