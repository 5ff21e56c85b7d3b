// tests/test_animation.cpp — animations (issue 12): the "animation" block
// and its errors, frame shutters and keyframe clocks, the time grid, frames
// of a sequence against the analytic moving plane and against the same
// frame rendered alone, bit-identical frames whatever the range, window or
// threads, and the command line: patterns, ranges, --video, nothing
// written on bad input, and bounded memory with --window.
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "cli/frame_pattern.h"
#include "cli_harness.h"
#include "core/error.h"
#include "render/animation.h"
#include "render/renderer.h"
#include "scene/parse.h"
#include "scene/parse_animation.h"
#include "scene/scene.h"
#include "moving_plane.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

std::string errorOf(const std::string& json) {
  try {
    scene::parseScene(json, "anim.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A sphere moving from x = -1 (t = 0) to x = 1 (t = T), T = frames / fps.
std::string animatedJson(const std::string& animation, const std::string& camera = "", double t1 = 2.0) {
  return R"({"animation": )" + animation + R"(,
 "camera": {"position": [0, 1, 5], "target": [0, 0, 0], "resolution": [16, 12])" + camera + R"(},
 "objects": [{"shape": {"type": "sphere", "radius": 0.5},
   "motion": [{"time": 0, "translate": [-1, 0, 0]}, {"time": )" + std::to_string(t1) + R"(, "translate": [1, 0, 0]}]}]})";
}

constexpr float kIntensity = test::kMovingPlaneIntensity;  // W/sr of the point light
constexpr float kRho = test::kMovingPlaneRho;

// The moving plane of tests/test_photon_render.cpp as an animation: 4
// frames at 4 fps (timeline [0, 1]), the plane from y = 0 to y = -1 over
// the timeline, so frame i sees it between -i/4 and -(i/4 + 1/8).
scene::SceneDescription planeAnimation() {
  auto d = test::movingPlaneScene(8);
  d.camera.shutterOpen = 0;
  d.camera.shutterClose = 1;
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  return d;
}

// The same frame alone: one frame whose shutter is frame i's, the plane's
// keyframes at that shutter's ends (the same clock, the same positions).
scene::SceneDescription planeFrameAlone(int frame) {
  auto d = planeAnimation();
  d.animation.reset();
  float t0 = float(frame) / 4.0f, t1 = t0 + 0.125f;
  d.camera.shutterOpen = t0;
  d.camera.shutterClose = t1;
  d.objects[0].motion = test::translation({0, -t0, 0}, {0, -t1, 0});
  d.objects[0].motion.times = {t0, t1};
  return d;
}

// Exact mean of a pixel over frame [t0, t1]: rho/pi I cos / d^2 at the
// plane point each sub-pixel ray meets, averaged over sub-pixels and time.
double analyticPixel(const Camera& cam, const Shutter& sceneShutter, int x, int y, float t0, float t1) {
  return test::movingPlanePixel(cam, sceneShutter, x, y, t0, t1, 32);
}

RenderOptions planeOptions(uint64_t seed) { return test::movingPlaneFrameOptions(seed); }

double meanRed(const Film& f) {
  double s = 0;
  for (const Rgb& c : f.color) s += c.r;
  return s / double(f.color.size());
}

struct Sequence {
  std::vector<Film> films;
  std::vector<RenderStats> stats;
};

Sequence renderSequence(const scene::SceneDescription& d, const RenderOptions& o, AnimationOptions ao,
                        int threads = 0) {
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  auto s = Scene::build(d);
  Sequence q;
  renderAnimation(*s, *d.animation, o, ao, Progress{}, [&](int, Film&& f, const RenderStats& st) {
    q.films.push_back(std::move(f));
    q.stats.push_back(st);
  });
  return q;
}

}  // namespace

