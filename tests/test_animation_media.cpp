// tests/test_animation_media.cpp — animations in participating media
// (render/animation.cpp frameMap's volume beam maps): a frame of a fog
// animation with a light moving through it against the same frame rendered
// alone as a still with the same shutter and against the volumetric path
// tracer of that frame (time and standard, the first and an inner frame,
// both forms of the time estimate), volume photons shared by a block
// (still light, moving occluder) against the same frame without sharing,
// progressive frames against the frame alone in passes, and the command
// line: a fog animation renders with time, refuses accumulation.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "airlight_scene.h"
#include "cli_harness.h"
#include "render/animation.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

constexpr float kI = 10, kSa = 0.05f, kSs = 0.25f, kH = 0.7f, kD = 5;

// The light moves sideways at z = 1, from x = 0.8 (t = 0) to 2 (t = 1),
// outside the camera's 60 degree cone (no eye ray passes near it: a ray
// that does makes the estimate's noise several times larger).
Vec3f lightAt(double t) { return {float(0.8 + 1.2 * t), 0, 1}; }
// The camera, when it moves, a hair along its axis (every eye path then
// takes the time-dependent estimate; the picture does not change).
Vec3f cameraAt(double t) { return {0, 0, float(1e-4 * t)}; }

void setMotion(scene::SceneDescription& d, float t0, float t1, bool cameraMoves) {
  d.camera.shutterOpen = t0;
  d.camera.shutterClose = t1;
  d.lights[0].position = {0, 0, 0};
  d.lights[0].motion = test::translation(lightAt(t0), lightAt(t1));
  d.lights[0].motion.times = {t0, t1};
  d.camera.motion.clear();
  if (cameraMoves)
    for (float t : {t0, t1}) {
      scene::CameraKeyframe k;
      k.time = t;
      k.position = cameraAt(t);
      k.target = cameraAt(t) + Vec3f{0, 0, 1};
      d.camera.motion.push_back(k);
    }
}

// The airlight scene seen through 4x4 pixels over 60 degrees (the image
// mean over many eye rays: less noise than one ray's).
scene::SceneDescription fogScene() {
  auto d = test::airlightScene(kI, kSa, kSs, 0, kH, kD);
  d.camera.fovDegrees = 60;
  d.camera.width = d.camera.height = 4;
  return d;
}

// 4 frames at 4 fps, 180°: frame i's shutter is [i/4, i/4 + 1/8].
scene::SceneDescription fogAnimation(bool cameraMoves) {
  auto d = fogScene();
  setMotion(d, 0, 1, cameraMoves);
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  return d;
}

// Frame i alone: one still whose shutter is frame i's, the light and the
// camera at the same places on the same clock.
scene::SceneDescription fogFrameAlone(int frame, bool cameraMoves) {
  auto d = fogScene();
  setMotion(d, float(frame) / 4.0f, float(frame) / 4.0f + 0.125f, cameraMoves);
  return d;
}

// Single scattering (max depth 1), volume photons alone.
RenderOptions fogOptions(RenderMethod m, uint64_t seed, int spp = 4) {
  auto o = test::smallRenderOptions(m, spp, 1, seed);
  o.volumePhotons = 40000;
  o.causticPhotons = o.globalPhotons = 0;
  o.gatherRays = 0;
  return o;
}

// Frame `frame` of the animation, rendered alone in its run (the range is
// that frame: its photons do not depend on the range).
Film animationFrame(const scene::SceneDescription& d, const RenderOptions& o, int frame, AnimationOptions ao = {},
                    AnimationStats* stats = nullptr) {
  auto s = Scene::build(d);
  ao.first = ao.last = frame;
  Film out(d.camera.width, d.camera.height);
  AnimationStats st = renderAnimation(*s, *d.animation, o, ao, Progress{}, [&](int, Film&& f, const RenderStats&) {
    out = std::move(f);
  });
  if (stats) *stats = st;
  return out;
}

