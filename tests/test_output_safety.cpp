// tests/test_output_safety.cpp — what happens to outputs when things go
// wrong (issue 11, items 10 and 12-15): the EXR + PNG pair is committed
// together (a failed write or rename leaves the old pair), output paths are
// checked before rendering (directories, long names, the temporary's name,
// inputs), symbolic links are written through keeping the target's mode,
// SIGINT/SIGTERM remove temporaries, the memory pre-flight names the
// resolution, and accumulation says when frames raise its budget.
#include <dirent.h>
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_harness.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/signals.h"
#include "image/exr.h"
#include "image/png.h"
#include "render/film_output.h"
#include "render/memory_budget.h"
#include "scene/description.h"
#include "scene_fixtures.h"

using namespace tdpm;
using test::runTdpm;

namespace {

// A moving sphere over a floor, a point light: pathtrace renders it in a
// blink at the sizes used here.
const char* kScene = R"({
  "camera": {"position": [0, 1, 4], "target": [0, 0.5, 0], "fov": 40, "resolution": [32, 24], "shutter": [0, 1]},
  "materials": {"white": {"type": "diffuse", "color": 0.7}},
  "objects": [
    {"shape": {"type": "quad", "size": [4, 4]}, "material": "white"},
    {"shape": {"type": "sphere", "radius": 0.4}, "material": "white",
     "transform": {"translate": [0, 0.5, 0]},
     "motion": [{"time": 0, "translate": [-0.5, 0, 0]}, {"time": 1, "translate": [0.5, 0, 0]}]}],
  "lights": [{"type": "point", "position": [0, 3, 1], "power": 200}],
  "render": {"method": "pathtrace", "spp": 2}
})";

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Names in `dir` that look like our temporaries.
std::vector<std::string> temporariesIn(const std::string& dir) {
  std::vector<std::string> found;
  DIR* d = ::opendir(dir.c_str());
  while (d) {
    const dirent* e = ::readdir(d);
    if (!e) break;
    if (contains(e->d_name, ".tmp.")) found.push_back(e->d_name);
  }
  if (d) ::closedir(d);
  return found;
}

mode_t modeOf(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 07777) : mode_t(0);
}

bool isSymlink(const std::string& path) {
  struct stat st;
  return ::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

// Waits (at most ~10 s) until process `pid` has a handler for `signo`
// (the SigCgt mask in /proc), so a signal sent after this meets tdpm's
// handler and not the default action, however slowly the child started.
void waitUntilCatching(pid_t pid, int signo) {
  for (int i = 0; i < 1000; ++i) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("SigCgt:", 0) == 0 && (std::stoull(line.substr(7), nullptr, 16) >> (signo - 1)) & 1) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// A forked test child's messages would clutter the test log.
void quietChild() {
  int fd = ::open("/dev/null", O_WRONLY);
  if (fd >= 0) ::dup2(fd, STDERR_FILENO);
}

// Writes `text` through AtomicFile's temporary, as the image writers do.
void fill(const AtomicFile& f, const std::string& text) { test::writeFile(f.tempPath(), text); }

// A scene directory with an earlier render's r.exr / r.png in it.
struct OldPair {
  std::string dir = test::makeTempDir();
  std::string scene = dir + "/s.json";
  std::string exr = dir + "/r.exr", png = dir + "/r.png";
  std::string oldExr, oldPng;
  OldPair() {
    test::writeFile(scene, kScene);
    auto r = runTdpm("render '" + scene + "' -q --seed 1 -o '" + exr + "'");
    REQUIRE_MESSAGE(r.exitCode == 0, r.output);
    oldExr = readAll(exr);
    oldPng = readAll(png);
    REQUIRE(oldExr.size() > 1000);
    REQUIRE(oldPng.size() > 100);
  }
  bool intact() const { return readAll(exr) == oldExr && readAll(png) == oldPng; }
};

}  // namespace

// ---- item 12: the pair is committed together ----

