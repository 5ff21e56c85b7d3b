// tests/test_animation_continue.cpp — frames continuing the block pass's
// photon paths that meet motion (docs/animation.md section 8): the
// continued photons of a frame segment against the analytic irradiance
// behind a moving occluder and against the same segment traced in full from
// the light, the split between shared and continued photons (no shared
// photon behind the occluder), and a frame rendered with continuation
// against the same frame without it.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "photon/tracer.h"
#include "render/animation.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene_fixtures.h"
#include "shadow_sweep.h"

using namespace tdpm;

namespace {

constexpr Vec3f kLight = test::kSweepLight;  // tests/shadow_sweep.h
constexpr float kPower = test::kSweepPower;

using test::shadowSweep;  // tests/shadow_sweep.h

// The floor rectangle R the test reads: x in [-2, -0.8], z in [-0.4, 0.4].
// Every light -> R segment crosses the slab's swept bounds over the block
// [0, 0.375] s (the slab's x from -1.45 to -0.05), so its direct light is
// all time-dependent; during frame 1's shutter [0.25, 0.375] the shadow's
// left edge sweeps across it (from x = -1.73 to -1.12), and x > -1.12 is
// in shadow all along.
constexpr float kRx0 = -2.0f, kRx1 = -0.8f, kRz0 = -0.4f, kRz1 = 0.4f;
bool inR(Vec3f p) { return std::fabs(p.y) < 1e-3f && p.x >= kRx0 && p.x < kRx1 && p.z >= kRz0 && p.z < kRz1; }

// Whether the slab, centred at x = xc, blocks the segment light -> p.
bool slabBlocks(float xc, Vec3f p) {
  Bounds3f b;
  b.lo = {xc - 0.25f, 1.475f, -0.25f};
  b.hi = {xc + 0.25f, 1.525f, 0.25f};
  Vec3f d = p - kLight;
  float len = length(d);
  d = d / len;
  return b.intersectsSegment(kLight, Vec3f{1.0f / d.x, 1.0f / d.y, 1.0f / d.z}, 0.0f, len);
}

// Direct energy reaching R during [a, b]: the integral over time and R of
// I cos / r^2 where the slab does not block the light (midpoint rule, 120 x
// 80 points x 64 times).
double analyticDirect(float a, float b) {
  const double intensity = kPower / (4.0 * kPi);
  const int nx = 120, nz = 80, nt = 64;
  const double dx = (kRx1 - kRx0) / nx, dz = (kRz1 - kRz0) / nz, dt = (b - a) / double(nt);
  double e = 0;
  for (int it = 0; it < nt; ++it) {
    const float t = a + float((it + 0.5) * dt);
    const float xc = -1.2f + 2.4f * t;
    for (int ix = 0; ix < nx; ++ix)
      for (int iz = 0; iz < nz; ++iz) {
        Vec3f p{kRx0 + float((ix + 0.5) * dx), 0.0f, kRz0 + float((iz + 0.5) * dz)};
        if (slabBlocks(xc, p)) continue;
        double r2 = lengthSquared(p - kLight);
        e += intensity * (3.0 / std::sqrt(r2)) / r2 * dx * dz * dt;
      }
  }
  return e;
}

// The direct photons in R (on the floor, arriving straight from the light):
// their energy and its standard error (photons are independent paths).
struct Tally {
  double energy = 0, se = 0;
  size_t count = 0;
};
Tally direct(const photon::PhotonStore& st) {
  Tally t;
  double sq = 0;
  for (size_t i = 0; i < st.size(); ++i) {
    Vec3f p = st.position(i);
    if (!inR(p) || dot(st.direction(i), normalize(kLight - p)) < 0.999f) continue;
    double q = st.energy(i).r;
    t.energy += q;
    sq += q * q;
    ++t.count;
  }
  t.se = std::sqrt(sq);
  return t;
}

photon::TraceSettings settings(photon::InvariantPhotons mode, const photon::MotionBounds& motion, float t0, float t1,
                               uint64_t seed, SamplerKind sampler) {
  photon::TraceSettings ts;
  ts.kind = MapKind::Global;
  ts.storedWanted = 40000;
  ts.seed = seed;
  ts.sampler = sampler;
  ts.timeOpen = t0;
  ts.timeClose = t1;
  ts.invariant = mode;
  ts.motion = &motion;
  return ts;
}

}  // namespace

