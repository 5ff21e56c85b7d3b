// tests/test_output_races.cpp — issue 27 items 8, 12 and 13: frame patterns
// of any width give one file per frame; concurrent runs committing the same
// EXR + PNG pair never leave one run's EXR beside another's PNG (the
// directory flock of core/atomic_file, which a reader may share); a signal
// while ffmpeg makes the --video ends ffmpeg and removes its folder; and a
// later run removes the temporaries a killed run left, and nothing else.
#include <dirent.h>
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli/frame_pattern.h"
#include "cli_harness.h"
#include "core/atomic_file.h"
#include "core/error.h"

using namespace tdpm;

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}



}  // namespace

TEST_CASE("output races: a frame pattern of any width gives one file per frame; a name too long is refused") {
  using namespace tdpm::cli;
  for (size_t run : {31u, 32u, 33u, 40u, 200u}) {
    CAPTURE(run);
    const std::string pattern = "out/f_" + std::string(run, '#') + ".exr";
    std::set<std::string> names;
    for (int frame : {0, 1, 7, 99999}) {
      const std::string name = formatFramePath(pattern, frame);
      const std::string digits = std::to_string(frame);
      // Zero-padded to the run's width: a 32-byte buffer cut it before.
      CHECK(name == "out/f_" + std::string(run - digits.size(), '0') + digits + ".exr");
      names.insert(name);
    }
    CHECK(names.size() == 4);
    CHECK_NOTHROW(checkFramePattern(pattern, FrameRange{0, 99999}));
  }
  CHECK(formatFramePath("f_##.exr", 12345) == "f_12345.exr");  // a longer number keeps its digits
  const std::string tooLong = "out/f_" + std::string(300, '#') + ".exr";
  std::string msg;
  try {
    checkFramePattern(tooLong, FrameRange{0, 3});
  } catch (const Error& e) {
    msg = e.what();
  }
  CHECK(msg.rfind("--output: '" + tooLong + "' gives file names of 306 bytes (frame 3), more than a file name may have (255)",
                  0) == 0);
}

