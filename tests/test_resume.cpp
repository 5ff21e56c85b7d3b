// tests/test_resume.cpp — cli/resume: `--resume` accepts the state of the
// same render and refuses, with a message naming the file and the problem,
// every other file: missing, not readable, not an EXR, not progressive,
// another resolution, another scene or other settings; and needs
// --progressive (exit 1, nothing written).
#include <doctest/doctest.h>

#include <algorithm>

#include <cstring>
#include <string>

#include "cli/resume.h"
#include "cli_harness.h"
#include "core/error.h"
#include "image/exr.h"
#include "render/fingerprint.h"
#include "render/progressive_io.h"
#include "scene/parse.h"

using namespace tdpm;

namespace {

struct Setup {
  std::string dir = test::makeTempDir();
  scene::SceneDescription scene = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/glass-ball.json");
  RenderOptions options;
  Setup() {
    scene.camera.width = 8;
    scene.camera.height = 6;
    options.resolutionSource = "camera.resolution in glass-ball.json";
  }
  ~Setup() { std::system(("rm -rf '" + dir + "'").c_str()); }

  // The state a progressive render of `s` with `o` would have written.
  ProgressiveState stateFor(const scene::SceneDescription& s, const RenderOptions& o) const {
    RenderFingerprint f = fingerprintOf(s, o);
    ProgressiveState st;
    st.fingerprint = f.value;
    st.settings = f.settings;
    fill(st, o, size_t(s.camera.width) * size_t(s.camera.height), 4);
    return st;
  }
  // Every scalar and layer of `passes` passes, consistent with each other
  // and with `o` (what render/progressive_check.h accepts).
  static void fill(ProgressiveState& st, const RenderOptions& o, size_t n, int passes) {
    st.passesDone = passes;
    const double p = passes;
    st.pilot.done = true;
    st.pilot.maps[MapKind::Caustic].pathsPerPass = 10 * 1024;
    st.pilot.maps[MapKind::Global].pathsPerPass = 2 * 1024;
    for (MapKind k : kAllMapKinds) {
      if (mapKindInfo(k).onlyWhenAsked) continue;  // the volume map is not in progressive states
      ProgressiveMapPilot& m = st.pilot.maps[k];
      m.radius = m.halfWindow = m.spatialRadius = 0.125;
    }
    st.totals.photonsEmitted = p * 12 * 1024;
    st.totals.photonsStored = p * 3000;
    st.totals.seconds = 1.5;
    st.totals.kernelRadius = st.totals.kernelSpatialRadius = st.totals.kernelHalfWindow = 0.0625;
    for (const char* name : {"sum.R", "sum.G", "sum.B"}) st.layers[name] = std::vector<float>(n, 0.25f * float(p));
    for (const char* name : {"sumsq.R", "sumsq.G", "sumsq.B"})
      st.layers[name] = std::vector<float>(n, 0.0625f * float(p));
    st.layers["spp"] = std::vector<float>(n, float(p * o.spp));
  }

  std::string write(const std::string& name, const ProgressiveState* st, int w, int h) const {
    image::ExrFile exr;
    exr.color = image::ImageRgb(w, h, Rgb(0.5f));
    if (st) addProgressiveState(*st, exr);
    std::string path = dir + "/" + name;
    image::writeExr(path, exr);
    return path;
  }

