// tests/test_progressive_cli.cpp — `tdpm render --progressive` as a user
// meets it (build/tdpm as a child process): the pass count and metadata,
// clear errors for flags that need --progressive or a method without a
// progressive variant, flat peak memory from 10 to 100 passes, and SIGINT:
// the first stops after the current pass and writes the passes done (exit
// 0, a note on stderr), a second aborts at once with nothing written.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "cli_harness.h"
#include "image/exr.h"

using namespace tdpm;
using test::runTdpm;

namespace {

// A glass ball over a floor; a box moving under it; a point light.
const char* kScene = R"({
  "camera": {"position": [0, 1.5, 3], "target": [0, 0.3, 0], "fov": 40, "resolution": [RES], "shutter": [0, 1]},
  "materials": {"white": {"type": "diffuse", "color": 0.7}, "glass": {"type": "dielectric", "ior": 1.5}},
  "objects": [
    {"shape": {"type": "quad", "size": [4, 4]}, "material": "white"},
    {"shape": {"type": "sphere", "radius": 0.3}, "material": "glass", "transform": {"translate": [0, 1.0, 0]}},
    {"shape": {"type": "box", "size": [0.4, 0.4, 0.4]}, "material": "white",
     "transform": {"translate": [0, 0.2, 0]},
     "motion": [{"time": 0, "translate": [-0.5, 0, 0]}, {"time": 1, "translate": [0.5, 0, 0]}]}],
  "lights": [{"type": "point", "position": [0, 2.5, 0], "power": 100}],
  "render": {"method": "time", "spp": 1, "photons": PHOTONS, "global_photons": GLOBAL, "k": 20 EXTRA}
})";

