// tests/test_media_progressive.cpp — progressive passes of the photon
// methods in participating media (issue 25): each pass's Fixed beam map
// read by the eye (render/photon_integrator_media.cpp) and averaged over the
// passes (render/progressive.cpp). A fog scene without motion (the whole
// shutter on shrinking discs) and one with a light and a wall moving (the
// pass's time windows): against volumetric pathtrace, the error over seeds
// after 8 passes below that after 2 and the mean's bias falling (moving),
// the mean within 2% + 4 standard errors after 8 (both; see the case)
// against a reference of 32 path-traced seeds;
// 4 passes equal 2 + 2 continued and the same on one thread; and
// through the CLI, a render resumed from its EXR equals the uninterrupted one.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "image/exr.h"
#include "airlight_scene.h"
#include "progressive_checks.h"
#include "render/progressive.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

// The airlight scene of test_media_photon_methods.cpp with a grey wall:
// camera at the origin looking along +z, the wall at z = D, a point light
// at (h, 0, x0), fog everywhere (multiple scattering, final gather).
scene::SceneDescription fogScene(bool moving) {
  const float I = 10, sa = 0.05f, ss = 0.25f, x0 = 2, h = 0.7f, D = 5;
  auto d = test::airlightScene(I, sa, ss, x0, h, D);
  d.materials[0] = test::diffuse(Rgb(0.5f));
  if (moving) {  // the light along the ray, the wall behind it (the moving test there)
    d.lights[0].position = {0, 0, 0};
    d.lights[0].motion = test::translation({h, 0, 0.5f}, {h, 0, 4.0f});
    d.objects[0].placement.translate = {0, 0, 0};
    d.objects[0].motion = test::translation({0, 0, 2.005f}, {0, 0, 5.505f});
  }
  return d;
}

// The volumetric path trace of the one pixel, averaged over 32 seeds of
// 40,000 samples (2 s). One render is not a reference here: next-event
// estimation at a path's second medium vertex, drawn anywhere near the
// point light, carries I / d^2, whose tail P(V > v) ~ v^(-3/2) has no
// variance, so a render now and then lands far above the rest (still scene:
// seed 3 gave 0.575 against 0.548 +- 0.003 over seeds 1-16 and
// 0.5481 +- 0.0012 over 64 seeds of 100,000; moving: seed 1 gave 0.829
// against 0.64-0.71 for seeds 2-16; docs/media.md "Progressive passes in media").
test::MeanError pathtraceReference(const Scene& s) {
  const int seeds = 32;
  std::vector<double> v;
  RenderStats st;
  for (int seed = 1; seed <= seeds; ++seed)
    v.push_back(render(s, test::smallRenderOptions(RenderMethod::PathTrace, 40000, 8, uint64_t(seed)), Progress{}, st)
                    .color[0]
                    .g);
  return test::overRuns(v);
}

RenderOptions passOptions(uint64_t seed) {
  RenderOptions o = test::smallRenderOptions(RenderMethod::Time, 16, 8, seed);
  o.progressive = true;
  o.causticPhotons = 2000;
  o.volumePhotons = 20000;
  o.globalPhotons = 10000;
  o.gatherRays = 8;
  o.passExtraSamples = 0;
  return o;
}

}  // namespace

