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

TEST_CASE("progress: the line") {
  std::string line = formatProgressLine("render", 450, 1000, 12.0, 15.0, 100);
  CHECK(line.size() <= 100);
  CHECK(line.rfind("render [", 0) == 0);
  CHECK(line.find("]  45%  450/1000 0:12 elapsed, 0:15 left") != std::string::npos);
  // The bar: 40 cells (the most) at this width, 18 full, then the arrow head.
  const size_t open = line.find('['), close = line.find(']');
  CHECK(close - open - 1 == 40);
  CHECK(count(line, "=") == 18);
  CHECK(line.find("=>") != std::string::npos);

  std::string done = formatProgressLine("photons", 1000, 1000, 61.0, 0.0, 100);
  CHECK(done.find("100% 1000/1000 1:01 elapsed") != std::string::npos);
  CHECK(done.find("left") == std::string::npos);
  CHECK(done.find('>') == std::string::npos);  // full bar, no head
  CHECK(count(done, "=") == 40);
  // The bar keeps its length while it fills (done is padded, the "left"
  // part stays reserved), so it does not jump about on screen.
  for (size_t d : {size_t(1), size_t(999), size_t(1000)})
    CHECK(formatProgressLine("render", d, 1000, 1.0, d == 1 ? -1.0 : 1.0, 70).find(']') ==
          formatProgressLine("render", 500, 1000, 1.0, 1.0, 70).find(']'));

  // 99.9% never shows as 100%; unknown ETA shows dashes.
  CHECK(formatProgressLine("x", 999, 1000, 1.0, -1.0, 80).find(" 99%  999/1000 0:01 elapsed, --:-- left") !=
        std::string::npos);

  // Narrow terminal: the bar shrinks, then disappears, the line always fits.
  for (int width : {60, 45, 30, 10}) {
    CAPTURE(width);
    CHECK(formatProgressLine("render", 450, 1000, 12.0, 15.0, width).size() <= size_t(width));
  }
  CHECK(formatProgressLine("render", 450, 1000, 12.0, 15.0, 45).find('[') == std::string::npos);

  // Unknown total: just a count.
  CHECK(formatProgressLine("scan", 42, 0, 3.0, -1.0, 80) == "scan 42 0:03 elapsed");
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