TEST_CASE("output safety: commitTogether replaces both files, or on a failed rename neither") {
  const std::string dir = test::makeTempDir();
  const std::string a = dir + "/r.exr", b = dir + "/r.png";
  test::writeFile(a, "old exr");
  test::writeFile(b, "old png");
  {
    AtomicFile fa(a), fb(b);
    fill(fa, "new exr");
    fill(fb, "new png");
    commitTogether({&fa, &fb});
    CHECK(fa.committed());
    CHECK(fb.committed());
  }
  CHECK(readAll(a) == "new exr");
  CHECK(readAll(b) == "new png");
  CHECK(temporariesIn(dir).empty());

  // The second rename fails (a directory appeared in its way after the
  // files were checked): the first target gets its old content back.
  {
    AtomicFile fa(a), fb(b);
    fill(fa, "newer exr");
    fill(fb, "newer png");
    REQUIRE(::unlink(b.c_str()) == 0);
    REQUIRE(::mkdir(b.c_str(), 0755) == 0);
    try {
      commitTogether({&fa, &fb});
      FAIL("commitTogether should have thrown");
    } catch (const Error& e) {
      CHECK(contains(e.what(), b));
      CHECK(contains(e.what(), "left as they were"));
    }
    CHECK_FALSE(fa.committed());
  }
  CHECK(readAll(a) == "new exr");
  CHECK(temporariesIn(dir).empty());

  // Now that a directory is where the preview goes, AtomicFile refuses it at once.
  CHECK_THROWS_WITH_AS(AtomicFile{b}, doctest::Contains("is a directory"), Error);
}

TEST_CASE("output safety: a failed group leaves a new first target absent") {
  const std::string dir = test::makeTempDir();
  const std::string c = dir + "/fresh.exr", b = dir + "/fresh.png";
  {
    AtomicFile fc(c), fb(b);
    fill(fc, "x");
    fill(fb, "y");
    REQUIRE(::mkdir(b.c_str(), 0755) == 0);
    CHECK_THROWS_AS(commitTogether({&fc, &fb}), Error);
  }
  CHECK_FALSE(test::fileExists(c));
  CHECK(temporariesIn(dir).empty());
}