std::string writeScene(const std::string& dir, const std::string& name, const std::string& res, int photons,
                       int global, const std::string& extra = "") {
  std::string s = kScene;
  auto put = [&](const std::string& key, const std::string& v) { s.replace(s.find(key), key.size(), v); };
  put("RES", res);
  put("PHOTONS", std::to_string(photons));
  put("GLOBAL", std::to_string(global));
  put(" EXTRA", extra);
  std::string path = dir + "/" + name;
  test::writeFile(path, s);
  return path;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

uint64_t peakRss(const std::string& output) {
  const std::string key = "peak resident memory: ";
  size_t at = output.find(key);
  return at == std::string::npos ? 0 : std::strtoull(output.c_str() + at + key.size(), nullptr, 10);
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Starts build/tdpm with `args` (stdout and stderr to `log`); returns its pid.
pid_t spawnTdpm(const std::string& args, const std::string& log) {
  pid_t pid = fork();
  if (pid == 0) {
    std::string cmd = std::string("exec '") + TDPM_BINARY + "' " + args + " > '" + log + "' 2>&1 < /dev/null";
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Waits until `log` contains `marker` (or the child ended). A guard against
// a hang, not a timed assertion: the limit is far above any normal run.
bool waitForMarker(pid_t pid, const std::string& log, const std::string& marker) {
  for (int i = 0; i < 6000; ++i) {
    if (contains(readText(log), marker)) return true;
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace

TEST_CASE("progressive cli: --passes N renders N passes and records them in the EXR") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "s.json", "16, 12", 2000, 1000);
  auto r = runTdpm("render '" + scene + "' --progressive --passes 3 -t 2 -o '" + dir + "/o.exr'");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(contains(r.output, "tdpm: pass 3 of 3 done"));
  CHECK(contains(r.output, "tdpm: progressive: 3 passes"));
  image::ExrFile exr = image::readExr(dir + "/o.exr");
  CHECK(exr.metadata["tdpm/progressive"] == "1");
  CHECK(exr.metadata["tdpm/passes"] == "3");
  CHECK(std::atof(exr.metadata["tdpm/kernel_radius"].c_str()) > 0.0);
  CHECK(std::atof(exr.metadata["tdpm/kernel_half_window"].c_str()) > 0.0);
  CHECK(std::atof(exr.metadata["tdpm/photons_emitted"].c_str()) > 0.0);
  // A time limit stops after the pass that reaches it: a microsecond is
  // reached by the first pass, whatever the machine.
  auto t = runTdpm("render '" + scene + "' --progressive --time-limit 0.000001 -t 2 -o '" + dir + "/t.exr'");
  INFO(t.output);
  REQUIRE(t.exitCode == 0);
  CHECK(image::readExr(dir + "/t.exr").metadata["tdpm/passes"] == "1");
  // The scene keys do the same.
  std::string keyed = writeScene(dir, "k.json", "16, 12", 2000, 1000, ", \"progressive\": true, \"passes\": 2");
  auto k = runTdpm("render '" + keyed + "' -t 2 -q -o '" + dir + "/k.exr'");
  REQUIRE(k.exitCode == 0);
  CHECK(image::readExr(dir + "/k.exr").metadata["tdpm/passes"] == "2");
}

TEST_CASE("progressive cli: flags that need --progressive, and methods without a progressive variant, are errors") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "s.json", "16, 12", 2000, 1000);
  std::string out = " -o '" + dir + "/o.exr'";
  // A method chosen with -m (or --fixed-budget) keeps one budget: pass flags are errors.
  for (const char* flag : {"--passes 3", "--time-limit 1", "--alpha 0.5", "--fixed-budget --passes 3",
                           "--extra-samples 0.2", "--extra-cap 4"}) {
    auto r = runTdpm("render '" + scene + "' -m time " + flag + out);
    CAPTURE(r.output);
    CHECK(r.exitCode == 1);
    std::string f = std::string(flag);
    if (f.rfind("--fixed-budget ", 0) == 0) f = f.substr(15);
    std::string name = f.substr(0, f.find(' '));
    CHECK(contains(r.output, name + " needs --progressive"));
  }
  for (const char* method : {"pathtrace", "static"}) {
    auto r = runTdpm("render '" + scene + "' --progressive -m " + method + out);
    CAPTURE(r.output);
    CHECK(r.exitCode == 1);
    CHECK(contains(r.output, "--progressive works with the methods time, accumulation and standard"));
  }
  for (const char* flag : {"--max-spp 8", "--frames 4", "--search 4d", "--kernel-space cone", "--kappa 2"}) {
    auto r = runTdpm("render '" + scene + "' --progressive " + flag + out);
    CAPTURE(r.output);
    CHECK(r.exitCode == 1);
    CHECK(contains(r.output, std::string(flag).substr(0, std::string(flag).find(' '))));
    CHECK(contains(r.output, "has no effect with --progressive"));
    if (std::string(flag) == "--max-spp 8") CHECK(contains(r.output, "--extra-samples"));
  }
  // Not a number is out of every range (CLI::Range let NaN through).
  for (const char* flag : {"--progressive --alpha nan", "--progressive --time-limit nan", "--kernel-footprint nan",
                           "--progressive --extra-samples nan", "--progressive --extra-samples -1"}) {
    auto r = runTdpm("render '" + scene + "' " + flag + out);
    CAPTURE(r.output);
    CHECK(r.exitCode == 2);
    CHECK((contains(r.output, "Value nan not in range") || contains(r.output, "Value -1 not in range")));
  }
  auto help = runTdpm("render --help");
  for (const char* flag : {"--progressive", "--fixed-budget", "--passes", "--time-limit", "--alpha", "--extra-samples",
                           "--extra-cap"})
    CHECK(contains(help.output, flag));
  std::string keyed = writeScene(dir, "k.json", "16, 12", 2000, 1000, ", \"passes\": 2");
  auto k = runTdpm("render '" + keyed + "' -m time" + out);
  CHECK(k.exitCode == 1);
  CHECK(contains(k.output, "render.passes in"));
  CHECK(test::countEntries(dir) == 2);  // the two scenes: no output written
}

TEST_CASE("progressive cli: peak memory after 100 passes is that after 10") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "s.json", "8, 6", 3000, 1000);
  auto run = [&](int passes) {
    auto r = runTdpm("render '" + scene + "' --progressive --passes " + std::to_string(passes) +
                     " -t 2 -q --stats -o '" + dir + "/o.exr'");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    return peakRss(r.output);
  };
  uint64_t ten = run(10), hundred = run(100);
  MESSAGE("peak RSS: 10 passes " << ten << " bytes, 100 passes " << hundred << " bytes");
  REQUIRE(ten > 0);
  // One pass's maps are ~100 kB here: 10x the passes must not add them up.
  CHECK(double(hundred) <= double(ten) * 1.03 + 1e6);
}

