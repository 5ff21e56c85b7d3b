// core/progress.h — how long-running stages report progress without knowing
// who listens. The render and photon loops call it once per unit of work
// (a tile, a batch of photons), never per sample; cli/ draws the bar.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace tdpm {

// Where a long render stands in its outer loop (the passes of a
// progressive render, the frames of an animation), so that the bar can
// label its units and estimate the time left from work actually measured.
struct WorkPosition {
  std::string unit;              // "pass" or "frame"
  size_t done = 0, total = 0;    // units finished; total 0: unknown (a time limit decides)
  double timeLimitSeconds = 0;   // > 0: the loop stops after the unit that reaches it
  uint64_t photonsEmitted = 0;   // photon paths traced so far, for photons per second
};

struct Progress {
  // (stage name, units done, units total). Must be thread-safe: called from
  // worker threads. Empty means nobody is listening.
  std::function<void(const std::string&, size_t, size_t)> report;
  // Called from the thread that runs the outer loop, at its start and after
  // each unit. Empty means nobody is listening.
  std::function<void(const WorkPosition&)> position;

  void operator()(const std::string& stage, size_t done, size_t total) const {
    if (report) report(stage, done, total);
  }
  void at(const WorkPosition& w) const {
    if (position) position(w);
  }
};

}  // namespace tdpm