TEST_CASE("output safety: a directory where the PNG goes is refused before rendering; the old pair stays") {
  OldPair old;
  REQUIRE(::unlink(old.png.c_str()) == 0);
  REQUIRE(::mkdir(old.png.c_str(), 0755) == 0);
  auto r = runTdpm("render '" + old.scene + "' -q --seed 2 -o '" + old.exr + "'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, old.png + ": is a directory"));
  CHECK(readAll(old.exr) == old.oldExr);
  CHECK(temporariesIn(old.dir).empty());
}

TEST_CASE("output safety: a write error (file size limit) leaves the old pair intact; a good run replaces both") {
  OldPair old;
  // The file-size limit makes writes past it fail with EFBIG, as a full
  // disk fails with ENOSPC: the preview (~0.8 kB) is written, the EXR
  // (~4.4 kB) is not (the limit is 1 or 2 kB: 2 blocks of 512 or 1024
  // bytes, as the shell counts). SIGXFSZ is ignored so the write error is seen.
  const std::string cmd = std::string("trap '' XFSZ; ulimit -f 2; exec '") + TDPM_BINARY + "' render '" +
                          old.scene + "' -q --seed 2 -o '" + old.exr + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int status = pclose(p);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK(contains(out, old.exr + ": cannot write OpenEXR file"));
  CHECK(old.intact());
  CHECK(temporariesIn(old.dir).empty());

  // Without the limit the same render replaces both files.
  auto r = runTdpm("render '" + old.scene + "' -q --seed 2 -o '" + old.exr + "'");
  REQUIRE(r.exitCode == 0);
  CHECK(readAll(old.exr) != old.oldExr);
  CHECK(readAll(old.png) != old.oldPng);
  CHECK(image::readExr(old.exr).metadata.at("tdpm/seed") == "2");
  CHECK(temporariesIn(old.dir).empty());
}

TEST_CASE("output safety: writeRenderOutputs writes a pair that reads back") {
  const std::string dir = test::makeTempDir();
  Film film(4, 3);
  for (size_t i = 0; i < film.color.size(); ++i) {
    film.color[i] = Rgb(float(i) * 0.1f);
    film.sampleCount[i] = 4;
    film.varianceOfMean[i] = Rgb(float(i), float(i) * 2, float(i) * 3);
  }
  image::ExrFile exr = filmToExr(std::move(film));
  CHECK(film.varianceOfMean.empty());  // the moved film holds nothing any more
  writeRenderOutputs(dir + "/o.exr", dir + "/o.png", exr, 0.0f);
  image::ExrFile back = image::readExr(dir + "/o.exr");
  CHECK(back.color.pixels[5][0] == doctest::Approx(0.5f));
  CHECK(back.findChannel("variance.B")->values[5] == 15.0f);
  CHECK(image::readPng(dir + "/o.png").width == 4);
  CHECK(temporariesIn(dir).empty());
}

// ---- item 13: output paths checked before the work ----

TEST_CASE("output safety: -o naming a directory fails before rendering") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", kScene);
  REQUIRE(::mkdir((dir + "/out.exr").c_str(), 0755) == 0);
  // A resolution whose render would take minutes: the error must come first.
  auto r = runTdpm("render '" + dir + "/s.json' -q --resolution 8000x8000 --spp 64 -o '" + dir + "/out.exr'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "--output: " + dir + "/out.exr: is a directory"));
  CHECK_FALSE(test::fileExists(dir + "/out.png"));
}

TEST_CASE("output safety: long names: the temporary stays within NAME_MAX; too long is refused up front") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", kScene);
  const std::string name250 = std::string(246, 'a') + ".exr";  // 250 bytes: its ".tmp.PID.N" would not fit
  auto r = runTdpm("render '" + dir + "/s.json' -q -o '" + dir + "/" + name250 + "'");
  CHECK_MESSAGE(r.exitCode == 0, r.output);
  CHECK(test::fileExists(dir + "/" + name250));
  CHECK(test::fileExists(dir + "/" + std::string(246, 'a') + ".png"));
  CHECK(temporariesIn(dir).empty());

  {
    AtomicFile f(dir + "/" + name250);
    std::string tempName = f.tempPath().substr(dir.size() + 1);
    CHECK(tempName.size() <= 255);
    CHECK(tempName.rfind(".aaaa", 0) == 0);
    CHECK(contains(tempName, ".tmp."));
  }

  const std::string name256 = std::string(252, 'b') + ".exr";
  auto r2 = runTdpm("render '" + dir + "/s.json' -q --resolution 8000x8000 --spp 64 -o '" + dir + "/" + name256 + "'");
  CHECK(r2.exitCode == 1);
  CHECK(contains(r2.output, "the file name is 256 bytes long, more than the file system allows (255)"));
  CHECK(temporariesIn(dir).empty());
}

// ---- item 15: inputs, symbolic links, modes ----

