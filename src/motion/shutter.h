// motion/shutter.h — the camera's exposure interval and the mapping between
// scene time (seconds, as in the scene file) and Embree's ray time in [0, 1].
#pragma once
#include <algorithm>

namespace tdpm {

struct Shutter {
  float open = 0.0f, close = 1.0f;

  float length() const { return close - open; }
  bool instant() const { return !(close > open); }
  // Scene time -> [0, 1] (Embree's ray time). A zero-length shutter maps to 0.
  float normalized(float t) const {
    if (instant()) return 0.0f;
    return std::clamp((t - open) / (close - open), 0.0f, 1.0f);
  }
  float fromNormalized(float u) const { return open + u * (close - open); }
};

}  // namespace tdpm
