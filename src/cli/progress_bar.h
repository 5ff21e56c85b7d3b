// cli/progress_bar.h — the terminal progress bar behind tdpm::Progress.
// Owns: ProgressBar (thread-safe, throttled drawing on stderr) and the pure
// formatting and estimating functions it uses (tested without a terminal).
// Render and photon loops only see tdpm::Progress (core/progress.h); this
// file decides whether and how to show it.
//
// Two kinds of line:
//  * a stage alone (no outer loop reported): one line per stage, ended when
//    the stage finishes, with the stage's own elapsed and remaining time:
//      "render [=====>     ]  45% 414/920 tiles, 0:12 elapsed, 0:15 left"
//  * inside an outer loop (Progress::at: the passes of a progressive render,
//    the frames of an animation): one line for the whole loop, redrawn in
//    place, the loop's position and times first, the stage under way after:
//      "pass 3/10, 0:32 elapsed, 1:08 left, 812k photons/s | render [==> ] 45% 414/920 tiles"
// Units: a stage whose name ends in "photons" counts photon paths emitted
// (photon/tracer.cpp reports them so), every other stage counts image
// tiles of 16x16 pixels (render/tile_loop.h).
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

// Short counts for the bar: "920", "331.8k", "1.08M", "2.50G".
std::string formatShortCount(double n);

// What a stage's units are: "photons" for stages named "... photons",
// "tiles" otherwise (see the header comment).
std::string stageUnit(const std::string& stage);

// Seconds left assuming the rate seen so far continues: units done since a
// baseline (doneAtStart, at elapsed 0) over the time they took. Negative
// when unknown (no progress yet, or total unknown). Honest only when the
// units done so far are a fair sample of all of them: render/tile_loop.h
// hands tiles out spread over the image (not row by row) for this reason.
double estimateSecondsLeft(size_t doneAtStart, size_t done, size_t total, double elapsedSeconds);

// Timings of an outer loop (passes, frames), in seconds since the bar first
// saw it, for estimateLoopSecondsLeft.
struct LoopTiming {
  size_t doneAtStart = 0;       // units already done when the bar first saw the loop (a resumed render)
  size_t done = 0, total = 0;   // total 0: unknown (a time limit decides)
  double timeLimitSeconds = 0;  // > 0: the loop stops after the unit that reaches it
  double lastUnitEnd = 0;       // when the last unit finished (0 before any)
  double now = 0;
};

// Seconds until the loop ends, from the units measured in this run (their
// mean duration; the first is as good as any: every pass does the same
// work). With a total: the rest of the unit under way (at least 0: a unit
// that overran the mean is taken to end now) plus the units after it. With
// a time limit: the loop ends with the first unit that finishes at or after
// the limit, so the end is the limit rounded up to the next unit boundary;
// before any unit is measured, the limit minus now (a lower bound). With
// both, whichever comes first. Negative when unknown (no total, no limit,
// or no unit measured with only a total).
double estimateLoopSecondsLeft(const LoopTiming& t);

// Everything one line shows (see the header comment).
struct LineParts {
  std::string stage;
  size_t done = 0, total = 0;   // of the stage; total 0: unknown, count only
  std::string unit;             // of the stage's counts: "tiles", "photons"
  double elapsedSeconds = 0;    // of the stage, or of the loop when `loop` is set
  double secondsLeft = -1;      // same; < 0: unknown ("--:--")
  double photonsPerSecond = -1; // < 0: not shown
  std::string loop;             // "pass 3/10", "frame 2/24", "pass 4 (time limit 1:00)"; empty: no loop
};

// The position label of an outer loop: "pass 3/10" for the unit under way
// (done + 1, at most total), "pass 4 (time limit 1:00)" without a total.
std::string formatLoopLabel(const WorkPosition& w);

// One line of the bar, at most `width` characters (no control codes). The
// bar (10..40 cells) shrinks to fit `width`, then vanishes; what still does
// not fit is cut at the end (the stage part of a loop line goes first).
std::string formatProgressLine(const LineParts& p, int width);

class ProgressBar {
 public:
  // Draws on `out` when `enabled`; a disabled bar ignores every report at
  // the cost of one branch. `width` 0 asks the terminal (TIOCGWINSZ),
  // falling back to 80. Redraws at most once per `minIntervalSeconds`,
  // except a stage's final report (done == total) and every loop position,
  // which always draw.
  explicit ProgressBar(bool enabled, std::FILE* out = stderr, double minIntervalSeconds = 0.1, int width = 0);
  // Ends an open line, so a following error message starts on its own line.
  ~ProgressBar();

  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // The policy of issue 2: show when stderr is a terminal and not --quiet.
  static bool shouldShow(bool quiet);
  // Where the bar of this process goes, or nullptr for none: stderr when
  // shouldShow, and never under mpirun (`distributed`). There a rank's
  // stderr is a pipe to mpirun, which copies it to wherever its own stderr
  // goes (a file, when redirected: issue 27 item 16 found \r and ESC[K
  // there), and Open MPI 4.1 gives a rank's stdout a pty whatever mpirun's
  // stdout is (measured: `mpirun -np 1 sh -c 'test -t 1' > file` is a
  // terminal), so no rank can tell whether anyone sees a terminal.
  static std::FILE* stream(bool quiet, bool distributed);

  bool enabled() const { return enabled_; }

  // A Progress that forwards to this bar (report and at). The bar must
  // outlive every use.
  Progress progress();

  // Thread-safe. Cheap when not drawing: one clock read and one atomic load;
  // the mutex is taken only by the one thread that wins the redraw slot.
  void report(const std::string& stage, size_t done, size_t total);

  // The outer loop's position (Progress::at): from the loop's thread, at its
  // start and after each unit. Always redraws. A loop that reaches its
  // total ends its line. Thread-safe.
  void position(const WorkPosition& w);

  // Ends the current line (newline) if one is open. Thread-safe.
  void finish();

 private:
  // All with mutex_ held.
  void draw(const std::string& stage, size_t done, size_t total, int64_t nowNs);
  void startStage(const std::string& stage, size_t done, size_t total, int64_t nowNs);
  void redraw(int64_t nowNs);
  void endLine();

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
  size_t lastTotal_ = 0;

  // The outer loop, while one is under way (Progress::at).
  bool inLoop_ = false;
  WorkPosition loop_;
  int64_t loopStartNs_ = 0;
  int64_t loopLastUnitNs_ = 0;
  size_t loopDoneAtStart_ = 0;
  uint64_t loopPhotonsAtStart_ = 0;
};

}  // namespace tdpm::cli