test::MeanError overSeeds(int seeds, const std::function<double(uint64_t)>& run) {
  std::vector<double> v;
  for (uint64_t seed = 1; seed <= uint64_t(seeds); ++seed) v.push_back(run(seed));
  return test::overRuns(v);
}

double meanGreen(const Film& f) {
  double sum = 0;
  for (const Rgb& c : f.color) sum += c.g;
  return sum / double(f.color.size());
}

double combined(const test::MeanError& a, const test::MeanError& b) {
  return std::sqrt(a.error * a.error + b.error * b.error);
}

}  // namespace

TEST_CASE("animation in media: a frame equals the frame alone and the volumetric path trace of that frame") {
  // time with the camera moving a hair: the time-dependent form on the time
  // map with its pads; standard: the shutter's map.
  // The frames' own photons at the full count (--moving-photons 1: the
  // moving light leaves no photon to share), as many as the frame alone
  // traces: the kernels' bias depends on the count.
  AnimationOptions ao;
  ao.movingScale = 1;
  struct Case {
    bool timeDependent;
    int frame;  // 0: the timeline's first (its map clipped at 0); 2: an inner one, pads on both sides
  };
  for (Case c : {Case{true, 0}, Case{true, 2}, Case{false, 0}}) {
    const bool timeDependent = c.timeDependent;
    const int frame = c.frame;
    const RenderMethod method = timeDependent ? RenderMethod::Time : RenderMethod::Standard;
    const auto anim = fogAnimation(timeDependent);
    {
      const auto pt = overSeeds(3, [&](uint64_t seed) {
        return meanGreen(animationFrame(anim, fogOptions(RenderMethod::PathTrace, seed, 500), frame));
      });
      const auto seq = overSeeds(8, [&](uint64_t seed) {
        return meanGreen(animationFrame(anim, fogOptions(method, seed), frame, ao));
      });
      const auto alone = overSeeds(8, [&](uint64_t seed) {
        return meanGreen(test::renderOnce(fogFrameAlone(frame, timeDependent), fogOptions(method, seed + 100)));
      });
      INFO(std::string(renderMethodName(method)) << " frame " << frame << ": " << seq.mean << " +- " << seq.error
                                                 << ", alone " << alone.mean << " +- " << alone.error
                                                 << ", pathtrace " << pt.mean << " +- " << pt.error);
      CHECK(seq.error < 0.025 * pt.mean);
      // (a) the same estimate of the same light: within the spread (the
      // kernels differ only by the sequence's pads in time).
      CHECK(std::fabs(seq.mean - alone.mean) < 4 * combined(seq, alone) + 0.01 * alone.mean);
      // (b) the frame's truth, within the spread and the beam kernels' bias.
      CHECK(std::fabs(seq.mean - pt.mean) < 4 * combined(seq, pt) + 0.03 * pt.mean);
    }
  }
  // time with a still camera reads the skip rule's standard form from the
  // Time map's shutter copy: the same photons and kernels as standard's map.
  const auto still = fogAnimation(false);
  for (int frame : {0, 3})  // the first and the last (its map clipped at the timeline's end)
    CHECK(test::sameImage(animationFrame(still, fogOptions(RenderMethod::Time, 1), frame),
                          animationFrame(still, fogOptions(RenderMethod::Standard, 1), frame)));
}

