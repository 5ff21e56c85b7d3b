// cli/progress_bar.h — the terminal progress bar behind tdpm::Progress.
// Owns: ProgressBar (thread-safe, throttled drawing on stderr) and the pure
// formatting functions it uses (tested without a terminal).
// Render and photon loops only see tdpm::Progress (core/progress.h); this
// file decides whether and how to show it.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

#include "core/progress.h"

namespace tdpm::cli {

// "m:ss" below an hour, "h:mm:ss" above; negative or non-finite -> "--:--".
std::string formatDuration(double seconds);

// Seconds left assuming the rate seen so far continues: units done since a
// baseline (doneAtStart, at elapsed 0) over the time they took. Negative
// when unknown (no progress yet, or total unknown).
double estimateSecondsLeft(size_t doneAtStart, size_t done, size_t total, double elapsedSeconds);

// One line of the bar, at most `width` characters (no control codes):
//   "render [=========>          ]  45% 450/1000 0:12 elapsed, 0:15 left"
// total == 0 (unknown) shows only the stage, the count and elapsed time.
// The bar shrinks to fit `width`; parts are dropped if even that fails.
std::string formatProgressLine(const std::string& stage, size_t done, size_t total, double elapsedSeconds,
                               double secondsLeft, int width);

class ProgressBar {
 public:
  // Draws on `out` when `enabled`; a disabled bar ignores every report at
  // the cost of one branch. `width` 0 asks the terminal (TIOCGWINSZ),
  // falling back to 80. Redraws at most once per `minIntervalSeconds`,
  // except a stage's final report (done == total), which always draws.
  explicit ProgressBar(bool enabled, std::FILE* out = stderr, double minIntervalSeconds = 0.1, int width = 0);
  // Ends an open line, so a following error message starts on its own line.
  ~ProgressBar();

  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // The policy of issue 2: show when stderr is a terminal and not --quiet.
  static bool shouldShow(bool quiet);

  bool enabled() const { return enabled_; }

  // A Progress that forwards to this bar. The bar must outlive every use.
  Progress progress();

  // Thread-safe. Cheap when not drawing: one clock read and one atomic load;
  // the mutex is taken only by the one thread that wins the redraw slot.
  void report(const std::string& stage, size_t done, size_t total);

  // Ends the current line (newline) if one is open. Thread-safe.
  void finish();

 private:
  // Both with mutex_ held.
  void draw(const std::string& stage, size_t done, size_t total, int64_t nowNs);
  void startStage(const std::string& stage, size_t done, size_t total, int64_t nowNs);

  // Reports of a finished stage within this time after its completion are
  // stragglers from other threads, not a new run of that stage.
  static constexpr int64_t kStragglerNs = 50'000'000;

  const bool enabled_;
  std::FILE* const out_;
  const int64_t intervalNs_;
  int width_;

  std::atomic<int64_t> nextDrawNs_{0};  // earliest time of the next redraw

  std::mutex mutex_;  // guards everything below and the writes to out_
  bool lineOpen_ = false;
  std::string stage_;       // stage of the open line (or of the last line)
  bool stageDone_ = false;  // stage_ reached done == total
  int64_t stageStartNs_ = 0;
  int64_t completedNs_ = 0;
  size_t stageStartDone_ = 0;
  size_t lastDone_ = 0;
};

}  // namespace tdpm::cli
