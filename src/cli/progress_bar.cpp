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

std::string formatShortCount(double n) {
  if (!(n >= 0)) n = 0;
  if (n < 1e3) return std::to_string(static_cast<long long>(n));
  const char* suffix[] = {"k", "M", "G", "T"};
  int i = 0;
  n /= 1e3;
  // Three significant digits; 999.6k rounds to "1.00M", not "1000k".
  while (i < 3 && n >= 999.5) {
    n /= 1e3;
    ++i;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, n < 9.995 ? "%.2f%s" : n < 99.95 ? "%.1f%s" : "%.0f%s", n, suffix[i]);
  return buf;
}

std::string stageUnit(const std::string& stage) {
  const std::string photons = "photons";
  if (stage.size() >= photons.size() && stage.compare(stage.size() - photons.size(), photons.size(), photons) == 0)
    return "photons";
  return "tiles";
}

double estimateSecondsLeft(size_t doneAtStart, size_t done, size_t total, double elapsedSeconds) {
  if (total == 0 || done <= doneAtStart || !(elapsedSeconds > 0)) return -1.0;
  if (done >= total) return 0.0;
  double rate = double(done - doneAtStart) / elapsedSeconds;  // units per second
  return double(total - done) / rate;
}

double estimateLoopSecondsLeft(const LoopTiming& t) {
  if (t.total > 0 && t.done >= t.total) return 0.0;
  const size_t measured = t.done > t.doneAtStart ? t.done - t.doneAtStart : 0;
  const double perUnit = measured > 0 ? t.lastUnitEnd / double(measured) : -1.0;
  // The unit under way ends at its mean duration after the last one, or
  // now if it already took longer.
  const double currentEnd = perUnit > 0 ? std::max(t.lastUnitEnd + perUnit, t.now) : -1.0;
  double left = -1.0;
  if (t.total > 0 && perUnit > 0) left = currentEnd - t.now + double(t.total - t.done - 1) * perUnit;
  if (t.timeLimitSeconds > 0) {
    double byLimit;
    if (perUnit > 0) {
      // Units after the current one, until one ends at or after the limit.
      double after = currentEnd >= t.timeLimitSeconds ? 0.0 : std::ceil((t.timeLimitSeconds - currentEnd) / perUnit);
      byLimit = currentEnd + after * perUnit - t.now;
    } else {
      byLimit = std::max(0.0, t.timeLimitSeconds - t.now);  // at least this: the unit under way ends later
    }
    left = left < 0 ? byLimit : std::min(left, byLimit);
  }
  return left < 0 ? -1.0 : std::max(0.0, left);
}

std::string formatLoopLabel(const WorkPosition& w) {
  const std::string unit = w.unit.empty() ? "step" : w.unit;
  std::string s = unit + " " + std::to_string(w.total > 0 ? std::min(w.done + 1, w.total) : w.done + 1);
  if (w.total > 0) s += "/" + std::to_string(w.total);
  if (w.timeLimitSeconds > 0) s += " (time limit " + formatDuration(w.timeLimitSeconds) + ")";
  return s;
}