TEST_CASE("output safety: an output that is an input (scene or mesh, also via its preview) is refused") {
  const std::string dir = test::makeTempDir();
  // A scene file called scene.exr, rendered to its default name scene.exr.
  test::writeFile(dir + "/scene.exr", kScene);
  auto r = runTdpm("render '" + dir + "/scene.exr' -q -o '" + dir + "/scene.exr'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "is the scene file"));
  CHECK(readAll(dir + "/scene.exr") == kScene);
  // Through a symbolic link to the scene.
  REQUIRE(::symlink("scene.exr", (dir + "/link.exr").c_str()) == 0);
  auto r2 = runTdpm("render '" + dir + "/scene.exr' -q -o '" + dir + "/link.exr'");
  CHECK(r2.exitCode == 1);
  CHECK(contains(r2.output, "is the scene file"));
  CHECK(readAll(dir + "/scene.exr") == kScene);

  // A mesh that the preview would overwrite: out.exr's preview is out.png.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  test::writeFile(dir + "/out.png", obj);
  std::string scene = kScene;
  scene.replace(scene.find(R"({"type": "quad", "size": [4, 4]})"), 32, R"({"type": "mesh", "file": "out.png"})");
  test::writeFile(dir + "/m.json", scene);
  auto r3 = runTdpm("render '" + dir + "/m.json' -q -o '" + dir + "/out.exr'");
  CHECK(r3.exitCode == 1);
  CHECK_MESSAGE(contains(r3.output, "is the mesh file of object"), r3.output);
  CHECK(readAll(dir + "/out.png") == obj);
  CHECK_FALSE(test::fileExists(dir + "/out.exr"));
}

TEST_CASE("output safety: a symbolic link is written through, keeping its target's mode") {
  const std::string dir = test::makeTempDir();
  REQUIRE(::mkdir((dir + "/store").c_str(), 0755) == 0);
  const std::string target = dir + "/store/real.txt";
  test::writeFile(target, "old");
  REQUIRE(::chmod(target.c_str(), 0640) == 0);
  REQUIRE(::symlink("store/real.txt", (dir + "/link.txt").c_str()) == 0);
  writeTextFileAtomic(dir + "/link.txt", "new");
  CHECK(isSymlink(dir + "/link.txt"));
  CHECK(readAll(target) == "new");
  CHECK(modeOf(target) == 0640);
  CHECK(temporariesIn(dir).empty());
  CHECK(temporariesIn(dir + "/store").empty());

  // A plain file keeps its mode too.
  REQUIRE(::chmod(target.c_str(), 0600) == 0);
  writeTextFileAtomic(target, "newer");
  CHECK(modeOf(target) == 0600);
  // A read-only one too (its mode is applied at commit, after the writer).
  REQUIRE(::chmod(target.c_str(), 0444) == 0);
  writeTextFileAtomic(target, "newest");
  CHECK(readAll(target) == "newest");
  CHECK(modeOf(target) == 0444);

  // A dangling link is refused, naming where it points.
  REQUIRE(::symlink("nowhere/x.txt", (dir + "/dangling.txt").c_str()) == 0);
  try {
    writeTextFileAtomic(dir + "/dangling.txt", "x");
    FAIL("a dangling link was accepted");
  } catch (const Error& e) {
    CHECK(contains(e.what(), "is a symbolic link to 'nowhere/x.txt'"));
  }
  // So is anything that is not a regular file.
  REQUIRE(::mkfifo((dir + "/fifo.txt").c_str(), 0644) == 0);
  CHECK_THROWS_WITH_AS(checkOutputPath(dir + "/fifo.txt"), doctest::Contains("not a regular file"), Error);
}

TEST_CASE("output safety: render writes through a symlinked output pair") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", kScene);
  REQUIRE(::mkdir((dir + "/keep").c_str(), 0755) == 0);
  test::writeFile(dir + "/keep/a.exr", "old");
  REQUIRE(::chmod((dir + "/keep/a.exr").c_str(), 0604) == 0);
  REQUIRE(::symlink("keep/a.exr", (dir + "/r.exr").c_str()) == 0);
  auto r = runTdpm("render '" + dir + "/s.json' -q -o '" + dir + "/r.exr'");
  REQUIRE_MESSAGE(r.exitCode == 0, r.output);
  CHECK(isSymlink(dir + "/r.exr"));
  CHECK(modeOf(dir + "/keep/a.exr") == 0604);
  CHECK(image::readExr(dir + "/keep/a.exr").color.width == 32);
  CHECK(test::fileExists(dir + "/r.png"));
}

// ---- item 14: signals ----

