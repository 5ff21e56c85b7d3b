// tests/test_animation_progressive.cpp — an animation's frames rendered in
// progressive passes (issue 22 item 7, docs/animation.md "Progressive
// frames"): a progressive frame converges to the fixed-budget frame's mean
// and to the analytic value of its own part of the timeline; --passes is
// per frame and a frame's image does not depend on the frame range; on the
// command line the frames are written with their states, and --resume
// continues each frame (one state file per frame).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "image/exr.h"
#include "render/animation.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "moving_plane.h"
#include "scene_fixtures.h"
#include "seed_stats.h"

using namespace tdpm;
using test::meanRed;
using test::overSeeds;
using test::MeanAndError;

namespace {

// The moving plane of tests/test_animation.cpp: 4 frames at 4 fps (the
// timeline [0, 1]), the plane from y = 0 to y = -1 over the timeline, so
// the light on it changes from frame to frame.
scene::SceneDescription planeAnimation() {
  auto d = test::movingPlaneScene(8);
  d.camera.shutterOpen = 0;
  d.camera.shutterClose = 1;
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  return d;
}

RenderOptions fixedOptions(uint64_t seed) { return test::movingPlaneFrameOptions(seed); }

RenderOptions progressiveOptions(uint64_t seed, int passes) {
  RenderOptions o = fixedOptions(seed);
  o.progressive = true;
  o.passes = passes;
  o.spp = 4;
  o.globalPhotons = 20000;  // per pass
  return o;
}


struct Frames {
  std::vector<int> index;
  std::vector<Film> films;
};

Frames renderFrames(const Scene& s, const scene::AnimationDesc& a, const RenderOptions& o, int first, int last) {
  AnimationOptions ao;
  ao.first = first;
  ao.last = last;
  ao.window = 1;
  Frames q;
  renderAnimation(s, a, o, ao, Progress{}, [&](int i, Film&& f, const RenderStats&) {
    q.index.push_back(i);
    q.films.push_back(std::move(f));
  });
  return q;
}

double analyticFrame(const Scene& s, const scene::AnimationDesc& a, int frame) {
  Shutter fs = frameShutter(a, frame);
  double want = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) want += test::movingPlanePixel(s.camera, s.shutter, x, y, fs.open, fs.close, 32);
  return want / 64.0;
}


}  // namespace

TEST_CASE("progressive animation frame: converges to the fixed-budget frame's mean, in its own part of the timeline") {
  auto d = planeAnimation();
  auto s = Scene::build(d);
  const scene::AnimationDesc& a = *d.animation;
  const int frame = 2;
  const double want = analyticFrame(*s, a, frame);
  // The remap matters: frame 0's light differs from frame 2's by far more
  // than the tolerances below, so a pass sampling the wrong part of the
  // timeline (or the whole of it) fails.
  const double other = analyticFrame(*s, a, 0);
  MESSAGE("analytic frame 2 " << want << ", frame 0 " << other);
  REQUIRE(std::fabs(other - want) > 0.1 * want);

  std::vector<double> prog, fixed, layerVar;
  for (uint64_t k = 0; k < 4; ++k) {
    Frames p = renderFrames(*s, a, progressiveOptions(200 + k, 8), frame, frame);
    REQUIRE(p.films.size() == 1);
    prog.push_back(meanRed(p.films[0]));
    // The variance layer: the variance of each pixel's mean of 8 pass means.
    double v = 0;
    for (const Rgb& c : p.films[0].varianceOfMean) v += double(c.r);
    layerVar.push_back(v / double(p.films[0].varianceOfMean.size()));
    fixed.push_back(meanRed(renderFrames(*s, a, fixedOptions(300 + k), frame, frame).films[0]));
  }
  MeanAndError mp = overSeeds(prog), mf = overSeeds(fixed);
  const double se = std::sqrt(mp.se * mp.se + mf.se * mf.se);
  MESSAGE("frame 2: progressive " << mp.mean << " +- " << mp.se << ", fixed budget " << mf.mean << " +- " << mf.se
                                  << ", analytic " << want << "; mean pixel variance layer " << layerVar[0]);
  for (double v : layerVar) CHECK(v > 0);  // 8 passes: the layer is filled
  // 4 standard errors, with a floor of 1% for the kernels' bias (the
  // fixed-budget frame's k-NN and the passes' shrinking kernels differ).
  CHECK(std::fabs(mp.mean - mf.mean) <= 4.0 * se + 0.01 * mf.mean);
  CHECK(mp.mean / want == doctest::Approx(1.0).epsilon(0.05));
  CHECK(std::fabs(mp.mean - want) < std::fabs(mp.mean - other) / 4.0);
}