  std::string errorOf(const std::string& path) const {
    try {
      cli::loadResumeState(path, scene, options);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
};

}  // namespace

TEST_CASE("resume: the state of the same render is accepted, exactly") {
  Setup s;
  const ProgressiveState st = s.stateFor(s.scene, s.options);
  const std::string path = s.write("old.exr", &st, 8, 6);
  ProgressiveState back = cli::loadResumeState(path, s.scene, s.options);
  CHECK(back.passesDone == 4);
  CHECK(back.fingerprint == st.fingerprint);
  CHECK(back.settings == st.settings);
  CHECK(back.pilot == st.pilot);
  CHECK(back.totals.photonsEmitted == st.totals.photonsEmitted);
  CHECK(back.totals.seconds == st.totals.seconds);
  CHECK(back.totals.kernelHalfWindow == st.totals.kernelHalfWindow);
  CHECK(back.layers == st.layers);
}

TEST_CASE("resume: files that are not a progressive render's") {
  Setup s;
  const std::string missing = s.dir + "/missing.exr";
  CHECK(s.errorOf(missing) == "--resume " + missing + ": No such file or directory");
  // A directory (running as root, permissions cannot make a file unreadable).
  CHECK(s.errorOf(s.dir) == "--resume " + s.dir + ": is a directory, not an OpenEXR file");
  const std::string text = s.dir + "/notes.exr";
  test::writeFile(text, "not an image\n");
  CHECK(s.errorOf(text) == "--resume " + text + ": not an OpenEXR file (bad magic number)");
  const std::string plain = s.write("plain.exr", nullptr, 8, 6);
  CHECK(s.errorOf(plain) == "--resume " + plain +
                                ": was not written by a progressive render (it has no tdpm/progressive/* attributes), so "
                                "there is nothing to continue");
  // A damaged state says so, naming what is wrong.
  ProgressiveState st = s.stateFor(s.scene, s.options);
  image::ExrFile exr;
  exr.color = image::ImageRgb(8, 6);
  addProgressiveState(st, exr);
  exr.metadata["tdpm/progressive/passes"] = "four";
  const std::string damaged = s.dir + "/damaged.exr";
  image::writeExr(damaged, exr);
  std::string msg = s.errorOf(damaged);
  CHECK(msg.rfind("damaged progressive state: " + damaged + ": tdpm/progressive/passes is 'four'", 0) == 0);
}

TEST_CASE("resume: another resolution") {
  Setup s;
  scene::SceneDescription bigger = s.scene;
  bigger.camera.width = 16;
  const ProgressiveState st = s.stateFor(bigger, s.options);
  const std::string path = s.write("big.exr", &st, 16, 6);
  CHECK(s.errorOf(path) ==
        "--resume " + path + ": its image is 16x6, this render's is 8x6 (camera.resolution in glass-ball.json)");
}

TEST_CASE("resume: another scene or other settings, each named") {
  Setup s;
  RenderOptions more = s.options;
  more.causticPhotons = 100000;
  more.seed = 9;
  ProgressiveState st = s.stateFor(s.scene, more);
  std::string path = s.write("old.exr", &st, 8, 6);
  CHECK(s.errorOf(path) == "--resume " + path + ": it is another render, so it cannot be continued: photons: 100000 in " +
                               path + ", 200000 now; seed: 9 in " + path + ", 1 now");

  scene::SceneDescription other = s.scene;
  other.lights[0].power = other.lights[0].power * 2.0f;
  st = s.stateFor(other, s.options);
  path = s.write("other-scene.exr", &st, 8, 6);
  CHECK(s.errorOf(path) == "--resume " + path + ": it is another render, so it cannot be continued: the scene differs");

  // Settings that match but a fingerprint that does not: said as such.
  st = s.stateFor(s.scene, s.options);
  st.fingerprint = "00000000000000000000000000000000";
  path = s.write("edited.exr", &st, 8, 6);
  CHECK(s.errorOf(path).find("its fingerprint 00000000000000000000000000000000 is not this render's") !=
        std::string::npos);
}

TEST_CASE("resume: the command line (needs --progressive, exit 1, nothing written, documented)") {
  Setup s;
  const ProgressiveState st = s.stateFor(s.scene, s.options);
  const std::string old = s.write("old.exr", &st, 8, 6);
  const std::string out = s.dir + "/out";
  test::CommandResult r = test::runTdpm("render '" + std::string(TDPM_SOURCE_DIR) + "/scenes/glass-ball.json' --resume '" +
                                        old + "' -o '" + out + ".exr' --resolution 8x6 --spp 1 -q --fixed-budget");
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("tdpm: error: --resume " + old + " needs --progressive") != std::string::npos);
  CHECK(!test::fileExists(out + ".exr"));
  CHECK(!test::fileExists(out + ".png"));
  CHECK(test::countEntries(s.dir) == 1);  // old.exr alone