TEST_CASE("animation block: frame shutters and keyframe clocks as specified") {
  auto d = scene::parseScene(animatedJson(R"({"fps": 24, "frames": 48, "shutter_angle": 90})"), "anim.json");
  REQUIRE(d.animation);
  CHECK(d.animation->fps == 24);
  CHECK(d.animation->frames == 48);
  CHECK(d.camera.shutterOpen == 0.0f);
  CHECK(d.camera.shutterClose == doctest::Approx(2.0));
  for (int i : {0, 1, 10, 47}) {
    Shutter s = frameShutter(*d.animation, i);
    CHECK(s.open == doctest::Approx(i / 24.0));
    CHECK(s.close == doctest::Approx(i / 24.0 + 0.25 / 24.0));
  }
  // Default shutter angle 180; keyframe times on the animation's clock:
  // the sphere is at x = -1 + t (T = 2) at scene time t.
  auto d2 = scene::parseScene(animatedJson(R"({"fps": 24, "frames": 48})"), "anim.json");
  CHECK(d2.animation->shutterAngle == 180);
  CHECK(frameShutter(*d2.animation, 12).close == doctest::Approx(0.5 + 0.5 / 24));
  auto s = Scene::build(d2);
  CHECK(s->shutter.open == 0.0f);
  CHECK(s->shutter.close == doctest::Approx(2.0f));
  for (float t : {0.0f, 0.5f, 1.25f, 2.0f}) {
    Vec3f c = s->objects[0].motion.atNormalized(s->shutter.normalized(t)).point({0, 0, 0});
    CHECK(c.x == doctest::Approx(-1.0 + t).epsilon(1e-4));
  }
  // A keyframe at the end of the timeline is fine; one past it is not.
  CHECK(errorOf(animatedJson(R"({"fps": 24, "frames": 48})", "", 2.0)).empty());
  std::string late = errorOf(animatedJson(R"({"fps": 24, "frames": 48})", "", 2.01));
  CHECK(late.find("anim.json:") == 0);
  CHECK(late.find("objects[0].motion[1].time") != std::string::npos);
  CHECK(late.find("outside the animation [0, 2]") != std::string::npos);
}

TEST_CASE("animation block: bad values give located errors") {
  struct Case {
    const char* animation;
    const char* path;
    const char* message;
  } cases[] = {
      {R"({"fps": 0, "frames": 4})", "animation.fps", "fps must be > 0"},
      {R"({"fps": -24, "frames": 4})", "animation.fps", "fps must be > 0"},
      {R"({"fps": 24, "frames": 0})", "animation.frames", "frames must be between 1"},
      {R"({"fps": 24, "frames": 2.5})", "animation.frames", "integer"},
      {R"({"fps": 24, "frames": 4, "shutter_angle": 0})", "animation.shutter_angle", "(0, 360]"},
      {R"({"fps": 24, "frames": 4, "shutter_angle": 361})", "animation.shutter_angle", "(0, 360]"},
      {R"({"fps": 24})", "animation", "missing required key \"frames\""},
      {R"({"fps": 24, "frames": 4, "shuter_angle": 90})", "animation", "unknown key"},
      {R"(24)", "animation", "expected an object"},
  };
  for (const Case& c : cases) {
    std::string e = errorOf(animatedJson(c.animation, "", 0.1));
    INFO(c.animation << " -> " << e);
    CHECK(e.find("anim.json:") == 0);
    CHECK(e.find(c.path) != std::string::npos);
    CHECK(e.find(c.message) != std::string::npos);
  }
  std::string both = errorOf(animatedJson(R"({"fps": 24, "frames": 4})", R"(, "shutter": [0, 1])", 0.1));
  CHECK(both.find("camera.shutter") != std::string::npos);
  CHECK(both.find("cannot be used together with \"animation\"") != std::string::npos);
}

