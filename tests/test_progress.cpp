// tests/test_progress.cpp — cli/progress_bar: line formatting, ETA maths,
// and the bar's behaviour (throttling, stage lines, thread safety) drawn into
// a temporary file instead of a terminal.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "cli/progress_bar.h"
#include "render/tile_loop.h"

using namespace tdpm;
using namespace tdpm::cli;

namespace {

std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

size_t count(const std::string& s, const std::string& needle) {
  size_t n = 0;
  for (size_t p = s.find(needle); p != std::string::npos; p = s.find(needle, p + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("progress: durations") {
  CHECK(formatDuration(0) == "0:00");
  CHECK(formatDuration(5.4) == "0:05");
  CHECK(formatDuration(65) == "1:05");
  CHECK(formatDuration(3599.4) == "59:59");
  CHECK(formatDuration(3600) == "1:00:00");
  CHECK(formatDuration(3 * 3600 + 62) == "3:01:02");
  CHECK(formatDuration(-1) == "--:--");
  CHECK(formatDuration(1.0 / 0.0) == "--:--");
  CHECK(formatDuration(1e12) == "999:00:00");
}

TEST_CASE("progress: time left from the observed rate") {
  CHECK(estimateSecondsLeft(0, 25, 100, 10.0) == doctest::Approx(30.0));
  // Baseline: first seen at 50 units; 10 more units in 2 s -> 5/s; 40 left.
  CHECK(estimateSecondsLeft(50, 60, 100, 2.0) == doctest::Approx(8.0));
  CHECK(estimateSecondsLeft(0, 100, 100, 10.0) == 0.0);
  CHECK(estimateSecondsLeft(0, 0, 100, 10.0) < 0);   // no progress yet
  CHECK(estimateSecondsLeft(0, 10, 0, 10.0) < 0);    // total unknown
  CHECK(estimateSecondsLeft(0, 10, 100, 0.0) < 0);   // no time yet
}

// A stage line as the bar draws it (unit from the stage's name).
static std::string stageLine(const std::string& stage, size_t done, size_t total, double elapsed, double left,
                             int width, double perSecond = -1) {
  LineParts p;
  p.stage = stage;
  p.done = done;
  p.total = total;
  p.unit = stageUnit(stage);
  p.elapsedSeconds = elapsed;
  p.secondsLeft = left;
  p.photonsPerSecond = perSecond;
  return formatProgressLine(p, width);
}

TEST_CASE("progress: short counts and units") {
  CHECK(formatShortCount(0) == "0");
  CHECK(formatShortCount(920) == "920");
  CHECK(formatShortCount(999) == "999");
  CHECK(formatShortCount(1000) == "1.00k");
  CHECK(formatShortCount(60416) == "60.4k");
  CHECK(formatShortCount(221184) == "221k");
  CHECK(formatShortCount(999600) == "1.00M");  // not "1000k"
  CHECK(formatShortCount(1102848) == "1.10M");
  CHECK(formatShortCount(2.5e9) == "2.50G");
  CHECK(formatShortCount(-3) == "0");
  CHECK(stageUnit("caustic photons") == "photons");
  CHECK(stageUnit("global photons") == "photons");
  CHECK(stageUnit("render") == "tiles");
  CHECK(stageUnit("render (adaptive pass 2)") == "tiles");
  CHECK(stageUnit("frame 3/8") == "tiles");
}

TEST_CASE("progress: the line") {
  std::string line = stageLine("render", 450, 1000, 12.0, 15.0, 100);
  CHECK(line.size() <= 100);
  CHECK(line.rfind("render [", 0) == 0);
  CHECK(line.find("]  45%  450/1000 tiles, 0:12 elapsed, 0:15 left") != std::string::npos);
  // The bar: 40 cells (the most) at this width, 18 full, then the arrow head.
  const size_t open = line.find('['), close = line.find(']');
  CHECK(close - open - 1 == 40);
  CHECK(count(line, "=") == 18);
  CHECK(line.find("=>") != std::string::npos);

  std::string done = stageLine("render", 1000, 1000, 61.0, 0.0, 100);
  CHECK(done.find("100% 1000/1000 tiles, 1:01 elapsed") != std::string::npos);
  CHECK(done.find("left") == std::string::npos);
  CHECK(done.find('>') == std::string::npos);  // full bar, no head
  CHECK(count(done, "=") == 40);
  // The bar keeps its length while it fills (done is padded, the "left"
  // part stays reserved), so it does not jump about on screen.
  for (size_t d : {size_t(1), size_t(999), size_t(1000)})
    CHECK(stageLine("render", d, 1000, 1.0, d == 1 ? -1.0 : 1.0, 70).find(']') ==
          stageLine("render", 500, 1000, 1.0, 1.0, 70).find(']'));

  // 99.9% never shows as 100%; unknown ETA shows dashes.
  CHECK(stageLine("x", 999, 1000, 1.0, -1.0, 80).find(" 99%  999/1000 tiles, 0:01 elapsed, --:-- left") !=
        std::string::npos);

  // Narrow terminal: the bar shrinks, then disappears, the line always fits.
  for (int width : {60, 45, 30, 10}) {
    CAPTURE(width);
    CHECK(stageLine("render", 450, 1000, 12.0, 15.0, width).size() <= size_t(width));
  }
  CHECK(stageLine("render", 450, 1000, 12.0, 15.0, 45).find('[') == std::string::npos);

  // Unknown total: just a count.
  CHECK(stageLine("scan", 42, 0, 3.0, -1.0, 80) == "scan 42 tiles, 0:03 elapsed");
}

TEST_CASE("progress: photon stages count photons emitted and show their rate") {
  std::string line = stageLine("caustic photons", 221184, 1102848, 0.4, 1.6, 120, 552960.0);
  CHECK(line.find("]  20%  221k/1.10M emitted (553k/s), 0:00 elapsed, 0:02 left") != std::string::npos);
  // The bar does not move when the rate appears after the first batches.
  CHECK(stageLine("caustic photons", 0, 1102848, 0.0, -1.0, 120).find(']') == line.find(']'));
  // In 79 columns (an 80-column terminal) the whole tail fits.
  std::string narrow = stageLine("caustic photons", 221184, 1102848, 0.4, 1.6, 79, 552960.0);
  CHECK(narrow.size() <= 79);
  CHECK(narrow.find("(553k/s), 0:00 elapsed, 0:02 left") != std::string::npos);
  // Finished: no "left", the rate stays.
  CHECK(stageLine("global photons", 60416, 60416, 0.2, 0.0, 79, 302080.0) ==
        "global photons 100% 60.4k/60.4k emitted (302k/s), 0:00 elapsed");
}

TEST_CASE("progress: loop lines (passes, frames)") {
  WorkPosition w;
  w.unit = "pass";
  w.done = 2;
  w.total = 10;
  CHECK(formatLoopLabel(w) == "pass 3/10");
  w.done = 10;
  CHECK(formatLoopLabel(w) == "pass 10/10");
  w.total = 0;
  w.done = 3;
  w.timeLimitSeconds = 60;
  CHECK(formatLoopLabel(w) == "pass 4 (time limit 1:00)");
  w.unit = "frame";
  w.done = 0;
  w.total = 24;
  w.timeLimitSeconds = 0;
  CHECK(formatLoopLabel(w) == "frame 1/24");

  LineParts p;
  p.loop = "pass 3/10";
  p.elapsedSeconds = 32;
  p.secondsLeft = 68;
  p.photonsPerSecond = 812000;
  p.stage = "render";
  p.unit = "tiles";
  p.done = 414;
  p.total = 920;
  std::string line = formatProgressLine(p, 120);
  CHECK(line.rfind("pass 3/10, 0:32 elapsed, 1:08 left, 812k photons/s | render [", 0) == 0);
  CHECK(line.find("]  45% 414/920 tiles") != std::string::npos);
  // Narrow: the stage part goes, the loop's position and times stay.
  std::string narrow = formatProgressLine(p, 56);
  CHECK(narrow.size() <= 56);
  CHECK(narrow.rfind("pass 3/10, 0:32 elapsed, 1:08 left, 812k photons/s", 0) == 0);
  // Before the first stage report: the loop part alone, unknown time left.
  LineParts first;
  first.loop = "pass 1/10";
  first.secondsLeft = -1;
  CHECK(formatProgressLine(first, 80) == "pass 1/10, 0:00 elapsed, --:-- left");
}

TEST_CASE("progress: time left of a loop, from the units measured") {
  LoopTiming t;
  t.total = 10;
  // Nothing measured yet, no limit: unknown.
  t.now = 3;
  CHECK(estimateLoopSecondsLeft(t) < 0);
  // 3 passes took 12 s (4 s each); 1 s into the 4th: 3 s of it and 6 more.
  t.done = 3;
  t.lastUnitEnd = 12;
  t.now = 13;
  CHECK(estimateLoopSecondsLeft(t) == doctest::Approx(3.0 + 6 * 4.0));
  // The pass under way overran the mean (6 s into it): taken to end now.
  t.now = 18;
  CHECK(estimateLoopSecondsLeft(t) == doctest::Approx(6 * 4.0));
  // Finished: 0.
  t.done = 10;
  CHECK(estimateLoopSecondsLeft(t) == 0.0);

  // A resumed render: 5 passes were done before this run; 2 more took 10 s.
  LoopTiming r;
  r.doneAtStart = 5;
  r.done = 7;
  r.total = 10;
  r.lastUnitEnd = 10;
  r.now = 10;
  CHECK(estimateLoopSecondsLeft(r) == doctest::Approx(3 * 5.0));

  // Time limit 60 s, no total. Before any pass is measured: at least the
  // limit minus now.
  LoopTiming l;
  l.timeLimitSeconds = 60;
  l.now = 5;
  CHECK(estimateLoopSecondsLeft(l) == doctest::Approx(55.0));
  // Passes of 7 s (3 done at 21 s, now 22): they end at 28, 35, ..., 56,
  // 63: the one ending at 63 is the first at or past the limit.
  l.done = 3;
  l.lastUnitEnd = 21;
  l.now = 22;
  CHECK(estimateLoopSecondsLeft(l) == doctest::Approx(63.0 - 22.0));
  // A pass boundary exactly on the limit ends the loop there (6 s passes).
  l.lastUnitEnd = 18;
  l.now = 18;
  CHECK(estimateLoopSecondsLeft(l) == doctest::Approx(60.0 - 18.0));
  // Past the limit: the pass under way is the last.
  l.done = 10;
  l.lastUnitEnd = 60;
  l.now = 62;
  CHECK(estimateLoopSecondsLeft(l) == doctest::Approx(4.0));  // 6 s pass started at 60
  // Total and limit: whichever ends first.
  LoopTiming b = l;
  b.total = 11;
  CHECK(estimateLoopSecondsLeft(b) == doctest::Approx(4.0));
  b.timeLimitSeconds = 1000;
  b.total = 12;
  CHECK(estimateLoopSecondsLeft(b) == doctest::Approx(4.0 + 6.0));
}

TEST_CASE("progress: the scattered tile order is a permutation spread over the image") {
  for (size_t total : {size_t(1), size_t(2), size_t(3), size_t(920), size_t(1024), size_t(4096 * 4096)}) {
    CAPTURE(total);
    const size_t stride = tileOrderStride(total);
    CHECK(stride >= 1);
    if (total > 1 << 16) continue;  // the permutation check below is for small totals
    std::vector<char> seen(total, 0);
    for (size_t k = 0; k < total; ++k) seen[size_t((uint64_t(k) * stride) % total)] = 1;
    CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(total));
  }
  // glass-ball's 40x23 tiles: the first quarter handed out covers every
  // tenth of the image's rows with between 15% and 35% of its tiles.
  const size_t total = 920, stride = tileOrderStride(total);
  std::vector<int> perBand(10, 0);
  for (size_t k = 0; k < total / 4; ++k) ++perBand[(uint64_t(k) * stride % total) * 10 / total];
  for (int n : perBand) CHECK((n >= 0.15 * 92 && n <= 0.35 * 92));
}

TEST_CASE("progress: a disabled bar is silent and gives an empty Progress") {
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  {
    ProgressBar bar(false, f);
    CHECK(!bar.progress().report);
    bar.report("render", 1, 2);
    bar.report("render", 2, 2);
  }
  CHECK(contents(f).empty());
  std::fclose(f);
}

TEST_CASE("progress: stages end with a newline, stragglers and backwards steps are ignored") {
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  {
    ProgressBar bar(true, f, 0.0, 100);  // no throttling: every report draws
    Progress p = bar.progress();
    p("photons", 1, 4);
    p("photons", 3, 4);
    p("photons", 2, 4);  // out of order: ignored
    p("photons", 4, 4);
    p("photons", 3, 4);  // straggler after completion: ignored
    p("render", 5, 10);
    p("gather", 1, 3);   // render never finished: its line is ended anyway
  }                      // destructor ends the open "gather" line
  std::string out = contents(f);
  CHECK(count(out, "\n") == 3);
  CHECK(count(out, "\r") == 5);
  CHECK(out.find("2/4") == std::string::npos);
  CHECK(count(out, "3/4") == 1);
  CHECK(out.find("100% 4/4") != std::string::npos);
  CHECK(out.find("5/10") < out.find("1/3"));
  CHECK(out.back() == '\n');
  std::fclose(f);
}

TEST_CASE("progress: a stage name reused later is a new run") {
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  {
    ProgressBar bar(true, f, 0.0, 100);
    bar.report("frame", 2, 2);
    std::this_thread::sleep_for(std::chrono::milliseconds(80));
    bar.report("frame", 1, 2);
    bar.report("frame", 2, 2);
  }
  std::string out = contents(f);
  CHECK(count(out, "100% 2/2") == 2);
  CHECK(count(out, "1/2") == 1);
  CHECK(count(out, "\n") == 2);
  std::fclose(f);
}

TEST_CASE("progress: throttled redraws from many threads, final state always drawn") {
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  const size_t total = 4 * 20000;
  {
    ProgressBar bar(true, f, 0.1, 100);
    Progress p = bar.progress();
    std::atomic<size_t> done{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
      threads.emplace_back([&] {
        for (int i = 0; i < 20000; ++i) p("render", done.fetch_add(1) + 1, total);
      });
    for (auto& t : threads) t.join();
  }
  std::string out = contents(f);
  // 80,000 reports in well under a second or two: a handful of redraws.
  CHECK(count(out, "\r") < 50);
  CHECK(out.find("100% 80000/80000") != std::string::npos);
  CHECK(count(out, "\n") == 1);
  std::fclose(f);
}

TEST_CASE("progress: inside a loop, one line for all passes, ended when the loop ends") {
  std::FILE* f = std::tmpfile();
  REQUIRE(f);
  {
    ProgressBar bar(true, f, 0.0, 120);
    Progress p = bar.progress();
    REQUIRE(p.position);
    WorkPosition w;
    w.unit = "pass";
    w.total = 2;
    p.at(w);
    for (int pass = 0; pass < 2; ++pass) {
      p("caustic photons", 0, 2048);
      p("caustic photons", 2048, 2048);
      p("render", 0, 4);
      p("render", 4, 4);
      w.done = size_t(pass + 1);
      w.photonsEmitted += 2048;
      p.at(w);
    }
    p("after the loop", 1, 2);  // a stage after the loop gets its own line again
  }
  std::string out = contents(f);
  CHECK(count(out, "\n") == 2);  // the loop's line and the later stage's
  CHECK(out.find("pass 1/2, 0:00 elapsed, --:-- left") != std::string::npos);
  CHECK(out.find("pass 2/2") != std::string::npos);
  CHECK(out.find("| caustic photons [") != std::string::npos);
  CHECK(out.find("| render [") != std::string::npos);
  CHECK(out.find("photons/s") != std::string::npos);
  CHECK(out.find("\n") > out.rfind("pass 2/2"));  // the line ends only after the last pass
  CHECK(out.find("after the loop") > out.find("\n"));
  std::fclose(f);
}
