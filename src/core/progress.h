// core/progress.h — how long-running stages report progress without knowing
// who listens. The render and photon loops call it once per unit of work
// (a tile, a batch of photons), never per sample; cli/ draws the bar.
#pragma once
#include <cstddef>
#include <functional>
#include <string>

namespace tdpm {

struct Progress {
  // (stage name, units done, units total). Must be thread-safe: called from
  // worker threads. Empty means nobody is listening.
  std::function<void(const std::string&, size_t, size_t)> report;

  void operator()(const std::string& stage, size_t done, size_t total) const {
    if (report) report(stage, done, total);
  }
};

}  // namespace tdpm