TEST_CASE("animation time grid: shutters on bin edges, maps within 256 bins, the kernel's reach covered") {
  for (double angle : {180.0, 360.0, 90.0, 172.8, 1.0}) {
    scene::AnimationDesc a{24.0, 10, angle};
    for (double reach : {0.0, 0.1, 0.5, 1.0}) {
      TimeGrid g = makeTimeGrid(a, reach);
      INFO("angle " << angle << " reach " << reach);
      CHECK(g.shutterBins + 2 * g.padBins <= 256);
      CHECK(double(g.padBins - 1) >= reach * double(g.shutterBins) - 1e-9);
      CHECK(g.binWidth * double(g.binsPerFrame) == doctest::Approx(1.0 / 24.0));
      // The shutter in whole bins: exact, or within half a bin.
      CHECK(std::fabs(double(g.shutterBins) - double(g.binsPerFrame) * angle / 360.0) <= 0.5);
      CHECK(g.shutterBins >= 40);  // fine enough in time (>= 40 bins per shutter)
    }
  }
  // 180 degrees, the default reach: 210 shutter bins of 420 per frame,
  // pads of 23 (docs/animation.md).
  TimeGrid g = makeTimeGrid(scene::AnimationDesc{24.0, 48, 180.0}, double(RenderOptions{}.maxDtFraction));
  CHECK(g.binsPerFrame == 420);
  CHECK(g.shutterBins == 210);
  CHECK(g.padBins == 23);
}

TEST_CASE("animation: frames of the moving plane match the analytic irradiance, and the frame rendered alone") {
  auto d = planeAnimation();
  RenderOptions o = planeOptions(11);
  AnimationOptions ao;
  ao.first = 0;
  ao.last = 3;
  ao.window = 2;
  Sequence q = renderSequence(d, o, ao);
  REQUIRE(q.films.size() == 4);
  auto s = Scene::build(d);
  for (int i = 0; i < 4; ++i) {
    Shutter fs = frameShutter(*d.animation, i);
    double want = 0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) want += analyticPixel(s->camera, s->shutter, x, y, fs.open, fs.close);
    want /= 64.0;
    double ratio = meanRed(q.films[size_t(i)]) / want;
    MESSAGE("frame " << i << ": sequence / analytic = " << ratio);
    CHECK(ratio == doctest::Approx(1.0).epsilon(0.05));
    CHECK(q.stats[size_t(i)].timeEstimates > 0);
  }
  // Frame 2 alone (its own single-frame scene and maps) against frame 2 of
  // the sequence: the two are independent estimates of one value. Their
  // spread over 4 seeds each bounds the difference of the means.
  double seqSum = 0, aloneSum = 0, seqSq = 0, aloneSq = 0;
  const int seeds = 4;
  auto alone = planeFrameAlone(2);
  auto sa = Scene::build(alone);
  AnimationOptions one;
  one.first = one.last = 2;
  one.window = 1;
  for (int k = 0; k < seeds; ++k) {
    RenderOptions ok = planeOptions(100 + uint64_t(k));
    double a = meanRed(renderSequence(d, ok, one).films[0]);
    RenderStats st;
    double b = meanRed(render(*sa, ok, Progress{}, st));
    seqSum += a;
    seqSq += a * a;
    aloneSum += b;
    aloneSq += b * b;
  }
  double ma = seqSum / seeds, mb = aloneSum / seeds;
  double va = std::max(0.0, seqSq / seeds - ma * ma) * seeds / (seeds - 1);
  double vb = std::max(0.0, aloneSq / seeds - mb * mb) * seeds / (seeds - 1);
  double se = std::sqrt((va + vb) / seeds);
  MESSAGE("frame 2: sequence " << ma << ", alone " << mb << ", standard error of the difference " << se);
  // 4 standard errors, with a floor of 1% for the kernels' (shared) bias
  // near the shutter ends, which the pads shrink in the sequence.
  CHECK(std::fabs(ma - mb) <= 4.0 * se + 0.01 * mb);
}