TEST_CASE("progressive animation frame: every pass's photons are the frame's own shutter's") {
  // tests/test_animation.cpp's still plane under a light that moves far
  // away over the timeline: the standard estimate ignores time, so a frame
  // in passes follows its own frame's lighting only if every pass traces
  // its photons over that frame's shutter (over the timeline it would give
  // the timeline's average to every frame).
  auto d = planeAnimation();
  d.objects[0].motion = scene::MotionDesc{};
  d.lights[0].motion = test::translation({0, 0, 0}, {0, 2, 0});  // up 2 m over the timeline: 1/d^2 falls
  auto s = Scene::build(d);
  RenderOptions o = progressiveOptions(5, 6);
  o.method = RenderMethod::Standard;
  Frames q = renderFrames(*s, *d.animation, o, 0, 3);
  REQUIRE(q.films.size() == 4);
  for (int i : {0, 3}) {
    Shutter fs = frameShutter(*d.animation, i);
    double want = 0;  // irradiance at the centre pixels' plane point, averaged over the frame
    const int nt = 64;
    for (int k = 0; k < nt; ++k) {
      double t = fs.open + (fs.close - fs.open) * (k + 0.5) / nt;
      double h = 2.0 + 2.0 * t;
      want += test::kMovingPlaneRho / kPi * test::kMovingPlaneIntensity / (h * h) / nt;
    }
    const Film& f = q.films[size_t(i)];
    double got = (f.color[f.index(3, 3)].r + f.color[f.index(4, 4)].r + f.color[f.index(3, 4)].r + f.color[f.index(4, 3)].r) / 4;
    MESSAGE("progressive frame " << i << ": centre / analytic = " << got / want);
    CHECK(got / want == doctest::Approx(1.0).epsilon(0.06));  // frame 0 is 2.3x frame 3: far outside
  }
}

