// tests/test_work_folder.cpp — issue 27 item 13, the SIGKILL half: the
// --video work folder carries its owner's pid (core/temp_dir), and a later
// run removes the folders of dead runs, only those, and never what their
// links point to.
#include <dirent.h>
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "core/temp_dir.h"

using namespace tdpm;

namespace {



bool isDir(const std::string& p) {
  struct stat st;
  return ::lstat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}
bool exists(const std::string& p) {
  struct stat st;
  return ::lstat(p.c_str(), &st) == 0;
}

}  // namespace

TEST_CASE("work folders: a dead run's folder is removed; live, foreign and look-alike entries stay") {
  const std::string dir = test::makeTempDir();
  const std::string dead = std::to_string(test::deadPid()), live = std::to_string(::getppid());
  const std::string keepFile = dir + "/frame.png";
  test::writeFile(keepFile, "png");
  const std::string staleDir = dir + "/.tdpm-video-" + dead + "-aB3xY9";
  REQUIRE(::mkdir(staleDir.c_str(), 0700) == 0);
  REQUIRE(::symlink(keepFile.c_str(), (staleDir + "/000000.png").c_str()) == 0);  // a link to a real frame
  test::writeFile(staleDir + "/video.mp4", "half a video");
  const std::vector<std::string> kept = {
      ".tdpm-video-" + live + "-aB3xY9",   // a live process's
      ".tdpm-video-" + dead + "-aB3xY",    // five characters: not mkdtemp's
      ".tdpm-video-" + dead + "-aB3x_9",   // not mkdtemp's characters
      ".tdpm-video-" + dead + "aB3xY9",    // no dash
      ".tdpm-video-XXaB3xY9",              // no pid (the old names)
      ".tdpm-frame-" + dead + "-aB3xY9",   // another prefix
      "tdpm-video-" + dead + "-aB3xY9",    // no dot
  };
  for (const std::string& n : kept) REQUIRE(::mkdir((dir + "/" + n).c_str(), 0700) == 0);
  const std::string plainFile = ".tdpm-video-" + dead + "-fIlE00";  // the right name, but a file
  test::writeFile(dir + "/" + plainFile, "mine");
  const std::string target = dir + "/elsewhere";
  REQUIRE(::mkdir(target.c_str(), 0700) == 0);
  test::writeFile(target + "/precious", "x");
  const std::string linkName = ".tdpm-video-" + dead + "-LiNk00";  // the right name, but a link to a folder
  REQUIRE(::symlink(target.c_str(), (dir + "/" + linkName).c_str()) == 0);

  CHECK(removeStaleWorkFolders(dir, ".tdpm-video-") == 1);
  CHECK_FALSE(exists(staleDir));
  CHECK(test::fileExists(keepFile));  // the link went, its frame stays
  for (const std::string& n : kept) CHECK_MESSAGE(isDir(dir + "/" + n), n);
  CHECK(test::fileExists(dir + "/" + plainFile));
  CHECK(exists(dir + "/" + linkName));
  CHECK(test::fileExists(target + "/precious"));

  // A new folder is named by this process, and is not removed as stale.
  const std::string mine = makeWorkFolder(dir, ".tdpm-video-", "--video");
  CHECK(mine.rfind(dir + "/.tdpm-video-" + std::to_string(::getpid()) + "-", 0) == 0);
  CHECK(mine.size() == dir.size() + 1 + std::string(".tdpm-video-").size() + std::to_string(::getpid()).size() + 7);
  CHECK(isDir(mine));
  CHECK(removeStaleWorkFolders(dir, ".tdpm-video-") == 0);
  CHECK(isDir(mine));
  CHECK_THROWS_WITH_AS(makeWorkFolder(dir + "/missing", ".tdpm-video-", "--video"),
                       doctest::Contains("--video: cannot create a temporary directory in"), std::exception);
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("work folders: the folder a SIGKILLed --video run left is removed by the next --video run") {
  const std::string dir = test::makeTempDir();
  const std::string bin = dir + "/bin", pidFile = dir + "/ffmpeg.pid", mode = dir + "/mode";
  REQUIRE(::mkdir(bin.c_str(), 0755) == 0);
  // A stand-in ffmpeg: first it says who it is and waits (to be killed with
  // tdpm); once `mode` exists it writes its output (the last argument).
  test::writeFile(bin + "/ffmpeg", "#!/bin/sh\nif [ -e '" + mode + "' ]; then for a; do out=$a; done; echo v > \"$out\"; "
                                   "exit 0; fi\necho $$ > '" + pidFile + ".tmp'\nmv '" + pidFile + ".tmp' '" + pidFile +
                                   "'\nexec sleep 300\n");
  REQUIRE(::chmod((bin + "/ffmpeg").c_str(), 0755) == 0);
  const std::string scene = dir + "/anim.json";
  test::writeFile(scene, R"({"animation": {"fps": 24, "frames": 2},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0.3, 0], "resolution": [8, 6]},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200]}]})");
  const std::string video = dir + "/v", mp4 = video + "/movie.mp4";
  REQUIRE(::mkdir(video.c_str(), 0755) == 0);
  const std::string path = bin + ":/usr/bin:/bin";
  const std::string args = "render '" + scene + "' -o '" + dir + "/o/f_##.exr' --video '" + mp4 +
                           "' --spp 1 --photons 100 --global-photons 100 -q";
  pid_t tdpm = ::fork();
  REQUIRE(tdpm >= 0);
  if (tdpm == 0) {
    int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::setenv("PATH", path.c_str(), 1);
    const std::string out = dir + "/o/f_##.exr";
    ::execl(TDPM_BINARY, TDPM_BINARY, "render", scene.c_str(), "-o", out.c_str(), "--video", mp4.c_str(), "--spp",
            "1", "--photons", "100", "--global-photons", "100", "-q", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool started = false;  // no time is asserted: wait until the stand-in runs, or tdpm ended
  for (int i = 0; i < 6000 && !started; ++i) {
    if (test::fileExists(pidFile)) started = true;
    else if (::waitpid(tdpm, nullptr, WNOHANG) == tdpm) break;
    else ::usleep(10000);
  }
  REQUIRE(started);
  REQUIRE(::kill(tdpm, SIGKILL) == 0);
  int status = 0;
  REQUIRE(::waitpid(tdpm, &status, 0) == tdpm);
  std::ifstream pidIn(pidFile);
  int ffmpeg = 0;
  pidIn >> ffmpeg;
  REQUIRE(ffmpeg > 0);
  // The kernel ends ffmpeg with its parent (PR_SET_PDEATHSIG in runProcess):
  // wait until it is gone or a zombie (no time asserted: a bounded wait).
  auto running = [](int pid) {
    if (::kill(pid, 0) != 0) return false;
    std::ifstream st("/proc/" + std::to_string(pid) + "/stat");
    std::string pidText, comm, state;
    st >> pidText >> comm >> state;
    return state != "Z" && state != "X";
  };
  bool ended = false;
  for (int i = 0; i < 6000 && !ended; ++i) {
    ended = !running(ffmpeg);
    if (!ended) ::usleep(10000);
  }
  CHECK(ended);                          // not left orphaned
  if (!ended) ::kill(ffmpeg, SIGKILL);  // do not leave it behind the test either
  const std::string left = ".tdpm-video-" + std::to_string(tdpm) + "-";
  std::vector<std::string> before = test::folderEntries(video);
  REQUIRE(before.size() == 1);  // SIGKILL cannot be caught: the folder stays, named by the dead pid
  CHECK(before[0].rfind(left, 0) == 0);

  test::writeFile(mode, "write");
  const test::CommandResult r = test::runShell("PATH='" + path + "' '" + TDPM_BINARY + "' " + args + " 2>&1");
  INFO(r.output);
  CHECK(r.exitCode == 0);
  const std::vector<std::string> after = test::folderEntries(video);
  CHECK(after == std::vector<std::string>{"movie.mp4"});
  std::system(("rm -rf '" + dir + "'").c_str());
}