// In a child: a registered temporary, then SIGTERM: the temporary is gone
// and the child died by SIGTERM.
TEST_CASE("output safety: a signal removes registered temporaries and ends the process by that signal") {
  for (int signo : {SIGTERM, SIGHUP, SIGINT, SIGUSR1}) {
    CAPTURE(signo);
    const std::string dir = test::makeTempDir();
    int pipeFd[2];
    REQUIRE(::pipe(pipeFd) == 0);
    pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      quietChild();
      ::close(pipeFd[0]);
      signals::install(signals::Mode::Exit);
      AtomicFile f(dir + "/x.exr");
      test::writeFile(f.tempPath(), "partial");
      char ok = 1;
      if (::write(pipeFd[1], &ok, 1) != 1) ::_exit(10);
      ::raise(signo);
      ::_exit(11);  // not reached
    }
    ::close(pipeFd[1]);
    char ok = 0;
    CHECK(::read(pipeFd[0], &ok, 1) == 1);
    ::close(pipeFd[0]);
    int status = 0;
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == signo);
    CHECK(temporariesIn(dir).empty());
    CHECK_FALSE(test::fileExists(dir + "/x.exr"));
  }
}

TEST_CASE("output safety: in stop mode the first signal only asks to stop, the second ends the process") {
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    quietChild();
    signals::install(signals::Mode::Stop);
    if (signals::stopRequested() != 0) ::_exit(20);
    ::raise(SIGINT);
    if (signals::stopRequested() != SIGINT) ::_exit(21);
    ::raise(SIGINT);
    ::_exit(22);  // not reached
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGINT);
}

TEST_CASE("output safety: a deferred signal acts when the deferral ends") {
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    quietChild();
    signals::install(signals::Mode::Exit);
    {
      signals::Deferral d;
      ::raise(SIGTERM);
      // Still alive here: the renames of a pair are never cut in half.
      if (::write(STDOUT_FILENO, "", 0) != 0) ::_exit(30);
    }
    ::_exit(31);  // not reached: the pending SIGTERM ends the process
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);
}

// SIGINT to a `tdpm render` child at several moments: whenever it lands,
// no temporary remains, and either the run finished with a complete pair
// or it died by SIGINT saying so and the old pair is intact.
TEST_CASE("output safety: SIGINT during `tdpm render` leaves no temporary and never a broken pair") {
  OldPair old;
  int interrupted = 0;
  for (int delayMs : {100, 400, 700, 1000}) {
    const std::string log = old.dir + "/log.txt";
    pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, STDERR_FILENO);
      ::dup2(fd, STDOUT_FILENO);
      ::execl(TDPM_BINARY, TDPM_BINARY, "render", old.scene.c_str(), "-q", "-t", "1", "--resolution", "480x360",
              "--seed", "3", "-o", old.exr.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    waitUntilCatching(pid, SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(delayMs));
    ::kill(pid, SIGINT);
    int status = 0;
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    CHECK(temporariesIn(old.dir).empty());
    if (WIFSIGNALED(status)) {
      ++interrupted;
      CHECK(WTERMSIG(status) == SIGINT);
      CHECK(contains(readAll(log), "tdpm: interrupted by SIGINT (temporary files removed)"));
      if (old.intact()) continue;
      // The signal came during the final renames, which it waits for
      // (commitTogether's Deferral): the new pair is whole, then tdpm dies
      // by the signal. Either way never one old and one new file.
      CHECK(readAll(old.exr) != old.oldExr);  // both files new, not one of each
      CHECK(readAll(old.png) != old.oldPng);
      image::ExrFile e = image::readExr(old.exr);
      CHECK(e.metadata.at("tdpm/seed") == "3");
      CHECK(image::readPng(old.png).width == 480);
      break;
    } else {
      CHECK(WEXITSTATUS(status) == 0);
      image::ExrFile e = image::readExr(old.exr);
      CHECK(e.metadata.at("tdpm/seed") == "3");
      CHECK(image::readPng(old.png).width == 480);
      break;  // the pair was replaced: later runs would compare against it
    }
  }
  CHECK(interrupted >= 1);
}