TEST_CASE("progressive animation frames: --passes per frame, a frame's image whatever the range") {
  auto d = planeAnimation();
  auto s = Scene::build(d);
  RenderOptions o = progressiveOptions(7, 3);
  o.globalPhotons = 5000;
  Frames range = renderFrames(*s, *d.animation, o, 1, 2);
  REQUIRE(range.films.size() == 2);
  CHECK(range.index == std::vector<int>{1, 2});
  for (const Film& f : range.films)
    for (float c : f.sampleCount) CHECK(c == float(3 * o.spp));  // 3 passes of spp each, every frame
  Frames alone = renderFrames(*s, *d.animation, o, 2, 2);
  REQUIRE(alone.films.size() == 1);
  const std::vector<Rgb>& x = alone.films[0].color;
  const std::vector<Rgb>& y = range.films[1].color;
  REQUIRE(x.size() == y.size());
  CHECK(std::memcmp(x.data(), y.data(), x.size() * sizeof(Rgb)) == 0);  // bit for bit
  CHECK(meanRed(range.films[0]) != meanRed(range.films[1]));
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Frame i's pixels as bytes, for bit-for-bit comparisons.
std::string framePixels(const std::string& path) {
  image::ExrFile e = image::readExr(path);
  return std::string(reinterpret_cast<const char*>(e.color.pixels.data()), e.color.pixels.size() * sizeof(Rgb));
}

TEST_CASE("render CLI: --progressive animation frames carry their state; --resume continues each frame bit for bit, "
          "skips finished ones, and refuses another render's state") {
  std::string dir = test::makeTempDir();
  const std::string scene = dir + "/anim.json";
  test::writeFile(scene, R"({"animation": {"fps": 24, "frames": 3},
 "camera": {"position": [0, 1.5, 4], "target": [0, 0.3, 0], "resolution": [16, 12]},
 "materials": {"glass": {"type": "dielectric", "ior": 1.5}},
 "objects": [{"shape": {"type": "quad", "size": [6, 6]}},
   {"shape": {"type": "sphere", "radius": 0.4}, "material": "glass", "transform": {"translate": [0, 0.6, 0]},
    "motion": [{"time": 0, "translate": [-1, 0, 0]}, {"time": 0.12, "translate": [1, 0, 0]}]}],
 "lights": [{"type": "point", "position": [0, 3, 0], "power": [200, 200, 200]}]})");
  const std::string flags = " --progressive --spp 1 --photons 2000 --global-photons 1000 -t 2";
  auto r = test::runTdpm("render '" + scene + "' -o '" + dir + "/out/f_#.exr' --passes 2" + flags);
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  for (int i : {0, 1, 2}) CHECK(test::fileExists(dir + "/out/f_" + std::to_string(i) + ".exr"));
  CHECK(r.output.find("stored in 6 passes") != std::string::npos);  // 2 passes for each of the 3 frames
  // Frames 0 and 1 resumed in place to 4 passes (frame 2's file removed: it starts from pass 0).
  std::remove((dir + "/out/f_2.exr").c_str());
  auto res = test::runTdpm("render '" + scene + "' -o '" + dir + "/out/f_#.exr' --passes 4 --resume '" + dir +
                           "/out/f_#.exr'" + flags);
  INFO(res.output);
  REQUIRE(res.exitCode == 0);
  CHECK(res.output.find("stored in 8 passes") != std::string::npos);  // 2 more for frames 0, 1; 4 for frame 2
  auto whole = test::runTdpm("render '" + scene + "' -o '" + dir + "/ref/f_#.exr' --passes 4" + flags);
  INFO(whole.output);
  REQUIRE(whole.exitCode == 0);
  for (int i : {0, 1, 2}) {
    const std::string n = "/f_" + std::to_string(i) + ".exr";
    CHECK(framePixels(dir + "/out" + n) == framePixels(dir + "/ref" + n));
  }
  // Finished frames are skipped: no pass is traced, the files stay.
  const std::string before0 = readBytes(dir + "/out/f_0.exr");
  auto again = test::runTdpm("render '" + scene + "' -o '" + dir + "/out/f_#.exr' --passes 4 --resume '" + dir +
                             "/out/f_#.exr'" + flags);
  INFO(again.output);
  REQUIRE(again.exitCode == 0);
  CHECK(again.output.find("stored in 0 passes") != std::string::npos);
  CHECK(readBytes(dir + "/out/f_0.exr") == before0);
  // Another render's state (other --photons): a located error, nothing written.
  int entries = test::countEntries(dir);
  auto bad = test::runTdpm("render '" + scene + "' -o '" + dir + "/out/f_#.exr' --passes 6 --resume '" + dir +
                           "/out/f_#.exr' --progressive --spp 1 --photons 100 --global-photons 1000 -t 2");
  INFO(bad.output);
  CHECK(bad.exitCode == 1);
  CHECK(bad.output.find("--resume " + dir + "/out/f_0.exr: it is another render") != std::string::npos);
  CHECK(bad.output.find("photons: 2000") != std::string::npos);
  CHECK(test::countEntries(dir) == entries);
  CHECK(readBytes(dir + "/out/f_0.exr") == before0);
  // Frame 1's state resumed as frame 0's: refused by its shutter.
  std::filesystem::create_directories(dir + "/swap");
  test::writeFile(dir + "/swap/f_0.exr", readBytes(dir + "/out/f_1.exr"));
  auto swapped = test::runTdpm("render '" + scene + "' -o '" + dir + "/swap/f_#.exr' --frame-range 0-0 --passes 6 --resume '" +
                               dir + "/swap/f_#.exr'" + flags);
  INFO(swapped.output);
  CHECK(swapped.exitCode == 1);
  CHECK(swapped.output.find("frame_shutter") != std::string::npos);
}