TEST_CASE("media progressive: time passes converge to pathtrace, with and without motion") {
  for (bool moving : {false, true}) {
    CAPTURE(moving);
    auto d = fogScene(moving);
    auto s = Scene::build(d);
    REQUIRE(s->hasMedia());
    REQUIRE(s->hasMotion == moving);
    RenderStats st;
    const test::MeanError ref = pathtraceReference(*s);
    const int seeds = 8;
    std::vector<double> at2, at8;
    for (int seed = 1; seed <= seeds; ++seed) {
      RenderOptions o = passOptions(uint64_t(seed));
      ProgressiveState state;
      o.passes = 2;
      at2.push_back(renderProgressive(*s, o, state, Progress{}, st).color[0].g);
      o.passes = 8;  // the same state continued
      at8.push_back(renderProgressive(*s, o, state, Progress{}, st).color[0].g);
    }
    double mse2 = 0, mse8 = 0, mean2 = 0, mean8 = 0;
    for (int i = 0; i < seeds; ++i) {
      mse2 += (at2[size_t(i)] - ref.mean) * (at2[size_t(i)] - ref.mean) / seeds;
      mse8 += (at8[size_t(i)] - ref.mean) * (at8[size_t(i)] - ref.mean) / seeds;
      mean2 += at2[size_t(i)] / seeds;
      mean8 += at8[size_t(i)] / seeds;
    }
    double var8 = 0;
    for (double v : at8) var8 += (v - mean8) * (v - mean8) / (seeds - 1);
    const double se8 = std::sqrt(var8 / seeds);
    MESSAGE((moving ? "moving" : "still") << ": pathtrace " << ref.mean << " +- " << ref.error << "; rms error 2 passes "
                                          << std::sqrt(mse2) / ref.mean << ", 8 passes " << std::sqrt(mse8) / ref.mean
                                          << "; mean at 2 " << mean2 << ", at 8 " << mean8 << " +- " << se8);
    // Each pass's beam map is its own photons' k-NN kernel, shrunk by the
    // schedule (render/progressive.cpp volumePassBeam). Measured (8 seeds,
    // against the 16-seed reference): still +0.6% at 2 passes, +0.3% at 8;
    // moving +2.7% at 2, +1.3% at 8. The "still 4.5% low" of earlier stops was
    // the one-seed reference's (seed 3, 0.575: +4.9% over the 16 seeds'
    // 0.548); a bound of 2% fails against it.
    // The moving case's bias falling from 2 to 8 passes (2.0% to 0.6% against
    // the old one-seed reference) is below what this reference resolves (its
    // standard error is ~1%), so only the error's fall is checked there.
    const double bound = 4 * std::sqrt(se8 * se8 + ref.error * ref.error) + 0.02 * ref.mean;
    CHECK(std::fabs(mean8 - ref.mean) < bound);
    if (moving) CHECK(mse8 < 0.7 * mse2);
  }
}

TEST_CASE("media progressive: 4 passes equal 2 + 2 continued and on one thread") {
  auto s = Scene::build(fogScene(true));
  RenderOptions o = passOptions(7);
  o.volumePhotons = 4000;
  o.globalPhotons = 2000;
  RenderStats st;
  ProgressiveState whole = test::checkResumeAndThreads(*s, o, st);
  CHECK(whole.passesDone == 4);
  CHECK(whole.pilot.maps[MapKind::Volume].radius > 0);
  CHECK(whole.pilot.maps[MapKind::Volume].pathsPerPass > 0);
}

TEST_CASE("media progressive: a render resumed from its EXR equals the uninterrupted one, bit for bit") {
  std::string dir = test::makeTempDir();
  const std::string base = "render '" + std::string(TDPM_SOURCE_DIR) +
                           "/scenes/fog-glass-ball.json' -m time --progressive --resolution 16x12 --spp 1 "
                           "--photons 2000 --global-photons 1000 --volume-photons 3000 -q --seed 5 ";
  test::CommandResult full = test::runTdpm(base + "-t 2 --passes 4 -o " + dir + "/full.exr");
  REQUIRE_MESSAGE(full.exitCode == 0, full.output);
  test::CommandResult half = test::runTdpm(base + "-t 1 --passes 2 -o " + dir + "/part.exr");
  REQUIRE_MESSAGE(half.exitCode == 0, half.output);
  image::ExrFile two = image::readExr(dir + "/part.exr");
  // The volume map's pass-1 kernel is in the state (else resume could not
  // rebuild the passes' beam maps).
  bool volumeKernel = false;
  for (const auto& [key, value] : two.metadata) volumeKernel = volumeKernel || key.find("kernel.volume.radius_1") != std::string::npos;
  CHECK(volumeKernel);
  test::CommandResult more = test::runTdpm(base + "-t 2 --passes 4 --resume " + dir + "/part.exr -o " + dir + "/part.exr");
  REQUIRE_MESSAGE(more.exitCode == 0, more.output);
  image::ExrFile a = image::readExr(dir + "/full.exr"), b = image::readExr(dir + "/part.exr");
  REQUIRE(a.color.pixels.size() == b.color.pixels.size());
  CHECK(std::memcmp(a.color.pixels.data(), b.color.pixels.data(), a.color.pixels.size() * sizeof(Rgb)) == 0);
  CHECK(b.metadata["tdpm/progressive/passes"] == "4");
  // ... and the comparison can fail: 2 passes are another image.
  CHECK(std::memcmp(a.color.pixels.data(), two.color.pixels.data(), a.color.pixels.size() * sizeof(Rgb)) != 0);
  std::system(("rm -rf '" + dir + "'").c_str());
}
