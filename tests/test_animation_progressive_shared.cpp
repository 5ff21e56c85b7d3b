// tests/test_animation_progressive_shared.cpp — progressive animation
// frames sharing each pass's time-invariant photons over a block of frames
// (issue 26, docs/animation.md "Progressive frames sharing time-invariant
// photons"): a shared frame agrees with the same frame rendered
// progressively alone (a shadow sweeping over a still floor), converges
// (4x the passes, lower error against the analytic still plane under a
// moving speck), and resumes bit for bit, also with the frames of a block
// at different pass counts; the fingerprint names the sharing.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "render/animation.h"
#include "render/fingerprint.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "moving_plane.h"
#include "render_fixtures.h"
#include "scene_fixtures.h"
#include "seed_stats.h"
#include "shadow_sweep.h"

using namespace tdpm;
using test::meanRed;
using test::overSeeds;

namespace {

RenderOptions sweepOptions(uint64_t seed, int passes) {
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.progressive = true;
  o.passes = passes;
  o.spp = 2;
  o.seed = seed;
  o.causticPhotons = 0;
  o.globalPhotons = 10000;  // per pass
  o.visualizeGlobal = true;
  o.estimate.k = 60;
  o.estimate.ks = 60;
  o.estimate.maxRadius = 0.5f;
  return o;
}

AnimationOptions frames(int first, int last, int window, double shared, double moving) {
  AnimationOptions ao;
  ao.first = first;
  ao.last = last;
  ao.window = window;
  ao.sharedScale = shared;
  ao.movingScale = moving;
  return ao;
}

struct Sequence {
  std::map<int, Film> films;
  std::map<int, ProgressiveState> states;
  AnimationStats all;
};

Sequence render(const Scene& s, const scene::AnimationDesc& a, const RenderOptions& o, AnimationOptions ao,
                const std::map<int, ProgressiveState>* from = nullptr) {
  Sequence q;
  if (from)
    ao.startState = [from](int i, const RenderOptions&) {
      auto it = from->find(i);
      return it == from->end() ? ProgressiveState{} : it->second;
    };
  ao.keepState = [&](int i, ProgressiveState&& st) { q.states[i] = std::move(st); };
  q.all = renderAnimation(s, a, o, ao, Progress{}, [&](int i, Film&& f, const RenderStats&) { q.films[i] = std::move(f); });
  return q;
}


// Colour (tests/render_fixtures.h) and the variance layer, bit for bit.
bool samePixels(const Film& a, const Film& b) {
  return test::sameImage(a, b) &&
         std::memcmp(a.varianceOfMean.data(), b.varianceOfMean.data(), a.varianceOfMean.size() * sizeof(Rgb)) == 0;
}

}  // namespace

TEST_CASE("progressive shared frames: the floor under a sweeping shadow matches the frame rendered progressively alone") {
  // Frame 1 of the shadow sweep in 4 passes, its block frames 0-1, 6 seeds:
  // shared (the block's invariant photons, frames continuing the paths that
  // meet the slab) at --shared-photons = --moving-photons = c against the
  // frame alone with c x the photons (c = 1, and the defaults 0.5: each
  // pass then holds half a frame's photons, and the passes' kernels, sized
  // on them, are wider: the frame alone at 10000 photons reads the strip
  // 9% brighter than at 5000, the same 4 passes); the whole floor and the
  // band the shadow crosses within four standard errors of the difference
  // plus 1%.
  auto d = test::shadowSweep(16);
  auto s = Scene::build(d);
  const double scales[2] = {1.0, 0.5};
  for (double c : scales) {
    std::vector<double> all[2], strip[2];
    for (uint64_t seed = 1; seed <= 6; ++seed)
      for (int v = 0; v < 2; ++v) {
        RenderOptions o = sweepOptions(seed, 4);
        if (v == 1) o.globalPhotons = size_t(double(o.globalPhotons) * c);
        Sequence q = render(*s, *d.animation, o, frames(1, 1, 2, v == 0 ? c : 0.0, c));
        REQUIRE(q.films.count(1) == 1);
        if (v == 1) {
          CHECK(q.all.sharedSets == 0);
        } else {
          CHECK(q.all.sharedSets == 4);  // one per pass
          CHECK(q.all.sharedPhotons > 0);
          CHECK(q.all.continuedPaths > 0);
        }
        CHECK(q.states[1].passesDone == 4);
        all[v].push_back(meanRed(q.films[1], 0, 0, 16, 16));
        strip[v].push_back(meanRed(q.films[1], 0, 6, 16, 10));  // rows 6-10: where the slab's shadow crosses
      }
    for (auto [x, y, what] : {std::tuple{overSeeds(all[0]), overSeeds(all[1]), std::string("floor")},
                              std::tuple{overSeeds(strip[0]), overSeeds(strip[1]), std::string("shadow strip")}}) {
      double se = std::sqrt(x.se * x.se + y.se * y.se);
      MESSAGE(what << " (shared = moving = " << c << "): shared " << x.mean << " +- " << x.se << ", alone " << y.mean
                   << " +- " << y.se);
      CHECK(std::fabs(x.mean - y.mean) <= 4.0 * se + 0.01 * y.mean);
    }
  }
}