TEST_CASE("progressive cli: SIGINT stops after the current pass and writes the passes done; a second aborts") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "s.json", "32, 24", 60000, 20000);
  SUBCASE("one signal") {
    std::string log = dir + "/log1";
    pid_t pid = spawnTdpm("render '" + scene + "' --progressive --passes 100000 -t 2 -o '" + dir + "/o.exr'", log);
    REQUIRE(waitForMarker(pid, log, "tdpm: pass 1 of 100000 done"));
    kill(pid, SIGINT);
    int status = 0;
    waitpid(pid, &status, 0);
    std::string out = readText(log);
    INFO(out);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(contains(out, "tdpm: stopped by SIGINT after pass"));
    image::ExrFile exr = image::readExr(dir + "/o.exr");
    int passes = std::atoi(exr.metadata["tdpm/passes"].c_str());
    CHECK(passes >= 1);
    CHECK(passes < 100000);
    CHECK(test::fileExists(dir + "/o.png"));
  }
  SUBCASE("two signals") {
    std::string log = dir + "/log2";
    pid_t pid = spawnTdpm("render '" + scene + "' --progressive --passes 100000 -t 2 -o '" + dir + "/p.exr'", log);
    REQUIRE(waitForMarker(pid, log, "tdpm: pass 1 of 100000 done"));
    // Two different signals: two of one kind sent at once may merge into one.
    kill(pid, SIGINT);
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    INFO(readText(log));
    CHECK(WIFSIGNALED(status));
    CHECK(!test::fileExists(dir + "/p.exr"));
    CHECK(!test::fileExists(dir + "/p.png"));
  }
}

TEST_CASE("progressive cli: a scene rendered with its own photon method renders in passes by default") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "s.json", "16, 12", 2000, 1000);
  // Its own method (render.method time), nobody said otherwise: passes (here 2, not the 30 s limit).
  auto p = runTdpm("render '" + scene + "' --passes 2 -t 2 -q -o '" + dir + "/p.exr'");
  REQUIRE_MESSAGE(p.exitCode == 0, p.output);
  CHECK(image::readExr(dir + "/p.exr").metadata["tdpm/passes"] == "2");
  // --fixed-budget, or a method chosen with -m: one budget, no passes.
  for (const char* flag : {"--fixed-budget", "-m time", "-m accumulation"}) {
    auto f = runTdpm("render '" + scene + "' " + flag + " -t 2 -q -o '" + dir + "/f.exr'");
    REQUIRE_MESSAGE(f.exitCode == 0, f.output);
    CHECK(image::readExr(dir + "/f.exr").metadata.count("tdpm/passes") == 0);
  }
  // render.progressive false in the scene: one budget too.
  std::string fixedScene = writeScene(dir, "f.json", "16, 12", 2000, 1000, ", \"progressive\": false");
  auto g = runTdpm("render '" + fixedScene + "' -t 2 -q -o '" + dir + "/g.exr'");
  REQUIRE_MESSAGE(g.exitCode == 0, g.output);
  CHECK(image::readExr(dir + "/g.exr").metadata.count("tdpm/passes") == 0);
  std::system(("rm -rf '" + dir + "'").c_str());
}