TEST_CASE("animation: a frame is bit-identical whatever the frame range and threads (for one --window)") {
  // The window is also the block of frames that share time-invariant
  // photons (docs/animation.md section 7), so it stays; without sharing any
  // window gives the same frame.
  auto d = planeAnimation();
  RenderOptions o = planeOptions(5);
  o.globalPhotons = 20000;
  o.spp = 4;
  AnimationOptions all;
  all.first = 0;
  all.last = 3;
  all.window = 2;
  AnimationOptions just;
  just.first = just.last = 2;
  just.window = 2;
  Sequence a = renderSequence(d, o, all, 2);
  Sequence b = renderSequence(d, o, just, 1);
  REQUIRE(a.films.size() == 4);
  REQUIRE(b.films.size() == 1);
  CHECK(std::memcmp(a.films[2].color.data(), b.films[0].color.data(), a.films[2].color.size() * sizeof(Rgb)) == 0);
  // Different frames differ (the plane moved).
  CHECK(meanRed(a.films[0]) > meanRed(a.films[3]) * 1.2);
  // Without sharing, the window does not matter either.
  all.window = 3;
  all.sharedScale = 0;
  just.window = 1;
  just.sharedScale = 0;
  Sequence c = renderSequence(d, o, all, 2);
  Sequence e = renderSequence(d, o, just, 1);
  CHECK(std::memcmp(c.films[2].color.data(), e.films[0].color.data(), c.films[2].color.size() * sizeof(Rgb)) == 0);
}

TEST_CASE("animation: the standard estimate uses only the frame's own photons") {
  // A still plane under a light that moves far away between frames: the
  // standard estimate (nothing the eye sees moves) of each frame must
  // follow its own frame's lighting, not the timeline's average.
  auto d = planeAnimation();
  d.objects[0].motion = scene::MotionDesc{};
  d.lights[0].motion = test::translation({0, 0, 0}, {0, 2, 0});  // up 2 m over the timeline: 1/d^2 falls
  RenderOptions o = planeOptions(3);
  o.method = RenderMethod::Standard;
  AnimationOptions ao;
  ao.first = 0;
  ao.last = 3;
  Sequence q = renderSequence(d, o, ao);
  auto s = Scene::build(d);
  for (int i = 0; i < 4; ++i) {
    Shutter fs = frameShutter(*d.animation, i);
    // Irradiance at the centre pixel's plane point, averaged over the frame.
    double want = 0;
    const int nt = 64;
    for (int k = 0; k < nt; ++k) {
      double t = fs.open + (fs.close - fs.open) * (k + 0.5) / nt;
      double h = 2.0 + 2.0 * t;
      want += kRho / kPi * kIntensity / (h * h) / nt;
    }
    const Film& f = q.films[size_t(i)];
    double got = (f.color[f.index(3, 3)].r + f.color[f.index(4, 4)].r + f.color[f.index(3, 4)].r + f.color[f.index(4, 3)].r) / 4;
    MESSAGE("frame " << i << ": centre / analytic = " << got / want);
    CHECK(got / want == doctest::Approx(1.0).epsilon(0.06));
  }
}

// ---- command line ----

namespace {

std::string writeScene(const std::string& dir, const std::string& name, const std::string& json) {
  std::string path = dir + "/" + name;
  test::writeFile(path, json);
  return path;
}

const char* kCliScene = R"({"animation": {"fps": 24, "frames": FRAMES},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0.3, 0], "resolution": [16, 12]},
 "materials": {"glass": {"type": "dielectric", "ior": 1.5}},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}},
   {"shape": {"type": "sphere", "radius": 0.4}, "material": "glass", "transform": {"translate": [0, 0.6, 0]},
    "motion": [{"time": 0, "translate": [-1, 0, 0]}, {"time": END, "translate": [1, 0, 0]}]}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200]}]})";

std::string cliScene(int frames) {
  std::string s = kCliScene;
  s.replace(s.find("FRAMES"), 6, std::to_string(frames));
  s.replace(s.find("END"), 3, std::to_string(0.999 * frames / 24.0));
  return s;
}

uint64_t peakOf(const std::string& output) {
  const char* key = "peak resident memory: ";
  size_t at = output.find(key);
  return at == std::string::npos ? 0 : std::strtoull(output.c_str() + at + std::strlen(key), nullptr, 10);
}

}  // namespace