TEST_CASE("progressive shared frames converge: 4x the passes, lower error against the still plane's analytic value") {
  // The still plane under a moving speck: every photon is time-invariant,
  // so the frames' passes read the block's shared photons alone (scaled to
  // the frame's shutter); frame 1 of block 0-1.
  auto d = test::stillPlaneUnderSpeck(8);
  auto s = Scene::build(d);
  std::vector<double> want;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) want.push_back(test::movingPlanePixel(s->camera, s->shutter, x, y, 0.0f, 0.0f, 1));
  auto errors = [&](int passes, uint64_t seed, double& mse, double& mean) {
    RenderOptions o = test::movingPlaneFrameOptions(seed);
    o.progressive = true;
    o.passes = passes;
    o.spp = 2;
    o.globalPhotons = 5000;  // per pass
    Sequence q = render(*s, *d.animation, o, frames(0, 1, 2, 0.5, 0.5));
    REQUIRE(q.films.size() == 2);
    CHECK(q.all.sharedSets == uint64_t(passes));
    const Film& f = q.films[1];
    mse = mean = 0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        double v = f.color[f.index(x, y)].r, w = want[size_t(y * 8 + x)];
        mse += (v - w) * (v - w) / 64.0;
        mean += v / w / 64.0;
      }
  };
  for (uint64_t seed : {3u, 4u}) {
    double e1, m1, e4, m4;
    errors(2, seed, e1, m1);
    errors(8, seed, e4, m4);
    MESSAGE("seed " << seed << ": MSE at 2 passes " << e1 << " (mean / analytic " << m1 << "), at 8 passes " << e4
                    << " (" << m4 << ")");
    CHECK(e4 < e1);
    // The kernels' bias (low: the plane's light falls off away from the
    // view's centre) shrinks with them.
    CHECK(std::fabs(m4 - 1.0) < std::fabs(m1 - 1.0));
    CHECK(std::fabs(m4 - 1.0) < 0.05);
  }
}

TEST_CASE("progressive shared frames resume bit for bit, also with a block's frames at different pass counts") {
  // Shadow sweep frames 0-2 (one block of --window 4) in 4 passes, and the
  // same from states of 2 passes (frames 0, 2) and 1 pass (frame 1): the
  // block's pass j set is the same whichever frames need it, so every
  // frame's pixels and variance equal the uninterrupted run's. A run of
  // frames 1-2 alone (another range) gives the same frames too.
  auto d = test::shadowSweep(12);
  auto s = Scene::build(d);
  const AnimationOptions ao = frames(0, 2, 4, 0.5, 0.5);
  Sequence full = render(*s, *d.animation, sweepOptions(9, 4), ao);
  Sequence two = render(*s, *d.animation, sweepOptions(9, 2), ao);
  Sequence one = render(*s, *d.animation, sweepOptions(9, 1), frames(1, 1, 4, 0.5, 0.5));
  std::map<int, ProgressiveState> from{{0, two.states[0]}, {1, one.states[1]}, {2, two.states[2]}};
  Sequence resumed = render(*s, *d.animation, sweepOptions(9, 4), ao, &from);
  REQUIRE(full.films.size() == 3);
  REQUIRE(resumed.films.size() == 3);
  CHECK(resumed.all.passesDone == 2 + 3 + 2);
  CHECK(resumed.all.sharedSets == 3);  // passes 1, 2, 3: frame 1 alone at pass 1
  for (int i = 0; i < 3; ++i) {
    CHECK(resumed.states[i].passesDone == 4);
    CHECK(samePixels(full.films[i], resumed.films[i]));
  }
  Sequence later = render(*s, *d.animation, sweepOptions(9, 4), frames(1, 2, 4, 0.5, 0.5));
  for (int i = 1; i < 3; ++i) CHECK(samePixels(full.films[i], later.films[i]));
  // A finished state is skipped: nothing traced, nothing rendered.
  Sequence again = render(*s, *d.animation, sweepOptions(9, 4), ao, &full.states);
  CHECK(again.films.empty());
  CHECK(again.all.framesSkipped == 3);
  CHECK(again.all.sharedSets == 0);
}

TEST_CASE("progressive shared frames: the fingerprint's settings name the block and the scales, only when sharing") {
  auto d = test::shadowSweep(8);
  auto s = Scene::build(d);
  const RenderOptions o = sweepOptions(1, 2);
  auto settingsOf = [&](const AnimationOptions& ao, int frame) {
    return renderSettings(progressiveFrameOptions(*s, *d.animation, o, ao, frame), 8, 8);
  };
  auto shared = settingsOf(frames(0, 3, 2, 0.5, 0.25), 3);
  REQUIRE(shared.count("frame_sharing") == 1);
  CHECK(shared["frame_sharing"] == "frames 2-3 (window 2), shared 0.5, moving 0.25, continued");
  CHECK(shared.count("frame_shutter") == 1);
  CHECK(settingsOf(frames(0, 3, 2, 0.0, 0.5), 3).count("frame_sharing") == 0);
  CHECK(settingsOf(frames(0, 3, 4, 0.5, 0.25), 3)["frame_sharing"] != shared["frame_sharing"]);
}