// SIGINT as soon as a temporary with content appears, i.e. while the pair
// is being written: no temporary remains, and the pair is either the old
// one (the process died by SIGINT) or the new one (it had finished).
TEST_CASE("output safety: SIGINT while the pair is written leaves the old pair or the new one, no temporary") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/e.json", R"({"camera": {"position": [0, 0, 4], "target": [0, 0, 0]},
    "materials": {}, "objects": [], "lights": [], "background": 0.25, "render": {"method": "pathtrace", "spp": 1}})");
  const std::string exr = dir + "/r.exr", png = dir + "/r.png";
  const std::string common = "render '" + dir + "/e.json' -q -t 1 --resolution 1200x900 -o '" + exr + "'";
  REQUIRE(runTdpm(common + " --seed 1").exitCode == 0);
  const std::string oldExr = readAll(exr), oldPng = readAll(png);

  const std::string log = dir + "/log.txt";
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDERR_FILENO);
    ::execl(TDPM_BINARY, TDPM_BINARY, "render", (dir + "/e.json").c_str(), "-q", "-t", "1", "--resolution", "1200x900",
            "--seed", "2", "--exposure", "1", "-o", exr.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool sawTemporary = false;
  for (int i = 0; i < 20000 && !sawTemporary; ++i) {  // at most ~20 s
    for (const std::string& name : temporariesIn(dir)) {
      struct stat st;
      if (::stat((dir + "/" + name).c_str(), &st) == 0 && st.st_size > 0) sawTemporary = true;
    }
    if (!sawTemporary) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ::kill(pid, SIGINT);
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  CHECK(sawTemporary);
  CHECK(temporariesIn(dir).empty());
  if (WIFSIGNALED(status)) {
    MESSAGE("interrupted while writing");
    CHECK(WTERMSIG(status) == SIGINT);
    CHECK(readAll(exr) == oldExr);
    CHECK(readAll(png) == oldPng);
  } else {
    MESSAGE("the write finished before the signal");
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(image::readExr(exr).metadata.at("tdpm/seed") == "2");
    CHECK(readAll(png) != oldPng);
  }
}

// ---- item 10: memory pre-flight ----

TEST_CASE("output safety: the memory estimate counts films, write buffers and photons per pixel") {
  auto desc = test::emptyScene(1000, 500);
  auto scene = Scene::build(desc);
  RenderOptions opt;
  opt.method = RenderMethod::PathTrace;
  opt.spp = 4;
  MemoryEstimate e = estimateRenderMemory(*scene, opt, 2);
  CHECK(e.pixels == 500000);
  CHECK(e.films == 500000 * 28);
  CHECK(e.sampler == 500000 * 61);
  CHECK(e.write == 500000 * 40);
  CHECK(e.samples == 2 * 4 * 24);
  CHECK(e.photons == 0);
  CHECK(e.peak() == 500000 * (28 + 61) + 2 * 4 * 24);  // rendering (film + adaptive state) exceeds writing

  // A budget that the image alone exceeds names the resolution's source.
  opt.resolutionSource = "--resolution 1000x500";
  CHECK_NOTHROW(checkMemoryBudget(*scene, opt, 2, 0));  // unknown: no check
  const uint64_t avail = (uint64_t(256) << 20) + (uint64_t(10) << 20);
  try {
    checkMemoryBudget(*scene, opt, 2, avail);
    FAIL("a 44 MB image fit in 10 MB");
  } catch (const Error& e2) {
    std::string m = e2.what();
    CHECK(contains(m, "--resolution 1000x500 (1000x500 = 500000 pixels) needs about 44500192 bytes"));
    CHECK(contains(m, "lower the resolution"));
  }
  CHECK_NOTHROW(checkMemoryBudget(*scene, opt, 2, uint64_t(1) << 30));
}

TEST_CASE("output safety: an image too large for memory is refused up front, naming the flag or the scene key") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", kScene);
  const uint64_t needed = uint64_t(65536) * 65536 * kWriteBytesPerPixel;  // 160 GiB
  const uint64_t avail = availableMemoryBytes();
  if (avail == 0 || avail > needed) {
    MESSAGE("this machine has room for a 65536x65536 image: check skipped");
    return;
  }
  auto r = runTdpm("render '" + dir + "/s.json' -q --resolution 65536x65536 -o '" + dir + "/o.exr'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "--resolution 65536x65536 (65536x65536 = 4294967296 pixels) needs about "));
  CHECK(contains(r.output, "of memory is available"));

  std::string scene = kScene;
  scene.replace(scene.find("[32, 24]"), 8, "[65536, 65536]");
  test::writeFile(dir + "/big.json", scene);
  auto r2 = runTdpm("render '" + dir + "/big.json' -q -o '" + dir + "/o.exr'");
  CHECK(r2.exitCode == 1);
  CHECK(contains(r2.output, "camera.resolution in " + dir + "/big.json (65536x65536"));
  CHECK_FALSE(test::fileExists(dir + "/o.exr"));
}

// The per-pixel constants are what the process really holds: the peak RSS
// of two path-traced renders of an empty scene differs by the larger of the
// rendering phase (film + the adaptive loop's state) and the writing phase
// (film + split variance) per extra pixel.
TEST_CASE("output safety: measured peak memory per pixel matches the per-pixel constants") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/e.json", R"({"camera": {"position": [0, 0, 4], "target": [0, 0, 0]},
    "materials": {}, "objects": [], "lights": [], "background": 0.5, "render": {"method": "pathtrace", "spp": 1}})");
  auto peakFor = [&](const char* res) -> double {
    auto r = runTdpm("render '" + dir + "/e.json' -q --stats -t 1 --resolution " + std::string(res) + " -o '" + dir +
                     "/o.exr'");
    REQUIRE_MESSAGE(r.exitCode == 0, r.output);
    size_t at = r.output.find("peak resident memory: ");
    REQUIRE(at != std::string::npos);
    return std::stod(r.output.substr(at + 22));
  };
  const double small = peakFor("200x200"), large = peakFor("1600x1200");
  const double perPixel = (large - small) / (1600.0 * 1200.0 - 200.0 * 200.0);
  MESSAGE("measured bytes per pixel: " << perPixel);
  const double model = double(std::max(kFilmBytesPerPixel + kSamplerBytesPerPixel, kWriteBytesPerPixel));
  CHECK(perPixel >= double(kFilmBytesPerPixel));
  CHECK(perPixel <= model * 1.1);
}