TEST_CASE("frame patterns: # runs become zero-padded frame numbers; ranges parse with located errors") {
  using namespace tdpm::cli;
  CHECK(formatFramePath("out/frame_####.exr", 7) == "out/frame_0007.exr");
  CHECK(formatFramePath("a#/b_##.exr", 12) == "a12/b_12.exr");
  CHECK(formatFramePath("f_#.exr", 123) == "f_123.exr");
  CHECK(parseFrameRange("3-7", 10).first == 3);
  CHECK(parseFrameRange("3-7", 10).last == 7);
  CHECK(parseFrameRange("4", 10).count() == 1);
  auto err = [](auto f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(err([] { parseFrameRange("7-3", 10); }).find("--frame-range: the first frame 7 comes after") == 0);
  CHECK(err([] { parseFrameRange("0-10", 10); }).find("past the animation's last frame 9") != std::string::npos);
  CHECK(err([] { parseFrameRange("a-b", 10); }).find("--frame-range: expected A-B") == 0);
  CHECK(err([] { parseFrameRange("-3", 10); }).find("--frame-range: expected A-B") == 0);
  CHECK(err([] { checkFramePattern("out/frame.exr", FrameRange{0, 3}); }).find("has no # for the frame number") !=
        std::string::npos);
  CHECK(err([] { checkFramePattern("out/frame.exr", FrameRange{2, 2}); }).empty());
  CHECK(err([] { checkFramePattern("out/frame_##.png", FrameRange{0, 3}); }).find("must end in .exr") !=
        std::string::npos);
}

TEST_CASE("render CLI: an animation writes one EXR and PNG per frame of the range, into a created directory") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "anim.json", cliScene(6));
  auto r = test::runTdpm("render '" + scene + "' -o '" + dir + "/out/sub/f_###.exr' --frame-range 2-4 --spp 2 "
                         "--photons 2000 --global-photons 1000 -t 2");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  for (int i : {2, 3, 4}) {
    CHECK(test::fileExists(dir + "/out/sub/f_00" + std::to_string(i) + ".exr"));
    CHECK(test::fileExists(dir + "/out/sub/f_00" + std::to_string(i) + ".png"));
  }
  CHECK(test::countEntries(dir + "/out/sub") == 6);
  CHECK(r.output.find("frame 3: ") != std::string::npos);
  CHECK(r.output.find("3 frames (2-4)") != std::string::npos);
  CHECK(r.output.find("per frame") != std::string::npos);
}

TEST_CASE("render CLI: bad animation blocks, patterns, ranges and --video are located errors and write nothing") {
  std::string dir = test::makeTempDir();
  std::string good = writeScene(dir, "good.json", cliScene(6));
  std::string bad = cliScene(6);
  bad.replace(bad.find("\"fps\": 24"), 9, "\"fps\": 0");
  std::string badScene = writeScene(dir, "bad.json", bad);
  struct Case {
    std::string args, message;
  } cases[] = {
      {"'" + badScene + "' -o '" + dir + "/o1/f_##.exr'", "bad.json:1: animation.fps: fps must be > 0"},
      {"'" + good + "' -o '" + dir + "/o2/f.exr'", "--output"},
      {"'" + good + "' -o '" + dir + "/f.exr'", "has no # for the frame number, but 6 frames"},
      {"'" + good + "' -o '" + dir + "/o3/f_##.exr' --frame-range 4-9", "--frame-range: frame 9 is past"},
      {"'" + good + "' -o '" + dir + "/o4/f_##.exr' --frame-range 1-x", "--frame-range: expected A-B"},
      {"'" + good + "' -o '" + dir + "/o5/f_##.exr' --video '" + dir + "/v.avi'", "--video: '"},
      {"'" + good + "' -o '" + dir + "/o6/f_##.exr' -m accumulation", "cannot render an animation"},
  };
  int before = test::countEntries(dir);
  for (const Case& c : cases) {
    auto r = test::runTdpm("render " + c.args + " --spp 1 --photons 100 --global-photons 100");
    INFO(c.args << "\n" << r.output);
    CHECK(r.exitCode == 1);
    CHECK(r.output.find(c.message) != std::string::npos);
  }
  CHECK(test::countEntries(dir) == before);  // no directory, image or video made
  // A pattern for a scene without animation.
  std::string still = writeScene(dir, "still.json", R"({"camera": {"resolution": [8, 8]}, "objects": []})");
  auto r = test::runTdpm("render '" + still + "' -o '" + dir + "/s_##.exr'");
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("has no \"animation\" block") != std::string::npos);
}