TEST_CASE("continued photon paths: a frame's photons behind a moving occluder, against analytic and the full trace") {
  auto d = shadowSweep(8);
  auto s = Scene::build(d);
  const photon::MotionBounds motion = photon::motionBoundsOver(*s, 0.0f, 0.375f);
  REQUIRE(motion.boxes.size() == 1);
  const float a = 0.25f, b = 0.375f;  // frame 1's shutter
  const double want = analyticDirect(a, b);
  const double unshadowed = [&] {
    double e = 0;
    const double intensity = kPower / (4.0 * kPi);
    for (int ix = 0; ix < 120; ++ix)
      for (int iz = 0; iz < 80; ++iz) {
        Vec3f p{kRx0 + (ix + 0.5f) * 0.01f, 0.0f, kRz0 + (iz + 0.5f) * 0.01f};
        double r2 = lengthSquared(p - kLight);
        e += intensity * (3.0 / std::sqrt(r2)) / r2 * 1e-4 * double(b - a);
      }
    return e;
  }();
  MESSAGE("analytic direct energy on R in frame 1: " << want << " (unshadowed " << unshadowed << ")");
  CHECK(want < 0.9 * unshadowed);  // the shadow does cross R during the frame
  CHECK(want > 0.3 * unshadowed);
  for (SamplerKind sampler : {SamplerKind::Sobol, SamplerKind::Random})
    for (double reuse : {1.0, 3.0}) {
      // 4 seeds pooled: each a block pass over frames 0-1's time (invariant
      // photons, and the states of the paths that meet the sweep), frame
      // 1's shutter traced in full from the light (photons of paths that
      // meet motion), and the block's paths continued over that shutter
      // with reuse x the block's paths (3: every block path continued three
      // times, at three times, rounds 0-2).
      Tally full, cont;
      uint64_t continued = 0;
      for (uint64_t seed = 1; seed <= 4; ++seed) {
        photon::TraceSettings block = settings(photon::InvariantPhotons::Only, motion, 0.0f, 0.375f, 10 + seed, sampler);
        block.keepMoving = true;
        photon::SegmentStore whole;
        whole.storeT0 = 0.0f;
        whole.storeT1 = 0.375f;
        whole.storedPerPath = 0.6;
        photon::TraceResult shared = photon::traceSegmentPhotons(*s, block, whole, Progress{});
        REQUIRE(shared.kept.emitted == shared.emitted);
        REQUIRE(!shared.kept.states.empty());
        // No shared photon is in R: every path to it crosses the sweep.
        CHECK(direct(shared.store).count == 0);
        bool ordered = true;
        for (size_t i = 1; i < shared.kept.states.size(); ++i)
          ordered = ordered && shared.kept.states[i - 1].pathIndex < shared.kept.states[i].pathIndex;
        CHECK(ordered);
        // Every kept state's segment meets the bounds (up to any distance).
        size_t meets = 0;
        for (const photon::PathState& st : shared.kept.states) meets += motion.meets(st.origin, st.dir, 100.0f);
        CHECK(meets == shared.kept.states.size());

        photon::TraceSettings seg = settings(photon::InvariantPhotons::None, motion, a, b, 100 + seed, sampler);
        seg.storedWanted = size_t(40000 * reuse / 3.0);
        photon::SegmentStore grid;
        grid.storeT0 = a;
        grid.storeT1 = b;
        grid.storedPerPath = 0.6;
        Tally f = direct(photon::traceSegmentPhotons(*s, seg, grid, Progress{}).store);
        photon::Continuation c;
        c.storeT0 = a;
        c.storeT1 = b;
        c.firstVirtual = seed * 997;
        c.virtualPaths = uint64_t(double(shared.emitted) * reuse);
        photon::TraceResult k = photon::continuePaths(*s, seg, shared.kept, c, Progress{});
        CHECK(k.emitted == c.virtualPaths);
        continued += k.continued;
        Tally g = direct(k.store);
        for (auto [to, from] : {std::pair{&full, &f}, std::pair{&cont, &g}}) {
          to->energy += from->energy / 4.0;
          to->se += from->se * from->se / 16.0;
          to->count += from->count;
        }
      }
      full.se = std::sqrt(full.se);
      // A block path continued `reuse` times carries one prefix: at worst its
      // continuations are fully correlated, reuse x the variance.
      cont.se = std::sqrt(cont.se * reuse);
      MESSAGE(std::string(sampler == SamplerKind::Sobol ? "sobol" : "random")
              << ", " << reuse << "x the block's paths: continued " << cont.energy << " +- " << cont.se << " ("
              << cont.count << " photons, " << continued << " paths continued), full trace " << full.energy << " +- "
              << full.se << " (" << full.count << "), analytic " << want);
      CHECK(cont.count > 200);
      CHECK(std::fabs(cont.energy - want) <= 4.0 * cont.se + 0.01 * want);
      CHECK(std::fabs(full.energy - want) <= 4.0 * full.se + 0.01 * want);
      CHECK(std::fabs(cont.energy - full.energy) <= 4.0 * std::sqrt(cont.se * cont.se + full.se * full.se));
    }
}