TEST_CASE("animation in media: a block's shared volume photons keep the frame's image") {
  // A still light beside the eye ray and a small ball sliding far off it:
  // most volume photons miss the ball's sweep and are shared by the block.
  auto d = fogScene();
  d.lights[0].position = {1.5f, 0, 1};
  d.camera.shutterOpen = 0;
  d.camera.shutterClose = 1;
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  auto ball = test::sphere(0.2f, {0, 0, 0}, 0);
  ball.motion = test::translation({-3, 2, 3}, {-2, 2, 3});
  d.objects.push_back(ball);
  const auto pt = overSeeds(3, [&](uint64_t seed) {
    return meanGreen(animationFrame(d, fogOptions(RenderMethod::PathTrace, seed, 500), 1));
  });
  {
    const RenderMethod m = RenderMethod::Time;  // both its maps (standard's map is its shutter copy)
    AnimationOptions shared, own;
    own.sharedScale = 0;
    size_t sharedPhotons = 0;
    const auto withShared = overSeeds(4, [&](uint64_t seed) {
      AnimationStats st;
      double v = meanGreen(animationFrame(d, fogOptions(m, seed), 1, shared, &st));
      sharedPhotons = st.sharedPhotons;
      return v;
    });
    const auto without = overSeeds(4, [&](uint64_t seed) {
      return meanGreen(animationFrame(d, fogOptions(m, seed + 100), 1, own));
    });
    INFO(std::string(renderMethodName(m)) << ": shared " << withShared.mean << " +- " << withShared.error << ", not shared "
                             << without.mean << " +- " << without.error << ", pathtrace " << pt.mean << " +- "
                             << pt.error);
    CHECK(sharedPhotons > 10000);  // the volume photons were shared
    CHECK(std::fabs(withShared.mean - without.mean) < 4 * combined(withShared, without) + 0.01 * without.mean);
    CHECK(std::fabs(withShared.mean - pt.mean) < 4 * combined(withShared, pt) + 0.03 * pt.mean);
  }
}

TEST_CASE("animation in media: a progressive frame equals the frame alone in the same passes") {
  const auto anim = fogAnimation(false);
  {
    const RenderMethod m = RenderMethod::Time;
    auto passes = [&](uint64_t seed) {
      auto o = fogOptions(m, seed, 4);
      o.volumePhotons = 10000;
      o.volumeK = 32;  // the fixed-budget default (progressive takes --k's)
      o.progressive = true;
      o.passes = 2;
      return o;
    };
    const auto seq = overSeeds(3, [&](uint64_t seed) { return meanGreen(animationFrame(anim, passes(seed), 2)); });
    const auto alone = overSeeds(3, [&](uint64_t seed) {
      return meanGreen(test::renderOnce(fogFrameAlone(2, false), passes(seed + 100)));
    });
    INFO(std::string(renderMethodName(m)) << ": progressive frame " << seq.mean << " +- " << seq.error << ", alone " << alone.mean
                             << " +- " << alone.error);
    CHECK(seq.mean > 0);
    CHECK(std::fabs(seq.mean - alone.mean) < 4 * combined(seq, alone) + 0.01 * alone.mean);
  }
}

TEST_CASE("animation in media: the command line renders a fog animation with time and refuses accumulation") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/fog.json", R"({"animation": {"fps": 4, "frames": 2},
 "camera": {"position": [0, 0, 0], "target": [0, 0, 1], "fov": 20, "resolution": [4, 4]},
 "media": {"fog": {"type": "homogeneous", "sigma_a": 0.05, "sigma_s": 0.25}},
 "exterior_medium": "fog",
 "objects": [{"shape": {"type": "box", "size": [10, 10, 0.1]}, "transform": {"translate": [0, 0, 5]}}],
 "lights": [{"type": "point", "power": [100, 100, 100], "position": [0.7, 0, 0],
   "motion": [{"time": 0, "translate": [0, 0, 0]}, {"time": 0.5, "translate": [0, 0, 3]}]}]})");
  auto r = test::runTdpm("render '" + dir + "/fog.json' -o '" + dir + "/f_####.exr' -q -m time --spp 2 "
                         "--volume-photons 2000 --frame-range 0-1");
  INFO(r.output);
  CHECK(r.exitCode == 0);
  CHECK(test::fileExists(dir + "/f_0000.exr"));
  CHECK(test::fileExists(dir + "/f_0001.exr"));
  auto bad = test::runTdpm("render '" + dir + "/fog.json' -o '" + dir + "/g_####.exr' -q -m accumulation --spp 2 "
                           "--frame-range 0-1");
  CHECK(bad.exitCode != 0);
  CHECK(bad.output.find("cannot render an animation") != std::string::npos);
  CHECK_FALSE(test::fileExists(dir + "/g_0000.exr"));
}