namespace tdpm::cli {
std::string findOnPath(const std::string& name);  // cli/animation_command.h (that header needs CLI11)
}

TEST_CASE("render CLI: --video without ffmpeg on PATH fails before rendering; with ffmpeg it makes the video") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "anim.json", cliScene(4));
  // A PATH that holds no ffmpeg (the binary is named by its full path).
  std::string empty = dir + "/emptybin";
  mkdir(empty.c_str(), 0755);
  std::string cmd = "env PATH='" + empty + "' '" + std::string(TDPM_BINARY) + "' render '" + scene + "' -o '" + dir +
                    "/o/f_##.exr' --video '" + dir + "/v/v.mp4' --spp 1 2>&1 < /dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buf[512];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int status = pclose(p);
  INFO(out);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK(out.find("--video: ffmpeg was not found on PATH") != std::string::npos);
  CHECK(!test::fileExists(dir + "/o"));
  CHECK(!test::fileExists(dir + "/v"));
  if (tdpm::cli::findOnPath("ffmpeg").empty()) {
    MESSAGE("ffmpeg is not on PATH: the video itself is not tested");
    return;
  }
  for (const char* ext : {"mp4", "gif"}) {
    std::string video = dir + "/v/movie." + ext;
    auto r = test::runTdpm("render '" + scene + "' -o '" + dir + "/o/f_##.exr' --video '" + video +
                           "' --spp 1 --photons 500 --global-photons 500 -t 2");
    INFO(r.output);
    CHECK(r.exitCode == 0);
    struct stat st;
    REQUIRE(stat(video.c_str(), &st) == 0);
    CHECK(st.st_size > 100);
    CHECK(test::countEntries(dir + "/v") == (std::string(ext) == "mp4" ? 1 : 2));  // no temporaries left
  }
}

TEST_CASE("render CLI: with --window, peak memory does not grow with the number of frames") {
  // A floor under a moving lamp, 10000 global photons per frame: all 48
  // frames held at once measured 25.2 MB of peak RSS against 13.6 MB with
  // --window 2 (tdpm render ... --window 48 --stats); 12 frames hold less.
  std::string dir = test::makeTempDir();
  uint64_t peak[2] = {0, 0};
  int frames[2] = {12, 48};
  for (int k = 0; k < 2; ++k) {
    std::string end = std::to_string(0.999 * frames[k] / 24.0);
    std::string scene = writeScene(dir, "a" + std::to_string(frames[k]) + ".json",
                                   R"({"animation": {"fps": 24, "frames": )" + std::to_string(frames[k]) + R"(},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0, 0], "resolution": [8, 6]},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200],
   "motion": [{"time": 0, "translate": [-1, 0, 0]}, {"time": )" + end + R"(, "translate": [1, 0, 0]}]}]})");
    auto r = test::runTdpm("render '" + scene + "' -o '" + dir + "/o" + std::to_string(k) +
                           "/f_##.exr' --window 2 --spp 1 --photons 0 --global-photons 10000 --global-direct -t 2 --stats");
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    peak[k] = peakOf(r.output);
    REQUIRE(peak[k] > 0);
  }
  MESSAGE("peak RSS: 12 frames " << peak[0] / 1024 << " KiB, 48 frames " << peak[1] / 1024 << " KiB");
  // Holding the 36 extra frames would add about 9 MB; allow 4 MB of noise.
  CHECK(peak[1] < peak[0] + (uint64_t(4) << 20));
}

