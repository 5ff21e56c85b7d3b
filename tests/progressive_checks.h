// tests/progressive_checks.h — the bit-identity checks progressive suites
// share: two states equal bit for bit (layers, pilot and totals, but wall-clock
// seconds), and a render of 4 passes equal to 2 + 2 resumed and to the same
// render on one thread.
#pragma once
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "core/progress.h"
#include "render/progressive.h"
#include "render/renderer.h"

namespace tdpm::test {

inline bool sameState(const ProgressiveState& a, const ProgressiveState& b) {
  ProgressiveTotals ta = a.totals, tb = b.totals;
  ta.seconds = tb.seconds = 0;  // wall clock
  const bool sameTotals = ta.photonsEmitted == tb.photonsEmitted && ta.photonsStored == tb.photonsStored &&
                          ta.kernelRadius == tb.kernelRadius && ta.kernelSpatialRadius == tb.kernelSpatialRadius &&
                          ta.kernelHalfWindow == tb.kernelHalfWindow;
  if (a.passesDone != b.passesDone || !(a.pilot == b.pilot) || !sameTotals || a.layers.size() != b.layers.size())
    return false;
  for (const auto& [name, l] : a.layers) {
    auto it = b.layers.find(name);
    if (it == b.layers.end() || it->second.size() != l.size()) return false;
    if (std::memcmp(l.data(), it->second.data(), l.size() * sizeof(float)) != 0) return false;
  }
  return true;
}

// Renders o with 4 passes, then 2 passes continued to 4 (as --resume does
// from the state in the EXR), then 4 passes on one thread; checks all three
// equal and returns the first (st: its stats).
inline ProgressiveState checkResumeAndThreads(const Scene& s, RenderOptions o, RenderStats& st) {
  o.passes = 4;
  ProgressiveState whole;
  renderProgressive(s, o, whole, Progress{}, st);
  RenderStats other;
  ProgressiveState copy;
  o.passes = 2;
  renderProgressive(s, o, copy, Progress{}, other);
  o.passes = 4;
  renderProgressive(s, o, copy, Progress{}, other);
  CHECK(sameState(whole, copy));
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  ProgressiveState serial;
  renderProgressive(s, o, serial, Progress{}, other);
  CHECK(sameState(whole, serial));
  return whole;
}

}  // namespace tdpm::test