TEST_CASE("continued photon paths: a frame under a sweeping shadow matches the frame without continuation") {
  // Frame 1 of the shadow sweep, 4 seeds each, photons continued from the
  // block pass against photons traced from the light (both sharing the
  // invariant ones): the whole floor and the strip the shadow crosses agree
  // within four standard errors of the difference plus 1%.
  auto d = shadowSweep(16);
  auto s = Scene::build(d);
  auto meanRed = [](const Film& f, int y0, int y1) {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < f.width; ++x) sum += f.color[f.index(x, y)].r;
    return sum / double((y1 - y0) * f.width);
  };
  std::vector<double> v[2][2];  // [continued][floor, strip]
  uint64_t continuedPaths = 0;
  for (uint64_t seed = 1; seed <= 4; ++seed)
    for (int cont = 0; cont < 2; ++cont) {
      RenderOptions o;
      o.method = RenderMethod::Time;
      o.spp = 4;
      o.seed = seed;
      o.causticPhotons = 0;
      o.globalPhotons = 30000;
      o.visualizeGlobal = true;
      o.estimate.k = 60;
      o.estimate.ks = 60;
      o.estimate.maxRadius = 0.5f;
      AnimationOptions ao;
      ao.first = ao.last = 1;
      ao.window = 2;
      ao.sharedScale = 1.0;
      ao.movingScale = 1.0;
      ao.continuePaths = cont == 1;
      Film f;
      AnimationStats st = renderAnimation(*s, *d.animation, o, ao, Progress{},
                                          [&](int, Film&& film, const RenderStats&) { f = std::move(film); });
      CHECK(st.sharedPhotons > 0);
      if (cont) {
        CHECK(st.continuedPaths > 0);
        CHECK(st.peakKeptStates > 0);
        continuedPaths += st.continuedPaths;
      } else {
        CHECK(st.continuedPaths == 0);
      }
      v[cont][0].push_back(meanRed(f, 0, 16));
      v[cont][1].push_back(meanRed(f, 6, 10));  // rows 6-10: the band the slab's shadow crosses
    }
  for (int region = 0; region < 2; ++region) {
    double m[2], se[2];
    for (int c = 0; c < 2; ++c) {
      const std::vector<double>& x = v[c][region];
      m[c] = 0;
      for (double y : x) m[c] += y / double(x.size());
      double ss = 0;
      for (double y : x) ss += (y - m[c]) * (y - m[c]);
      se[c] = std::sqrt(ss / double(x.size() - 1) / double(x.size()));
    }
    double se2 = std::sqrt(se[0] * se[0] + se[1] * se[1]);
    MESSAGE(std::string(region ? "shadow strip" : "floor") << ": continued " << m[1] << ", traced from the light " << m[0]
                                                << ", standard error of the difference " << se2);
    CHECK(std::fabs(m[1] - m[0]) <= 4.0 * se2 + 0.01 * m[0]);
  }
  MESSAGE("paths continued, 4 seeds: " << continuedPaths);
}
