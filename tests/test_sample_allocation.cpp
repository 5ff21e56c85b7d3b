// tests/test_sample_allocation.cpp — progressive passes with per-pixel eye
// sample counts from an eye-only pilot (render/sample_allocation.h): the
// allocation's bounds and proportionality, the same mean as passes of spp
// samples everywhere (unbiased), the real counts in the film, and the
// determinism guarantees (threads, N + N resumed == 2N).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "render/progressive.h"
#include "render/renderer.h"
#include "render/sample_allocation.h"
#include "moving_plane.h"
#include "progressive_checks.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

// A small area light reflected and refracted by a glass ball that moves
// across the view over the shutter, above a diffuse floor: the highlight on
// the ball is a rare eye path (E S+ L) in the pixels it sweeps.
scene::SceneDescription glassHighlight(int w, int h) {
  auto d = test::emptyScene(w, h);
  d.camera.position = {0, 1.3f, 1.8f};
  d.camera.target = {0, 0.35f, 0};
  d.camera.fovDegrees = 32;
  d.background = Rgb(0.05f);
  d.materials.push_back(test::diffuse(Rgb(0.6f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  glass.ior = 1.5f;
  d.materials.push_back(glass);
  d.objects.push_back(test::quad({4, 4}, {0, 0, 0}, 0));
  auto ball = test::sphere(0.3f, {0, 0.4f, 0}, 1);
  ball.motion = test::translation({-0.3f, 0, 0}, {0.3f, 0, 0});
  d.objects.push_back(ball);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaSize = {0.5f, 0.5f};
  l.power = Rgb(30.0f);
  l.placement.translate = {0.2f, 1.6f, 0.5f};
  d.lights.push_back(l);
  return d;
}

RenderOptions glassOptions(float extra) {
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.progressive = true;
  o.spp = 2;
  o.seed = 9;
  o.causticPhotons = 2000;
  o.globalPhotons = 500;
  o.passExtraSamples = extra;
  o.passSampleCap = 8;
  return o;
}


}  // namespace

TEST_CASE("sample allocation: within spp..cap x spp, within the budget, proportional to the noise between") {
  std::vector<float> noise = {0, 0, 0.5f, 1, 2, 4, 8, 100, 0, 0};
  const int spp = 4, cap = 8;
  // No budget, no cap: spp everywhere.
  for (uint32_t m : allocatePassSamples(noise, spp, cap, 0.0)) CHECK(m == 4u);
  for (uint32_t m : allocatePassSamples(noise, spp, 1, 0.5)) CHECK(m == 4u);
  for (double budget : {0.1, 0.5, 1.0, 3.0}) {
    CAPTURE(budget);
    std::vector<uint32_t> m = allocatePassSamples(noise, spp, cap, budget);
    double extra = 0;
    for (size_t i = 0; i < m.size(); ++i) {
      CHECK(m[i] >= 4u);
      CHECK(m[i] <= 32u);
      extra += double(m[i]) - spp;
      if (noise[i] == 0) CHECK(m[i] == 4u);
      if (i > 0) CHECK((noise[i] < noise[i - 1] || m[i] >= m[i - 1]));  // more noise, never fewer
    }
    CHECK(extra <= budget * spp * double(noise.size()));
    // Most of the budget is used (ceil rounding leaves at most a sample a
    // pixel), unless every noisy pixel is at the cap.
    bool allCapped = true;
    for (size_t i = 0; i < m.size(); ++i) allCapped = allCapped && (noise[i] == 0 || m[i] == 32u);
    if (!allCapped) CHECK(extra > budget * spp * double(noise.size()) - double(noise.size()));
  }
  // Between the bounds the counts follow the noise: 2 against 1 is ~2x.
  std::vector<uint32_t> m = allocatePassSamples(noise, spp, cap, 1.0);
  CHECK(m[7] == 32u);
  CHECK(double(m[5]) / double(m[4]) == doctest::Approx(2.0).epsilon(0.25));
  // A budget the cap cannot spend: every noisy pixel at the cap.
  m = allocatePassSamples(noise, spp, cap, 60.0);
  for (size_t i = 0; i < m.size(); ++i) CHECK(m[i] == (noise[i] > 0 ? 32u : 4u));
}

TEST_CASE("sample allocation: the pilot finds the swept glass ball, not the far floor") {
  auto s = Scene::build(glassHighlight(48, 32));
  RenderOptions o = glassOptions(0.5f);
  std::vector<float> noise = pilotNoise(*s, o, Progress{});
  std::vector<uint32_t> m = passSampleCounts(*s, o, Progress{});
  REQUIRE(m.size() == size_t(48 * 32));
  // The same map again (a function of scene, options and seed), and
  // another with another seed.
  CHECK(passSampleCounts(*s, o, Progress{}) == m);
  // Where the ball is seen (its swept band around the image centre) the
  // counts are above spp; far corners of the floor keep spp.
  uint32_t centreMax = 0;
  for (int y = 8; y < 24; ++y)
    for (int x = 12; x < 36; ++x) centreMax = std::max(centreMax, m[size_t(y) * 48 + size_t(x)]);
  CHECK(centreMax > 2u);
  CHECK(m[0] == 2u);
  CHECK(m[size_t(31) * 48 + 47] == 2u);
  double extra = 0;
  for (uint32_t c : m) extra += double(c) - 2.0;
  CHECK(extra <= 0.5 * 2 * double(m.size()));
  CHECK(extra > 0.25 * 2 * double(m.size()));
  o.passExtraSamples = 0;
  CHECK(passSampleCounts(*s, o, Progress{}).empty());
}

TEST_CASE("sample allocation: the adaptive passes have the mean of passes with spp everywhere (unbiased)") {
  // Eye paths alone (no photons, no gather): pixels are independent, so the
  // variance layers give the standard error of the image's mean.
  auto s = Scene::build(glassHighlight(24, 16));
  auto meanAndVar = [&](float extra, uint64_t seed, Film& f) {
    RenderOptions o = glassOptions(extra);
    o.seed = seed;
    o.causticPhotons = 0;
    o.globalPhotons = 0;
    o.gatherRays = 0;
    o.passes = 24;
    ProgressiveState state;
    RenderStats st;
    f = renderProgressive(*s, o, state, Progress{}, st);
    double m = 0, v = 0, n = double(f.color.size());
    for (size_t i = 0; i < f.color.size(); ++i) {
      m += double(f.color[i].luminance()) / n;
      v += double(f.varianceOfMean[i].luminance()) / (n * n);  // luminance weights < 1 on each: a bound
    }
    return std::pair<double, double>(m, v);
  };
  Film plain, adaptive;
  auto [m0, v0] = meanAndVar(0.0f, 21, plain);
  auto [m1, v1] = meanAndVar(0.5f, 22, adaptive);
  double z = (m1 - m0) / std::sqrt(v0 + v1);
  MESSAGE("image mean: spp everywhere " << m0 << ", adaptive " << m1 << ", z " << z);
  CHECK(std::fabs(z) < 4.0);
  // The film's counts are the real ones: 24 passes x m_p.
  float lo = *std::min_element(adaptive.sampleCount.begin(), adaptive.sampleCount.end());
  float hi = *std::max_element(adaptive.sampleCount.begin(), adaptive.sampleCount.end());
  CHECK(lo == 48.0f);
  CHECK(hi > 48.0f);
  CHECK(hi <= 24.0f * 16.0f);
  for (float c : adaptive.sampleCount) CHECK(std::fmod(c, 24.0f) == 0.0f);  // the same count every pass
  double total = std::accumulate(adaptive.sampleCount.begin(), adaptive.sampleCount.end(), 0.0);
  CHECK(total <= 1.5 * 48.0 * double(adaptive.sampleCount.size()));
  for (float c : plain.sampleCount) CHECK(c == 48.0f);
  // Where the extra samples went, the noise fell: the mean variance of the
  // pixels that took more than spp is lower than with spp there.
  double vPlain = 0, vAdaptive = 0;
  for (size_t i = 0; i < adaptive.sampleCount.size(); ++i)
    if (adaptive.sampleCount[i] > 48.0f) {
      vPlain += plain.varianceOfMean[i].luminance();
      vAdaptive += adaptive.varianceOfMean[i].luminance();
    }
  MESSAGE("variance where m_p > spp: spp everywhere " << vPlain << ", adaptive " << vAdaptive);
  CHECK(vPlain > 0);
  CHECK(vAdaptive < 0.6 * vPlain);
}

TEST_CASE("sample allocation: with photons and final gather, the eye part over m_p samples and the rest over spp "
          "keep the mean") {
  // Same seed in a pair: the same photons and kernels, the same first spp
  // samples; the images differ by the eye part's extra samples only, whose
  // difference has mean 0 when the split is unbiased. Over independent
  // seeds the differences' t statistic stays small.
  auto s = Scene::build(glassHighlight(24, 16));
  const int seeds = 16;
  std::vector<double> diffs;
  for (int k = 0; k < seeds; ++k) {
    double means[2] = {0, 0};
    for (int a = 0; a < 2; ++a) {
      RenderOptions o = glassOptions(a ? 1.0f : 0.0f);
      o.seed = uint64_t(40 + k);
      o.passes = 4;
      ProgressiveState state;
      RenderStats st;
      Film f = renderProgressive(*s, o, state, Progress{}, st);
      for (const Rgb& c : f.color) means[a] += double(c.luminance()) / double(f.color.size());
      if (a) CHECK(st.maxSpp > 4 * o.spp);
    }
    diffs.push_back(means[1] - means[0]);
  }
  double m = 0, v = 0;
  for (double d : diffs) m += d / seeds;
  for (double d : diffs) v += (d - m) * (d - m) / (seeds - 1);
  REQUIRE(v > 0);  // the extra samples change the image
  double t = m / std::sqrt(v / seeds);
  MESSAGE("adaptive - plain image mean over " << seeds << " seeds: " << m << ", t " << t);
  // t with 15 degrees of freedom: |t| > 4 has p ~ 0.001. Dropping the
  // emission seen through glass from the extra samples (a biased split)
  // gives t = -4.4 here.
  CHECK(std::fabs(t) < 4.0);
}

TEST_CASE("sample allocation: adaptive passes on the moving plane converge to the analytic value") {
  // The plane's direct light varies with the plane's distance over the
  // shutter: a little eye-side noise everywhere, photons seen directly.
  auto s = Scene::build(test::movingPlaneScene(8));
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.progressive = true;
  o.spp = 2;
  o.seed = 31;
  o.causticPhotons = 0;
  o.globalPhotons = 4000;
  o.visualizeGlobal = true;
  o.estimate.k = 50;
  o.estimate.ks = 50;
  o.estimate.maxRadius = 1.0f;
  o.passExtraSamples = 0.5f;
  o.passes = 16;
  ProgressiveState state;
  RenderStats st;
  Film f = renderProgressive(*s, o, state, Progress{}, st);
  double got = 0, want = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      got += f.color[f.index(x, y)].r;
      want += test::movingPlanePixel(s->camera, Shutter{0, 1}, x, y);
    }
  MESSAGE("moving plane, adaptive passes: ratio to the analytic value " << got / want);
  CHECK(got / want == doctest::Approx(1.0).epsilon(0.03));
}

TEST_CASE("sample allocation: N passes continued for N more equal 2N, for 1 and 2 threads, both samplers") {
  auto s = Scene::build(glassHighlight(24, 16));
  for (SamplerKind kind : {SamplerKind::Sobol, SamplerKind::Random}) {
    CAPTURE(samplerName(kind));
    RenderOptions o = glassOptions(0.5f);
    o.sampler = kind;
    RenderStats st;
    ProgressiveState whole = test::checkResumeAndThreads(*s, o, st);  // resume recomputes the map
    CHECK(st.maxSpp > 4 * o.spp);  // the map is in use
    // The map changes the image (the check can fail).
    ProgressiveState plain;
    o.passes = 4;
    o.passExtraSamples = 0;
    renderProgressive(*s, o, plain, Progress{}, st);
    CHECK_FALSE(test::sameState(whole, plain));
  }
}