// ---- smaller: accumulation says when frames raise the budget ----

TEST_CASE("output safety: accumulation warns when its frames raise the samples or photons") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", kScene);
  auto r = runTdpm("render '" + dir + "/s.json' -m accumulation --frames 8 --spp 2 --photons 0 --global-photons 0 "
                   "--resolution 8x6 -q -o '" + dir + "/o.exr'");
  CHECK_MESSAGE(r.exitCode == 0, r.output);
  CHECK(contains(r.output, "accumulation: 8 frames of 1 samples per pixel each take 8 samples per pixel in all, not "
                           "the 2 asked for"));
  auto r2 = runTdpm("render '" + dir + "/s.json' -m accumulation --frames 32 --spp 32 --photons 0 --global-photons 320 "
                    "--resolution 8x6 -q -o '" + dir + "/o.exr'");
  CHECK_MESSAGE(r2.exitCode == 0, r2.output);
  CHECK_FALSE(contains(r2.output, "samples per pixel in all"));
  CHECK(contains(r2.output, "global photons stored, not the 320 asked for"));
  // Exactly divisible and plenty of photons per frame: no warning.
  auto r3 = runTdpm("render '" + dir + "/s.json' -m accumulation --frames 2 --spp 4 --photons 0 --global-photons 20000 "
                    "--resolution 8x6 -q -o '" + dir + "/o.exr'");
  CHECK(r3.exitCode == 0);
  CHECK_FALSE(contains(r3.output, "warning"));
  auto h = runTdpm("render --help");
  CHECK(contains(h.output, "raise the totals"));
}