// Issue 27 item 15: one frame of a 2000-frame animation with --window
// 100000 was budgeted as if 100002 frames' photons were held at once
// ("asks for 2438164000 caustic photons (93 GiB)" from 20000 asked for).
TEST_CASE("render CLI: --window is capped at the frames rendered; a budget error it causes names it") {
  std::string dir = test::makeTempDir();
  std::string scene = writeScene(dir, "long.json", R"({"animation": {"fps": 24, "frames": 2000},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0, 0], "resolution": [8, 6]},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200],
   "motion": [{"time": 0, "translate": [-1, 0, 0]}, {"time": 83, "translate": [1, 0, 0]}]}]})");
  // Uncapped: 20000 x (100002 x 156/128 + 1) = 2.4e9 photons, far above this machine's memory.
  auto one = test::runTdpm("render '" + scene + "' -o '" + dir + "/one.exr' --frame-range 7-7 --window 100000 "
                           "--spp 1 --photons 0 --global-photons 20000 --global-direct -t 2 -q");
  INFO(one.output);
  CHECK(one.exitCode == 0);
  CHECK(test::fileExists(dir + "/one.exr"));
  // All 2000 frames in one window of 2e6 photons each: refused before any
  // tracing, and the message says the window multiplied the count.
  auto all = test::runTdpm("render '" + scene + "' -o '" + dir + "/all/f_####.exr' --window 100000 "
                           "--spp 1 --photons 0 --global-photons 2000000 --global-direct -t 2 -q");
  INFO(all.output);
  CHECK(all.exitCode == 1);
  CHECK(all.output.find("--global-photons (2000000 per frame, held for a window of 2000 frames at once (--window 100000))") !=
        std::string::npos);
  CHECK_FALSE(test::fileExists(dir + "/all/f_0000.exr"));
  std::system(("rm -rf '" + dir + "'").c_str());
}