TEST_CASE("output races: six writers of one pair never leave a mixed pair; a reader sharing the lock sees whole pairs") {
  const std::string dir = test::makeTempDir();
  const std::string exr = dir + "/s.exr", png = dir + "/s.png";
  constexpr int kWriters = 6, kCommits = 150;
  std::vector<pid_t> kids;
  for (int w = 0; w < kWriters; ++w) {
    pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      for (int i = 0; i < kCommits; ++i) {
        const std::string tag = std::to_string(w) + "." + std::to_string(i);
        try {
          AtomicFile a(exr), b(png);
          test::writeFile(a.tempPath(), "exr " + tag);
          test::writeFile(b.tempPath(), "png " + tag);
          commitTogether({&a, &b});
        } catch (...) {
          ::_exit(2);
        }
      }
      ::_exit(0);
    }
    kids.push_back(pid);
  }
  // The reader: under flock(LOCK_SH) on the directory (docs/output-safety.md)
  // the two files are always one commit's.
  int reads = 0, mixed = 0;
  std::string example;
  for (bool running = true; running;) {
    int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    REQUIRE(fd >= 0);
    REQUIRE(::flock(fd, LOCK_SH) == 0);
    const std::string a = readAll(exr), b = readAll(png);
    ::close(fd);
    if (!a.empty() && !b.empty()) {
      ++reads;
      if (a.substr(4) != b.substr(4)) {
        ++mixed;
        example = a + " / " + b;
      }
    }
    running = false;
    for (pid_t k : kids)
      if (::waitpid(k, nullptr, WNOHANG) == 0) running = true;  // a finished one is reaped here
  }
  INFO(example);
  CHECK(reads > 0);
  CHECK(mixed == 0);
  const std::string a = readAll(exr), b = readAll(png);
  CHECK(a.substr(0, 4) == "exr ");
  CHECK(a.substr(4) == b.substr(4));
  std::vector<std::string> left = test::folderEntries(dir);
  CHECK(left.size() == 2);  // no temporary, no lock file
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("output races: a new output removes the temporaries of dead runs for that name, and nothing else") {
  const std::string dir = test::makeTempDir();
  const std::string dead = std::to_string(test::deadPid());
  REQUIRE(::kill(std::stoi(dead), 0) == -1);
  // Process 1 is always running; our own pid is a live run too.
  const std::string self = std::to_string(::getpid());
  const std::vector<std::string> stale = {".x.exr.tmp." + dead + ".0", ".x.exr.tmp." + dead + ".17"};
  const std::vector<std::string> kept = {
      ".x.exr.tmp.1.0",             ".x.exr.tmp." + self + ".999999", ".y.exr.tmp." + dead + ".0",
      ".x.exr.tmp." + dead + ".0.bak", "x.exr.tmp." + dead + ".0",    ".x.exr.tmp.0" + dead + ".0",
      ".x.exr.tmp." + dead + ".",    ".x.exr.tmp.-" + dead + ".0",    ".x.exr.tmp." + dead + ".1x"};
  for (const std::string& n : stale) test::writeFile(dir + "/" + n, std::string(1000, 'x'));
  for (const std::string& n : kept) test::writeFile(dir + "/" + n, "keep");
  {
    AtomicFile f(dir + "/x.exr");
    test::writeFile(f.tempPath(), "new");
    f.commit();
  }
  for (const std::string& n : stale) CHECK_MESSAGE(!test::fileExists(dir + "/" + n), n);
  for (const std::string& n : kept) CHECK_MESSAGE(test::fileExists(dir + "/" + n), n);
  CHECK(readAll(dir + "/x.exr") == "new");
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("output races: SIGTERM while ffmpeg makes the --video kills ffmpeg and removes its folder") {
  const std::string dir = test::makeTempDir();
  // A stand-in ffmpeg that says who it is and then waits (exec: the pid
  // tdpm started is the one that sleeps).
  const std::string bin = dir + "/bin", pidFile = dir + "/ffmpeg.pid";
  REQUIRE(::mkdir(bin.c_str(), 0755) == 0);
  test::writeFile(bin + "/ffmpeg", "#!/bin/sh\necho $$ > '" + pidFile + ".tmp'\nmv '" + pidFile + ".tmp' '" + pidFile +
                                       "'\nexec sleep 300\n");
  REQUIRE(::chmod((bin + "/ffmpeg").c_str(), 0755) == 0);
  const std::string scene = dir + "/anim.json";
  test::writeFile(scene, R"({"animation": {"fps": 24, "frames": 2},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0.3, 0], "resolution": [8, 6]},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200]}]})");
  const std::string video = dir + "/v";
  REQUIRE(::mkdir(video.c_str(), 0755) == 0);
  pid_t tdpm = ::fork();
  REQUIRE(tdpm >= 0);
  if (tdpm == 0) {
    int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(null, 2);
    const std::string path = bin + ":/usr/bin:/bin";
    ::setenv("PATH", path.c_str(), 1);
    const std::string out = dir + "/o/f_##.exr", mp4 = video + "/movie.mp4";
    ::execl(TDPM_BINARY, TDPM_BINARY, "render", scene.c_str(), "-o", out.c_str(), "--video", mp4.c_str(), "--spp",
            "1", "--photons", "100", "--global-photons", "100", "-q", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait (no time is asserted) until the stand-in runs, or tdpm has ended.
  bool started = false;
  for (int i = 0; i < 6000 && !started; ++i) {
    if (test::fileExists(pidFile)) started = true;
    else if (::waitpid(tdpm, nullptr, WNOHANG) == tdpm) break;
    else ::usleep(10000);
  }
  REQUIRE(started);
  const int ffmpeg = std::atoi(readAll(pidFile).c_str());
  REQUIRE(ffmpeg > 0);
  bool folder = false;
  for (const std::string& n : test::folderEntries(video)) folder = folder || n.rfind(".tdpm-video-", 0) == 0;
  CHECK(folder);  // the folder the fix must remove exists while ffmpeg runs
  REQUIRE(::kill(tdpm, SIGTERM) == 0);
  // A hang guard, not a timing: the stand-in sleeps 300 s, and a tdpm that
  // waits for it (the old behaviour, with a Deferral) would hold the suite
  // that long; the fixed one ends at once. 120 s fails cleanly instead.
  int status = 0;
  bool ended = false;
  for (int i = 0; i < 12000 && !ended; ++i) {
    ended = ::waitpid(tdpm, &status, WNOHANG) == tdpm;
    if (!ended) ::usleep(10000);
  }
  if (!ended) {
    FAIL_CHECK("tdpm still runs 120 s after SIGTERM: it waits for ffmpeg");
    ::kill(ffmpeg, SIGKILL);
    REQUIRE(::waitpid(tdpm, &status, 0) == tdpm);
  }
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);
  // ffmpeg was tdpm's child: killed and reaped by it, so it is gone.
  const bool alive = ::kill(ffmpeg, 0) == 0;
  CHECK_FALSE(alive);
  if (alive) ::kill(ffmpeg, SIGKILL);  // the stand-in this test started
  CHECK(test::folderEntries(video).empty());       // no folder, no video
  std::system(("rm -rf '" + dir + "'").c_str());
}
