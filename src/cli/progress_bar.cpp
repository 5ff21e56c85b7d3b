// cli/progress_bar.cpp — formatting, throttling and drawing of the bar.
#include "cli/progress_bar.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace tdpm::cli {
namespace {

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int terminalWidth(std::FILE* out) {
  struct winsize ws;
  if (::ioctl(::fileno(out), TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return int(ws.ws_col);
  return 80;
}

}  // namespace

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  // Cap at 999 hours: an absurd ETA early on must not blow up the line.
  long long s = std::llround(std::min(seconds, 999.0 * 3600.0));
  long long h = s / 3600, m = (s / 60) % 60, sec = s % 60;
  char buf[32];
  if (h > 0)
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", h, m, sec);
  else
    std::snprintf(buf, sizeof buf, "%lld:%02lld", m, sec);
  return buf;
}

double estimateSecondsLeft(size_t doneAtStart, size_t done, size_t total, double elapsedSeconds) {
  if (total == 0 || done <= doneAtStart || !(elapsedSeconds > 0)) return -1.0;
  if (done >= total) return 0.0;
  double rate = double(done - doneAtStart) / elapsedSeconds;  // units per second
  return double(total - done) / rate;
}

std::string formatProgressLine(const std::string& stage, size_t done, size_t total, double elapsedSeconds,
                               double secondsLeft, int width) {
  std::string tail;
  char buf[128];
  // Room the bar must leave for the tail; kept the same for the whole stage
  // (done padded to total's digits, the "left" part reserved even once
  // finished) so the bar does not change length while it fills.
  size_t reserve = 0;
  if (total > 0) {
    size_t shown = std::min(done, total);
    int percent = int(100.0 * double(shown) / double(total));  // floor: 100% only when done
    int digits = int(std::to_string(total).size());
    std::snprintf(buf, sizeof buf, " %3d%% %*zu/%zu %s elapsed", percent, digits, shown, total,
                  formatDuration(elapsedSeconds).c_str());
    tail = buf;
    const std::string left = ", " + formatDuration(secondsLeft) + " left";
    reserve = tail.size() + std::max(left.size(), std::string(", 00:00 left").size());
    if (done < total) tail += left;
  } else {
    std::snprintf(buf, sizeof buf, " %zu %s elapsed", done, formatDuration(elapsedSeconds).c_str());
    tail = buf;
    reserve = tail.size();
  }

  std::string line = stage;
  // Bar: " [" cells "]"; 10..40 cells when there is room.
  const int room = width - int(stage.size()) - int(reserve) - 3;
  if (total > 0 && room >= 10) {
    const int cells = std::min(room, 40);
    const double frac = std::min(1.0, double(done) / double(total));
    const int full = int(frac * cells);
    line += " [";
    line.append(size_t(full), '=');
    if (full < cells) {
      line += '>';
      line.append(size_t(cells - full - 1), ' ');
    }
    line += ']';
  }
  line += tail;
  if (width > 0 && int(line.size()) > width) line.resize(size_t(width));
  return line;
}

// ---- ProgressBar ----

ProgressBar::ProgressBar(bool enabled, std::FILE* out, double minIntervalSeconds, int width)
    : enabled_(enabled && out != nullptr),
      out_(out),
      intervalNs_(int64_t(std::max(0.0, minIntervalSeconds) * 1e9)),
      width_(width) {
  if (enabled_ && width_ <= 0) width_ = terminalWidth(out_);
}

ProgressBar::~ProgressBar() { finish(); }

bool ProgressBar::shouldShow(bool quiet) { return !quiet && ::isatty(STDERR_FILENO) == 1; }

Progress ProgressBar::progress() {
  Progress p;
  if (enabled_) p.report = [this](const std::string& stage, size_t done, size_t total) { report(stage, done, total); };
  return p;
}

void ProgressBar::report(const std::string& stage, size_t done, size_t total) {
  if (!enabled_) return;
  const int64_t now = nowNs();
  const bool final = total > 0 && done >= total;
  if (!final) {
    // Claim the redraw slot: of all threads that see it open, exactly one
    // wins the compare-exchange; the rest return without touching the mutex.
    int64_t next = nextDrawNs_.load(std::memory_order_relaxed);
    if (now < next) return;
    if (!nextDrawNs_.compare_exchange_strong(next, now + intervalNs_, std::memory_order_relaxed)) return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  // Re-read the clock under the lock: draws then see monotonic times even
  // when the winning threads reach the lock in another order.
  draw(stage, done, total, nowNs());
}

void ProgressBar::draw(const std::string& stage, size_t done, size_t total, int64_t now) {
  if (stage == stage_ && stageDone_) {
    // Reports arrive out of order from worker threads, so a finished stage
    // can still get stragglers (done < total) microseconds later: ignore
    // them. A report well after completion is a new run of the same stage
    // name (e.g. one photon pass per frame) and starts a new line.
    if (now - completedNs_ < kStragglerNs) return;
    startStage(stage, done, total, now);
  } else if (stage == stage_ && lineOpen_) {
    if (done < lastDone_) return;  // out of order: never move backwards
  } else {
    if (lineOpen_) std::fputc('\n', out_);  // previous stage ended unfinished
    lineOpen_ = false;
    startStage(stage, done, total, now);
  }
  lastDone_ = done;
  const double elapsed = double(now - stageStartNs_) * 1e-9;
  const double left = estimateSecondsLeft(stageStartDone_, done, total, elapsed);
  // One column short of the width: writing the last column makes some
  // terminals wrap before the \r.
  std::string line = formatProgressLine(stage, done, total, elapsed, left, width_ - 1);
  // \r + clear-to-end-of-line: redraw in place.
  std::fprintf(out_, "\r%s\x1b[K", line.c_str());
  lineOpen_ = true;
  if (total > 0 && done >= total) {
    std::fputc('\n', out_);
    lineOpen_ = false;
    stageDone_ = true;
    completedNs_ = now;
  }
  std::fflush(out_);
}

void ProgressBar::startStage(const std::string& stage, size_t done, size_t total, int64_t now) {
  stage_ = stage;
  stageDone_ = false;
  stageStartNs_ = now;
  // The first sight of a stage may be late (throttled reports): measure the
  // rate from here, not from 0, so the estimate stays unbiased.
  stageStartDone_ = (total > 0 && done >= total) ? 0 : done;
  lastDone_ = 0;
}

void ProgressBar::finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (lineOpen_) {
    std::fputc('\n', out_);
    std::fflush(out_);
    lineOpen_ = false;
  }
}

}  // namespace tdpm::cli