namespace {

// makeTimeGrid as it was before issue 27 (a count down from 256 / share):
// the reference for the bisection, at angles where counting is quick.
TimeGrid countedTimeGrid(const scene::AnimationDesc& a, double reach) {
  reach = std::clamp(reach, 0.0, 1.0);
  const double share = a.shutterAngle / 360.0;
  auto fits = [&](int64_t B, TimeGrid& g) {
    int64_t S = std::max<int64_t>(1, std::llround(double(B) * share));
    int64_t P = int64_t(std::ceil(reach * double(S))) + 1;
    if (S + 2 * P > 256) return false;
    g.binsPerFrame = B;
    g.shutterBins = S;
    g.padBins = P;
    g.binWidth = 1.0 / (double(B) * a.fps);
    return true;
  };
  TimeGrid best;
  int64_t B = int64_t(std::floor(256.0 / share));
  while (B > 1 && !fits(B, best)) --B;
  if (B <= 1) fits(1, best);
  for (int64_t b = B; b >= std::max<int64_t>(1, B / 2); --b) {
    TimeGrid g;
    if (fits(b, g) && std::fabs(double(b) * share - double(g.shutterBins)) < 1e-6) return g;
  }
  return best;
}

std::string animationError(const std::string& animation) {
  try {
    scene::parseScene(animatedJson(animation, "", 0.001), "anim.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("animation time grid: the bisection finds the grid the count down found, for every angle and reach") {
  int checked = 0;
  for (double angle = 0.5; angle <= 360.0; angle += angle < 10 ? 0.25 : 1.7) {
    for (double reach : {0.0, 0.1, double(RenderOptions{}.maxDtFraction), 0.37, 1.0}) {
      scene::AnimationDesc a{24.0, 10, angle};
      TimeGrid fast = makeTimeGrid(a, reach), slow = countedTimeGrid(a, reach);
      INFO("angle " << angle << " reach " << reach);
      CHECK(fast.binsPerFrame == slow.binsPerFrame);
      CHECK(fast.shutterBins == slow.shutterBins);
      CHECK(fast.padBins == slow.padBins);
      CHECK(fast.binWidth == slow.binWidth);
      ++checked;
    }
  }
  CHECK(checked > 1000);
  // A 1e-6 degree shutter: 256 / share is 9.2e10, which the count down
  // walked one B at a time; the grid still fits (a single frame is usable).
  TimeGrid tiny = makeTimeGrid(scene::AnimationDesc{24.0, 1, 1e-6}, 0.1);
  CHECK(tiny.shutterBins + 2 * tiny.padBins <= 256);
  CHECK(tiny.shutterBins >= 200);
}

// Issue 27 item 2: tiny shutter angles looped, failed inside, or said "out
// of memory"; long timelines lost the shutter to float rounding.
TEST_CASE("animation block: a shutter float time cannot resolve is refused at shutter_angle, with the smallest usable angle") {
  for (const char* angle : {"1e-6", "1e-5", "1e-20"}) {
    std::string e = animationError(std::string(R"({"fps": 24, "frames": 4, "shutter_angle": )") + angle + "}");
    INFO(angle << " -> " << e);
    CHECK(e.find("anim.json:") == 0);
    CHECK(e.find("animation.shutter_angle") != std::string::npos);
    CHECK(e.find(std::string(angle) == "1e-20" ? "below tdpm's shortest shutter of 1e-12 s" : "cannot resolve") !=
          std::string::npos);
    CHECK(e.find("the smallest usable shutter_angle for this fps and frame count is ") != std::string::npos);
  }
  // One frame near t = 0: a 1e-17 degree shutter (1.2e-21 s) traced photons
  // for ever, 1e-30 degrees ran out of memory; below 1e-12 s is refused.
  for (const char* angle : {"1e-17", "1e-30"})
    CHECK(animationError(std::string(R"({"fps": 24, "frames": 1, "shutter_angle": )") + angle + "}")
              .find("below tdpm's shortest shutter of 1e-12 s; the smallest usable shutter_angle for this fps and "
                    "frame count is 8.64e-09") != std::string::npos);
  CHECK(animationError(R"({"fps": 24, "frames": 1, "shutter_angle": 8.64e-09})") == "(no error)");
  // The named smallest angle is accepted, and a little less is not.
  std::string e = animationError(R"({"fps": 24, "frames": 100, "shutter_angle": 1e-4})");
  const std::string key = "smallest usable shutter_angle for this fps and frame count is ";
  size_t at = e.find(key);
  REQUIRE(at != std::string::npos);
  double smallest = std::strtod(e.c_str() + at + key.size(), nullptr);
  CHECK(smallest > 0.5);
  CHECK(smallest < 2);
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", smallest);
  CHECK(animationError(std::string(R"({"fps": 24, "frames": 100, "shutter_angle": )") + text + "}") == "(no error)");
  std::snprintf(text, sizeof text, "%.17g", smallest * 0.5);
  CHECK(animationError(std::string(R"({"fps": 24, "frames": 100, "shutter_angle": )") + text + "}") != "(no error)");
  // The most frames at the given angle, and the limits docs/animation.md quotes (24 fps).
  for (auto [angle, most] : {std::pair{180.0, 24575}, std::pair{10.0, 1536}, std::pair{1.0, 96}}) {
    INFO("angle " << angle);
    CHECK(scene::animationTimeResolutionProblem(scene::AnimationDesc{24.0, most, angle}) == "");
    std::string p = scene::animationTimeResolutionProblem(scene::AnimationDesc{24.0, most + 1, angle});
    CHECK(p.find("or at most " + std::to_string(most) + " frames at this angle") != std::string::npos);
  }
  // Frame 99999 of 100000 at 10 degrees (rendered 1.2% dark before): refused.
  CHECK(scene::animationTimeResolutionProblem(scene::AnimationDesc{24.0, 100000, 10.0}) != "");
  // One frame of a tiny shutter sits near t = 0, where floats are fine.
  CHECK(scene::animationTimeResolutionProblem(scene::AnimationDesc{24.0, 1, 1e-4}) == "");
}