std::string formatProgressLine(const LineParts& p, int width) {
  const bool photons = p.unit == "photons";
  auto count = [&](size_t n) { return photons ? formatShortCount(double(n)) : std::to_string(n); };
  std::string times = formatDuration(p.elapsedSeconds) + " elapsed";
  // Room kept for "left" so the line does not change length when it goes.
  const std::string left = ", " + formatDuration(p.secondsLeft) + " left";
  const size_t leftRoom = std::max(left.size(), std::string(", 00:00 left").size());
  const bool showLeft = p.total > 0 && p.done < p.total;  // a stage line; a loop line always shows it
  const std::string rateText = p.photonsPerSecond >= 0 ? formatShortCount(p.photonsPerSecond) : std::string();

  // The stage's counts, padded to the total's width so the bar keeps its
  // length while it fills. A photon stage (named "... photons") counts the
  // photon paths emitted, and says so: "221k/1.10M emitted (553k/s)".
  const std::string label = photons ? "emitted" : p.unit;
  std::string counts;
  char buf[160];
  if (p.total > 0) {
    const size_t shown = std::min(p.done, p.total);
    const int percent = int(100.0 * double(shown) / double(p.total));  // floor: 100% only when done
    const std::string totalText = count(p.total);
    std::snprintf(buf, sizeof buf, " %3d%% %*s/%s %s", percent, int(totalText.size()), count(shown).c_str(),
                  totalText.c_str(), label.c_str());
  } else {
    std::snprintf(buf, sizeof buf, " %s %s", count(p.done).c_str(), label.c_str());
  }
  counts = buf;

  std::string head, tail;
  size_t reserve = 0;  // what the tail will take at most, kept the same for the whole stage
  if (p.loop.empty()) {
    head = p.stage;
    tail = counts;
    // Photon stages keep room for their rate, which appears after the
    // first batches: the bar must not shrink then.
    std::string rate = rateText.empty() ? std::string() : " (" + rateText + "/s)";
    const size_t rateRoom = photons ? std::max(rate.size(), std::string(" (999k/s)").size()) : rate.size();
    tail += rate + ", " + times;
    reserve = tail.size() - rate.size() + rateRoom + (p.total > 0 ? leftRoom : 0);
    if (showLeft) tail += left;
  } else {
    head = p.loop + ", " + times + left;
    if (!rateText.empty()) head += ", " + rateText + " photons/s";
    if (!p.stage.empty()) {  // no stage seen yet: the loop part alone
      head += " | " + p.stage;
      tail = counts;
      reserve = tail.size();
    }
  }

  std::string line = head;
  // Bar: " [" cells "]"; 10..40 cells when there is room.
  const int room = width - int(head.size()) - int(reserve) - 3;
  if (p.total > 0 && !p.stage.empty() && room >= 10) {
    const int cells = std::min(room, 40);
    const double frac = std::min(1.0, double(p.done) / double(p.total));
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

std::FILE* ProgressBar::stream(bool quiet, bool distributed) {
  return !distributed && shouldShow(quiet) ? stderr : nullptr;
}

Progress ProgressBar::progress() {
  Progress p;
  if (enabled_) {
    p.report = [this](const std::string& stage, size_t done, size_t total) { report(stage, done, total); };
    p.position = [this](const WorkPosition& w) { position(w); };
  }
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

void ProgressBar::position(const WorkPosition& w) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const int64_t now = nowNs();
  if (!inLoop_ || w.unit != loop_.unit || w.done < loop_.done) {
    // A new loop (or the first sight of one): time it from here. A resumed
    // render starts at done > 0; only the units of this run are measured.
    if (lineOpen_ && !inLoop_) endLine();
    inLoop_ = true;
    loopStartNs_ = now;
    loopLastUnitNs_ = now;
    loopDoneAtStart_ = w.done;
    loopPhotonsAtStart_ = w.photonsEmitted;
  } else if (w.done > loop_.done) {
    loopLastUnitNs_ = now;
  }
  loop_ = w;
  redraw(now);
  if (w.total > 0 && w.done >= w.total) {
    endLine();
    inLoop_ = false;
  }
}

void ProgressBar::draw(const std::string& stage, size_t done, size_t total, int64_t now) {
  if (stage == stage_ && stageDone_) {
    // Reports arrive out of order from worker threads, so a finished stage
    // can still get stragglers (done < total) microseconds later: ignore
    // them. A report well after completion is a new run of the same stage
    // name (e.g. one photon pass per frame) and starts a new line.
    if (now - completedNs_ < kStragglerNs) return;
    startStage(stage, done, total, now);
  } else if (stage == stage_ && (lineOpen_ || inLoop_)) {
    if (done < lastDone_) return;  // out of order: never move backwards
  } else {
    if (lineOpen_ && !inLoop_) endLine();  // previous stage ended unfinished
    startStage(stage, done, total, now);
  }
  lastDone_ = done;
  lastTotal_ = total;
  redraw(now);
  if (total > 0 && done >= total) {
    // Inside a loop the line stays open: the loop's next stage redraws it.
    if (!inLoop_) endLine();
    stageDone_ = true;
    completedNs_ = now;
  }
}

void ProgressBar::redraw(int64_t now) {
  LineParts p;
  p.stage = stage_;
  p.done = lastDone_;
  p.total = lastTotal_;
  p.unit = stageUnit(stage_);
  if (inLoop_) {
    p.loop = formatLoopLabel(loop_);
    LoopTiming t;
    t.doneAtStart = loopDoneAtStart_;
    t.done = loop_.done;
    t.total = loop_.total;
    t.timeLimitSeconds = loop_.timeLimitSeconds;
    t.lastUnitEnd = double(loopLastUnitNs_ - loopStartNs_) * 1e-9;
    t.now = double(now - loopStartNs_) * 1e-9;
    p.elapsedSeconds = t.now;
    p.secondsLeft = estimateLoopSecondsLeft(t);
    if (loop_.photonsEmitted > loopPhotonsAtStart_ && t.lastUnitEnd > 0)
      p.photonsPerSecond = double(loop_.photonsEmitted - loopPhotonsAtStart_) / t.lastUnitEnd;
  } else {
    const double elapsed = double(now - stageStartNs_) * 1e-9;
    p.elapsedSeconds = elapsed;
    p.secondsLeft = estimateSecondsLeft(stageStartDone_, p.done, p.total, elapsed);
    if (p.unit == "photons" && p.done > stageStartDone_ && elapsed > 0)
      p.photonsPerSecond = double(p.done - stageStartDone_) / elapsed;
  }
  // One column short of the width: writing the last column makes some
  // terminals wrap before the \r.
  std::string line = formatProgressLine(p, width_ - 1);
  // \r + clear-to-end-of-line: redraw in place.
  std::fprintf(out_, "\r%s\x1b[K", line.c_str());
  lineOpen_ = true;
  std::fflush(out_);
}

void ProgressBar::endLine() {
  if (!lineOpen_) return;
  std::fputc('\n', out_);
  std::fflush(out_);
  lineOpen_ = false;
}

void ProgressBar::startStage(const std::string& stage, size_t done, size_t total, int64_t now) {
  stage_ = stage;
  stageDone_ = false;
  stageStartNs_ = now;
  // The first sight of a stage may be late (throttled reports): measure the
  // rate from here, not from 0, so the estimate stays unbiased.
  stageStartDone_ = (total > 0 && done >= total) ? 0 : done;
  lastDone_ = 0;
  lastTotal_ = total;
}

void ProgressBar::finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  endLine();
  inLoop_ = false;
}

}  // namespace tdpm::cli