  test::CommandResult help = test::runTdpm("render --help");
  CHECK(help.exitCode == 0);
  CHECK(help.output.find("--resume") != std::string::npos);
  CHECK(help.output.find("replaced atomically") != std::string::npos);
}

TEST_CASE("resume: a fresh progressive render starts at pass 0 with its fingerprint") {
  Setup s;
  ProgressiveState fresh = cli::initialProgressiveState(nullptr, s.scene, s.options);
  CHECK(fresh.empty());
  CHECK(fresh.fingerprint == fingerprintOf(s.scene, s.options).value);
  CHECK(fresh.settings.at("photons") == "200000");
  CHECK(fresh.layers.empty());
  // Written after some passes, it is what a resumed run of the same render accepts.
  Setup::fill(fresh, s.options, 48, 2);
  const std::string path = s.write("run1.exr", &fresh, 8, 6);
  const std::string resume = path;
  ProgressiveState next = cli::initialProgressiveState(&resume, s.scene, s.options);
  CHECK(next.passesDone == 2);
  CHECK(next.fingerprint == fresh.fingerprint);
}

TEST_CASE("resume: N passes, then N more resumed from the EXR, equal 2N passes in one run, bit for bit") {
  std::string dir = test::makeTempDir();
  const std::string base = "render '" + std::string(TDPM_SOURCE_DIR) +
                           "/scenes/cube-caustic.json' -m time --progressive --resolution 40x30 --spp 1 "
                           "--photons 4000 --global-photons 1500 -q --seed 5 ";
  test::CommandResult full = test::runTdpm(base + "-t 2 --passes 4 -o " + dir + "/full.exr");
  REQUIRE_MESSAGE(full.exitCode == 0, full.output);
  test::CommandResult half = test::runTdpm(base + "-t 1 --passes 2 -o " + dir + "/part.exr");
  REQUIRE_MESSAGE(half.exitCode == 0, half.output);
  image::ExrFile two = image::readExr(dir + "/part.exr");
  // The output may be the file resumed: it is replaced atomically.
  test::CommandResult more = test::runTdpm(base + "-t 2 --passes 4 --resume " + dir + "/part.exr -o " + dir + "/part.exr");
  REQUIRE_MESSAGE(more.exitCode == 0, more.output);
  image::ExrFile a = image::readExr(dir + "/full.exr"), b = image::readExr(dir + "/part.exr");
  REQUIRE(a.color.pixels.size() == b.color.pixels.size());
  CHECK(std::memcmp(a.color.pixels.data(), b.color.pixels.data(), a.color.pixels.size() * sizeof(Rgb)) == 0);
  CHECK(a.metadata["tdpm/progressive/passes"] == "4");
  CHECK(b.metadata["tdpm/progressive/passes"] == "4");
  // ... and the comparison can fail: 2 passes are another image.
  CHECK(std::memcmp(a.color.pixels.data(), two.color.pixels.data(), a.color.pixels.size() * sizeof(Rgb)) != 0);
  // The default per-pixel eye sample counts (render/sample_allocation.h) are
  // recomputed on resume: the spp layers agree too, and vary by pixel.
  const image::Channel *sa = a.findChannel("spp"), *sb = b.findChannel("spp");
  REQUIRE((sa && sb));
  CHECK(sa->values == sb->values);
  CHECK(*std::max_element(sa->values.begin(), sa->values.end()) > 4.0f);
  // Resuming without them is another render, named as such.
  test::CommandResult off = test::runTdpm(base + "--extra-samples 0 --passes 6 --resume " + dir + "/full.exr -o " + dir +
                                          "/off.exr");
  CHECK(off.exitCode == 1);
  CHECK(off.output.find("extra_samples: 0.5 (cap 32) in") != std::string::npos);
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("resume: a long state's spp layer is checked against the float sums the pass loop forms") {
  // 2^20 passes of 17 samples: 17.8M per pixel, beyond 2^24, where the
  // float layer rounds as it grows. A legitimate state holds the loop's own
  // float sum, not passes x spp; an edited pass count is still refused.
  Setup s;
  s.options.spp = 17;
  ProgressiveState st = s.stateFor(s.scene, s.options);
  const int passes = 1 << 20;
  Setup::fill(st, s.options, 48, passes);
  float sum = 0;
  for (int i = 0; i < passes; ++i) sum += 17.0f;
  st.layers["spp"] = std::vector<float>(48, sum);
  std::string path = s.write("long.exr", &st, 8, 6);
  CHECK(s.errorOf(path).empty());
  st.passesDone = passes / 2;
  st.totals.photonsEmitted = double(passes / 2) * 12 * 1024;
  path = s.write("halved.exr", &st, 8, 6);
  CHECK(s.errorOf(path).find("damaged progressive state: " + path + ": layer progressive.spp is ") == 0);
}
