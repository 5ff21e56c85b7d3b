// photon/tracer.cpp — photon paths: light choice, emission, bounces with
// Russian roulette, storage, and the pilot run that sizes the emission.
#include "photon/tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "core/timer.h"
#include "math/frame.h"
#include "photon/surface_tag.h"
#include "photon/tracer_media.h"
#include "sampling/warp.h"
#include "scene/bsdf.h"

namespace tdpm::photon {

namespace {

// Photon bounces whose Sobol group seeds are hashed once per batch (deeper
// bounces hash theirs per draw, as the eye paths do): groups up to the
// roulette slot of vertex kSeedTableBounces.
constexpr int kSeedTableBounces = 64;
constexpr uint32_t kSeedTableGroups =
    uint32_t(dims::vertexGroup(kSeedTableBounces, dims::kSlotsPerVertex));

// Batches traced before they are appended to the result (see traceBatches):
// enough work to keep every core busy, small next to a large map.
constexpr uint64_t kBatchesPerChunk = 256;
// A scene that stores (almost) nothing must not hang: the pilot gives up
// after kMaxPilotPaths paths or kMaxPilotRays rays in one round, whichever
// comes first (a point light inside a closed mirror sphere bounces every
// path to the depth limit and stores nothing: 58 s for a black 64x48 image
// when the pilot was bounded by paths alone), and the emission is capped at
// kMaxPathsPerPhoton paths per wanted photon (both reported as warnings).
constexpr uint64_t kMaxPilotPaths = uint64_t(1) << 20;
constexpr uint64_t kMaxPilotRays = uint64_t(1) << 21;

// Radical inverse in base 2 with a random XOR scramble: a (0,1)-sequence,
// so every prefix of the path times is stratified over the shutter.
float scrambledVanDerCorput(uint32_t i, uint32_t scramble) {
  uint32_t bits = i;
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  bits ^= scramble;
  return std::min(float(bits >> 8) * 0x1p-24f, 0x1.fffffep-1f);
}

struct LightTable {
  std::vector<float> cdf;  // over lights, by emitted power (luminance)
  std::vector<float> pdf;
  bool empty() const { return cdf.empty(); }
  uint32_t pick(float u) const {
    auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
    return uint32_t(std::min<size_t>(size_t(it - cdf.begin()), cdf.size() - 1));
  }
};

// ---- projection maps (Jensen 2001, sec. 5.3), as bounding spheres ----
// A caustic path's first hit must be a specular surface (delta-only, or a
// sharp metal: Material::isCausticBounce), so the caustic map only needs
// photons emitted toward the swept bounding spheres of those objects. Directions (or, for a sun, points on the
// emission disc) are drawn from a mixture over those targets; the flux is
// divided by the mixture density (the number of targets covering the
// sample over their total measure), so energies stay exact however the
// targets overlap.
struct Target {
  Vec3f centre;
  float radius;
};

// World bounds of an object over normalised times [u0, u1]: the blended
// motion moves every point linearly between steps, so the bounds at u0, u1
// and the steps between them hold it all (as Motion::sweptBounds).
Bounds3f boundsOver(const SceneObject& o, float u0, float u1) {
  if (!o.motion.moving() || (u0 <= 0.0f && u1 >= 1.0f)) return o.sweptBounds;
  Bounds3f b = transformBounds(o.motion.atNormalized(u0), o.objectBounds);
  b.extend(transformBounds(o.motion.atNormalized(u1), o.objectBounds));
  const int n = o.motion.stepCount();
  for (int i = 1; i + 1 < n; ++i) {
    float u = float(i) / float(n - 1);
    if (u > u0 && u < u1) b.extend(transformBounds(o.motion.step(i), o.objectBounds));
  }
  return b;
}

// Targets over the paths' times [u0, u1] (normalised): a segment of an
// animation's timeline aims at where the objects are then, not at the
// whole timeline's sweep.
std::vector<Target> specularTargets(const Scene& scene, bool glossy, float u0 = 0.0f, float u1 = 1.0f) {
  std::vector<Target> t;
  for (const SceneObject& o : scene.objects)
    if (scene.materials[o.material].causticTarget(glossy)) {
      Bounds3f b = boundsOver(o, u0, u1);
      t.push_back({b.center(), 0.5f * length(b.diagonal()) * 1.001f});
    }
  return t;
}

// Cosine of the half-angle of the cone from x that holds the sphere; -1
// (every direction) when x is inside it.
float coneCos(const Target& t, Vec3f x) {
  float d2 = lengthSquared(t.centre - x);
  float r2 = t.radius * t.radius;
  return d2 <= r2 ? -1.0f : std::sqrt(1.0f - r2 / d2);
}

// The cone of directions from x that photon emission samples for one
// target: the target's own cone, or, for a spot light, the spot's cone when
// that is the smaller (a 1-degree laser aimed at a mirror whose bounding
// sphere subtends 16 degrees used to waste 99.6% of its paths: issue 10),
// or nothing when the two cannot meet. Either choice holds every direction
// that both leaves the spot and meets the target, so the caustic map's
// support is unchanged and energies stay exact.
struct Cone {
  Vec3f axis;
  float cosMax = 1.0f;  // -1: every direction
  bool empty = true;
  float solidAngle() const { return empty ? 0.0f : 2.0f * kPi * (1.0f - cosMax); }
  bool contains(Vec3f d) const { return !empty && (cosMax <= -1.0f || dot(d, axis) >= cosMax); }
};

// Spot: its axis and cosTotal at the emission time; cosTotal = -1 for a
// point light (no restriction).
struct EmitterCone {
  Vec3f axis{0, 0, 1};
  float cosTotal = -1.0f;
};

Cone samplingCone(const Target& t, Vec3f x, const EmitterCone& e) {
  Cone c;
  c.empty = false;
  c.cosMax = coneCos(t, x);
  if (c.cosMax > -1.0f) c.axis = normalize(t.centre - x);
  if (e.cosTotal <= -1.0f) return c;
  float spotSolid = 2.0f * kPi * (1.0f - e.cosTotal);
  if (c.cosMax > -1.0f) {
    // Disjoint when the angle between the axes exceeds the sum of the half-angles.
    float between = std::acos(std::min(1.0f, std::max(-1.0f, dot(c.axis, e.axis))));
    float sum = std::acos(std::min(1.0f, e.cosTotal)) + std::acos(std::min(1.0f, c.cosMax));
    if (sum < kPi && between > sum * 1.0001f + 1e-6f) {
      c.empty = true;
      return c;
    }
  }
  if (spotSolid < c.solidAngle()) {
    c.axis = e.axis;
    c.cosMax = e.cosTotal;
  }
  return c;
}

// Direction from x toward the targets (through the emitter's cone); returns
// the solid-angle density of the mixture at the chosen direction (0: no
// target). Each target's sampling cone is chosen by its solid angle and
// sampled uniformly, so the density is the number of cones holding the
// direction over their total solid angle.
float sampleTowardTargets(const std::vector<Target>& targets, Vec3f x, const EmitterCone& e, Vec3f uvw,
                          Vec3f& dir) {
  float total = 0;
  for (const Target& t : targets) total += samplingCone(t, x, e).solidAngle();
  if (!(total > 0)) return 0.0f;
  float pick = uvw.x * total, acc = 0;
  size_t j = 0;
  Cone chosen;
  for (; j < targets.size(); ++j) {
    chosen = samplingCone(targets[j], x, e);
    acc += chosen.solidAngle();
    if (pick < acc && !chosen.empty) break;
  }
  if (j == targets.size()) {  // round-off at the top end: the last non-empty cone
    for (size_t k = targets.size(); k-- > 0;) {
      chosen = samplingCone(targets[k], x, e);
      if (!chosen.empty) break;
    }
  }
  float cosMax = chosen.cosMax;
  Vec3f local = cosMax <= -1.0f ? squareToUniformSphere({uvw.y, uvw.z}) : squareToUniformCone({uvw.y, uvw.z}, cosMax);
  dir = cosMax <= -1.0f ? local : Frame(chosen.axis).toWorld(local);
  int covering = 0;
  for (const Target& t : targets) covering += samplingCone(t, x, e).contains(dir);
  return float(std::max(covering, 1)) / total;
}

// The sun's emission disc (travel direction d, irradiance e), restricted to
// the targets' shadows on it; an environment light's after its direction.
bool discTowardTargets(Vec3f d, Rgb e, const std::vector<Target>& targets, const Bounds3f& bounds, Vec3f uvw,
                       EmittedRay& out) {
  Vec3f c = bounds.empty() ? Vec3f(0, 0, 0) : bounds.center();
  float R = bounds.empty() ? 1.0f : 0.5f * length(bounds.diagonal()) * 1.001f + 1e-6f;
  float total = 0;
  for (const Target& t : targets) total += kPi * t.radius * t.radius;
  if (!(total > 0)) return false;
  float pick = uvw.x * total, acc = 0;
  size_t j = 0;
  for (; j + 1 < targets.size(); ++j) {
    acc += kPi * targets[j].radius * targets[j].radius;
    if (pick < acc) break;
  }
  Frame f(d);
  Vec2f disk = squareToConcentricDisk({uvw.y, uvw.z});
  Vec3f onPlane = targets[j].centre - d * dot(d, targets[j].centre - c) +
                  (f.s * disk.x + f.t * disk.y) * targets[j].radius;
  int covering = 0;
  for (const Target& t : targets) {
    Vec3f tc = t.centre - d * dot(d, t.centre - c);
    covering += lengthSquared(onPlane - tc) <= t.radius * t.radius;
  }
  out.origin = onPlane - d * (R + std::fabs(dot(d, onPlane - c)));
  out.direction = d;
  out.flux = e * (total / float(std::max(covering, 1)));
  return true;
}

// The cap of a sphere light (centre c, radius R) whose points can send
// light into target t: a point q = c + R w faces some point of the target
// iff dot(w, t.centre - c) > R - t.radius. Returns the cap's cosine bound
// about its axis (-1: the whole sphere; >= 1: no point can).
float sphereCap(const Target& t, Vec3f c, float R, Vec3f* axis) {
  Vec3f to = t.centre - c;
  float D = length(to);
  *axis = D > 0 ? to / D : Vec3f(0, 0, 1);
  if (!(D > 0)) return t.radius > R ? -1.0f : 1.0f;
  return std::clamp((R - t.radius) / D, -1.0f, 1.0f);
}

// Caustic photons of a one-sided sphere light: the point uniform on the
// cap that can see a target (the target chosen by its cap's area), then the
// direction toward the targets from there; density of the point: the
// mixture over every cap holding it. Points from which no target can be
// reached are never drawn: uniform points on the whole sphere put half the
// paths on its far side, each then refused for leaving the sphere inward.
bool sphereTowardTargets(const Light& light, const AreaLightFrame& fr, const std::vector<Target>& targets,
                         Vec2f uPos, Vec3f uvw, EmittedRay& out) {
  const float R = fr.radius;
  float total = 0;
  Vec3f axis;
  for (const Target& t : targets) {
    float k = sphereCap(t, fr.center, R, &axis);
    if (k < 1.0f) total += 1.0f - k;
  }
  if (!(total > 0)) return false;
  float pick = uPos.x * total, acc = 0, k = 1.0f, w0 = 0;
  for (const Target& t : targets) {
    float kt = sphereCap(t, fr.center, R, &axis);
    if (kt >= 1.0f) continue;
    w0 = acc;
    acc += 1.0f - kt;
    k = kt;
    if (pick < acc) break;
  }
  float ux = std::clamp((pick - w0) / (1.0f - k), 0.0f, 0.99999994f);
  float cosT = 1.0f - ux * (1.0f - k), sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
  float phi = 2.0f * kPi * uPos.y;
  Vec3f w = Frame(axis).toWorld({sinT * std::cos(phi), sinT * std::sin(phi), cosT});
  // Density per area: each cap is chosen with probability (1 - k) / total
  // and covers the fraction (1 - k) / 2 of the area: 2 / (A total) per cap.
  int covering = 0;
  for (const Target& t : targets) {
    Vec3f a;
    float kt = sphereCap(t, fr.center, R, &a);
    covering += kt < 1.0f && dot(w, a) >= kt;
  }
  float pdfArea = float(std::max(covering, 1)) * 2.0f / (fr.area * total);
  Vec3f q = fr.center + w * R;
  float pdf = sampleTowardTargets(targets, q, EmitterCone{}, uvw, out.direction);
  float cosE = dot(out.direction, w);
  if (!(pdf > 0) || cosE <= 0) return false;
  out.origin = q;
  out.flux = areaLightRadiance(light, fr, w, out.direction) * (cosE / (pdfArea * pdf));
  return true;
}

// Caustic-map emission of one light toward the targets. flux = emitted
// radiometric quantity / density, as in emitFromLight.
template <class Stream>
bool emitTowardTargets(const Light& light, const std::vector<Target>& targets, float time01, const Bounds3f& bounds,
                       Stream& rng, EmittedRay& out) {
  Vec3f uvw = rng.get3D(dims::kPhotonDirection);
  switch (light.type) {
    case Light::Type::Point:
    case Light::Type::Spot: {
      Affine3f m = light.motion.atNormalized(time01);
      Vec3f p = m.point(light.position);
      EmitterCone cone;
      if (light.type == Light::Type::Spot) cone = {normalize(m.vector(light.direction)), light.cosTotal};
      float pdf = sampleTowardTargets(targets, p, cone, uvw, out.direction);
      if (!(pdf > 0)) return false;
      Rgb i = light.intensity;
      if (light.type == Light::Type::Spot) {
        float f = light.spotFalloff(dot(out.direction, cone.axis));
        if (f <= 0) return false;
        i = i * f;
      }
      out.origin = p;
      out.flux = i / pdf;
      return true;
    }
    case Light::Type::Area: {
      AreaLightFrame fr = areaLightFrame(light, time01);
      if (!(fr.area > 0)) return false;
      if (light.shape == Light::AreaShape::Sphere && !light.twoSided && !light.reversed)
        return sphereTowardTargets(light, fr, targets, rng.get2D(dims::kPhotonPosition), uvw, out);
      // x and y crossed: the old expression drew its two rng.uniform()
      // calls right to left (GCC's order), and random keeps its maps.
      Vec2f uPos = rng.get2D(dims::kPhotonPosition);
      Vec3f q, n;
      if (!sampleAreaLightPoint(light, fr, {uPos.y, uPos.x}, q, n)) return false;
      float pdf = sampleTowardTargets(targets, q, EmitterCone{}, uvw, out.direction);
      float cosT = dot(out.direction, n);
      if (light.twoSided) cosT = std::fabs(cosT);
      if (!(pdf > 0) || cosT <= 0) return false;
      out.origin = q;
      out.flux = areaLightRadiance(light, fr, n, out.direction) * (cosT * fr.area / pdf);
      return true;
    }
    case Light::Type::Directional: {
      Affine3f m = light.motion.atNormalized(time01);
      return discTowardTargets(normalize(m.vector(light.direction)), light.power, targets, bounds, uvw, out);
    }
    case Light::Type::Environment: {
      // A sky direction by luminance, then the sun's disc toward the targets
      // with irradiance L / pdf (its expectation is the integral of L).
      Vec3f w;
      Rgb L;
      float pdf;
      if (!light.env->sample(rng.get2D(dims::kPhotonPosition), w, L, pdf)) return false;
      return discTowardTargets(-w, L / pdf, targets, bounds, uvw, out);
    }
  }
  return false;
}

// What a light can send at the targets (luminance), to choose lights for
// the caustic map: a cone's or disc's worth of its intensity or irradiance.
double powerTowardTargets(const Light& light, const std::vector<Target>& targets) {
  double sum = 0;
  switch (light.type) {
    case Light::Type::Point:
    case Light::Type::Spot: {
      Vec3f p = light.motion.atNormalized(0.5f).point(light.position);
      // Each target's sampling cone is at most the spot's own (see
      // samplingCone). Disjoint cones are not left out: the light may move
      // and meet the target at other times.
      double cap = light.type == Light::Type::Spot ? 2.0 * kPi * (1.0 - light.cosTotal) : 4.0 * kPi;
      for (const Target& t : targets) sum += std::min(2.0 * kPi * (1.0 - coneCos(t, p)), cap);
      return light.intensity.average() * std::min(sum, cap);
    }
    case Light::Type::Area: {
      // Radiance x area x the projected solid angle of the targets, seen
      // from the light's centre (small targets).
      AreaLightFrame fr = areaLightFrame(light, 0.5f);
      if (!(fr.area > 0)) return 0;
      for (const Target& t : targets) {
        Vec3f to = t.centre - fr.center;
        float dist = length(to);
        // A curved or twosided emitter faces every target somewhere: no cosine.
        bool planar = (light.shape == Light::AreaShape::Rect || light.shape == Light::AreaShape::Disk) && !light.twoSided;
        float cosL = dist > 0 && planar ? dot(to / dist, fr.normal) : 1.0f;
        float cone = 2.0f * kPi * (1.0f - coneCos(t, fr.center));
        sum += double(cone) * std::max(0.0f, std::min(1.0f, cosL + t.radius / std::max(dist, 1e-6f)));
      }
      return fr.radiance.average() * fr.area * (light.twoSided ? 2.0 : 1.0) * std::min(sum, double(kPi));
    }
    case Light::Type::Directional:
    case Light::Type::Environment:  // power: the integral of its radiance (see emittedPower)
      for (const Target& t : targets) sum += kPi * double(t.radius) * t.radius;
      return light.power.average() * sum;
  }
  return 0;
}

// Lights chosen by emitted power (global map) or by power sent toward the
// specular targets (caustic map).
LightTable makeLightTable(const Scene& scene, const std::vector<Target>* targets, bool areaLightsOnly) {
  LightTable t;
  double total = 0;
  std::vector<double> w;
  for (const Light& l : scene.lights) {
    double p = targets ? powerTowardTargets(l, *targets) : std::max(0.0f, emittedPower(l, scene.bounds).average());
    p = std::max(0.0, p);
    // The caustic guide serves area lights: an environment's photons made it
    // slower and noisier on caustic-glass (0.83 s / relMSE 0.00232 against
    // 0.55 s / 0.00177 without, 105x150 at 32 spp).
    if (areaLightsOnly && l.type != Light::Type::Area) p = 0.0;
    w.push_back(p);
    total += p;
  }
  if (!(total > 0)) return t;
  // Caustic map: half the photons by power toward the targets, half shared
  // equally among the lights that reach them (a defensive mixture). A faint
  // but concentrated source (a 14 W laser beside a sun of kilowatts) still
  // gets photons to resolve its caustic; energies stay exact because each
  // photon's flux is divided by its light's probability.
  size_t reaching = 0;
  for (double p : w) reaching += p > 0;
  double acc = 0;
  for (double p : w) {
    double prob = targets ? 0.5 * p / total + (p > 0 ? 0.5 / double(reaching) : 0.0) : p / total;
    acc += prob;
    t.cdf.push_back(float(acc));
    t.pdf.push_back(float(prob));
  }
  t.cdf.back() = 1.0f;
  return t;
}

struct Tracer {
  const Scene& scene;
  const TraceSettings& settings;
  std::vector<Target> targets;  // caustic map: where photons are aimed
  LightTable lights;
  float t0, t1, ts;
  uint32_t timeScramble;
  float u0 = 0.0f, u1 = 1.0f;  // path times, normalised over the scene's shutter
  uint64_t batchOffset = 0;    // global index of batch 0 (progressive passes)

  // Traces paths [first, first + count) of batch `b` into `out`, energies
  // scaled by `energyScale` (= ts / n_e). Returns nothing: out grows.
  // Returns the number of rays cast.
  uint64_t traceBatch(uint64_t local, double energyScale, PhotonStore& out, std::vector<ExitPoint>* exits,
                      std::vector<PathState>* kept = nullptr) const {
    uint64_t b = batchOffset + local;
    Rng rng(hashCombine(settings.seed, uint64_t(settings.kind) + 1, b), 0x9e37);
    // sobol: the path index is the sample index, the map's seed and kind the "pixel".
    uint64_t sobolSeed = hashCombine(settings.seed, uint64_t(settings.kind) + 1, 0x9407ull);
    // Sequences are indexed by 32 bits: past 2^32 paths (a long progressive
    // render) each further 2^32 take new scrambles instead of repeating the
    // first paths. Below 2^32 nothing changes.
    uint32_t timeScrambleHere = timeScramble;
    if (uint64_t high = (b * kPathsPerBatch) >> 32) {
      sobolSeed = hashCombine(sobolSeed, high);
      timeScrambleHere ^= uint32_t(mix64(high ^ 0x7173ull));
    }
    // Every path of the batch shares the Sobol "pixel" seed, so the seeds of
    // its groups (light, position, direction, and per bounce BSDF and
    // roulette, up to kSeedTableBounces) are hashed once per batch, not per
    // draw (callgrind, cube-caustic -m time 80x60: photon tracing 104.1M ->
    // 95.5M instructions, images identical).
    std::array<SobolStream::GroupSeeds, kSeedTableGroups> seedTable;
    if (settings.sampler == SamplerKind::Sobol) SobolStream::fillSeedTable(sobolSeed, seedTable.data(), kSeedTableGroups);
    uint64_t rays = 0;
    for (uint32_t i = 0; i < kPathsPerBatch; ++i) {
      uint64_t g = b * kPathsPerBatch + i;
      // The time stays the scrambled van der Corput of the path index for
      // both kinds: it is already a stratified 1D sequence over the shutter.
      float time01 = settings.spreadInTime ? u0 + scrambledVanDerCorput(uint32_t(g), timeScrambleHere) * (u1 - u0)
                                            : settings.fixedTime01;
      if (settings.sampler == SamplerKind::Sobol) {
        SobolStream s{sobolSeed, uint32_t(g)};
        s.table = seedTable.data();
        s.tableSize = kSeedTableGroups;
        rays += tracePath(time01, g, s, energyScale, out, exits, kept);
      } else {
        RandomStream s{&rng};
        rays += tracePath(time01, g, s, energyScale, out, exits, kept);
      }
    }
    return rays;
  }

  // Draws follow sampling/sampler.h's photon groups; RandomStream ignores
  // the group and draws in call order, which is the old PCG32 order.
  // exits (caustic maps, optional): receives each stored photon's last
  // specular vertex, in store order.
  // kept (InvariantPhotons::Only with keepMoving): receives the state of
  // every path that meets motion, before the segment that does.
  template <class Stream>
  uint64_t tracePath(float time01, uint64_t pathIndex, Stream& rng, double energyScale, PhotonStore& out,
                     std::vector<ExitPoint>* exits, std::vector<PathState>* kept = nullptr) const {
    uint64_t rays = 0;
    uint32_t li = lights.pick(rng.get1D(dims::kPhotonLight));
    const Light& light = scene.lights[li];
    EmittedRay ray;
    if (settings.kind == MapKind::Caustic && settings.projection) {
      if (!emitTowardTargets(light, targets, time01, scene.bounds, rng, ray)) return rays;
    } else {
      Vec2f uPos = rng.get2D(dims::kPhotonPosition);
      Vec2f uDir = rng.get2D(dims::kPhotonDirection);
      if (!emitFromLight(light, time01, scene.bounds, uPos, uDir, ray)) return rays;
    }
    // Time-invariant so far (settings.invariant != All): a still light, and
    // every segment up to here misses what moves over the window.
    bool invariant = settings.invariant != InvariantPhotons::All && !light.motion.moving();
    if (settings.invariant == InvariantPhotons::Only && !invariant) {
      if (kept) {  // a moving light: the continuation emits again at its own time
        PathState st;
        st.power = Rgb(1.0f / lights.pdf[li]);
        st.pathIndex = pathIndex;
        st.light = li;
        st.fromLight = true;
        kept->push_back(st);
      }
      return rays;
    }
    Rgb power = ray.flux / lights.pdf[li];
    float time = scene.shutter.instant() ? t0 : scene.shutter.fromNormalized(time01);
    // Off the emitter's surface: an area light is geometry, and a photon
    // starting on it would hit it at distance zero.
    Vec3f origin = scene.spawnOrigin(ray.origin, ray.direction, ray.direction), dir = ray.direction;
    // Media: the walk of photon/tracer_media.h (a scene without media never
    // takes it, so its paths are exactly the loop below).
    if (scene.hasMedia()) {
      // A sun's or the sky's photon starts on a disc outside the scene: its
      // media begin where it enters their world (Scene::mediaEntry), as a
      // shadow ray toward that light ends there.
      if (light.type == Light::Type::Directional || light.type == Light::Type::Environment)
        origin = origin + dir * scene.mediaEntry(origin, dir);
      MediaPath mp{origin, dir, power, time01, time, scene.lightMedia[li], invariant, pathIndex};
      return rays + walkPhotonInMedia(scene, settings, mp, rng, energyScale, out, exits);
    }
    return rays + bounces(0, origin, dir, power, true, invariant, time01, time, li, pathIndex, rng, energyScale, out,
                          exits, kept);
  }

  // The path's vertices from `first` on (the loop's count of segments so
  // far), its ray (origin, dir) and power: the rest of tracePath, and the
  // whole of a continuation (continuePaths), which starts where a block
  // pass kept the path.
  template <class Stream>
  uint64_t bounces(int first, Vec3f origin, Vec3f dir, Rgb power, bool allSpecular, bool invariant, float time01,
                   float time, uint32_t li, uint64_t pathIndex, Stream& rng, double energyScale, PhotonStore& out,
                   std::vector<ExitPoint>* exits, std::vector<PathState>* kept) const {
    uint64_t rays = 0;
    // allSpecular: every bounce so far was a delta reflection/refraction
    Vec3f lastSpecular = origin;
    for (int bounce = first; bounce <= settings.maxBounces; ++bounce) {
      Hit hit;
      ++rays;
      if (!scene.intersect(origin, dir, std::numeric_limits<float>::infinity(), time01, hit)) return rays;
      if (invariant && settings.motion->meets(origin, dir, hit.t)) {
        invariant = false;
        if (settings.invariant == InvariantPhotons::Only) {  // nothing further is invariant
          if (kept) {
            PathState st;
            st.origin = origin;
            st.dir = dir;
            st.power = power;
            st.pathIndex = pathIndex;
            st.light = li;
            st.bounce = uint16_t(bounce);
            st.allSpecular = allSpecular;
            kept->push_back(st);
          }
          return rays;
        }
      }
      if (hit.isLight()) return rays;  // emitters absorb
      Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
      const Material& mat = scene.materialAt(hit, -dir, &mixWeight);
      // A sharp metal continues a caustic path (after storing there: the
      // caustic seen on the metal itself is L S+ G).
      bool glossyBounce = settings.glossyCaustics && mat.isGlossy();
      if (!mat.isDeltaOnly()) {
        bool store = (settings.kind == MapKind::Global || (bounce > 0 && allSpecular)) &&
                     (settings.invariant != InvariantPhotons::None || !invariant);
        // The side it arrived on keeps it out of estimates on the other side
        // of the same object (photon/surface_tag.h).
        if (store) {
          out.add(hit.p, power * float(energyScale), -dir, time, surfaceTag(hit.object, dot(hit.n, dir) > 0.0f));
          if (exits) exits->push_back({lastSpecular, dot(hit.n, dir) > 0.0f ? -hit.n : hit.n});
        }
        if (settings.kind == MapKind::Caustic && !glossyBounce) return rays;  // L (S|G)+ D ends here
      }
      std::optional<Material> textured;
      ShadingContext ctx = scene.shadingContext(mat, hit, -dir, textured, mixWeight);
      BsdfSample bs;
      Vec3f ub = rng.get3D(dims::vertexGroup(bounce, dims::kBsdf));
      if (!bsdfSample(ctx, {ub.x, ub.y}, ub.z, Transport::Importance, bs)) return rays;
      // Shading normals: the adjoint BSDF (bsdf.h), before the roulette reads the weight.
      if (ctx.shaded) bs.weight = bs.weight * adjointShadingFactor(ctx, -dir, bs.wi);
      bool specularLike = bs.delta || glossyBounce;
      if (settings.kind == MapKind::Caustic && !specularLike) return rays;
      allSpecular = allSpecular && specularLike;
      if (specularLike) lastSpecular = hit.p;
      // Russian roulette by the scattering's throughput: surviving photons
      // keep (on average) their power instead of dimming.
      float survive = std::min(1.0f, bs.weight.maxComponent());
      if (!(survive > 0) || rng.get1D(dims::vertexGroup(bounce, dims::kRoulette)) >= survive) return rays;
      power = power * bs.weight / survive;
      origin = scene.spawnOrigin(hit.p, hit.n, bs.wi);
      dir = bs.wi;
    }
    return rays;
  }

  // Traces batches [first, end) in parallel into one store, in batch order.
  // Batches are traced and appended a chunk at a time into a store reserved
  // for the expected count, so memory peaks near the final store's 20 bytes
  // per photon instead of holding every batch buffer and the result at once.
  PhotonStore traceBatches(uint64_t firstBatch, uint64_t endBatch, double energyScale, const Progress& progress,
                           const char* stage, size_t expected, uint64_t* raysOut = nullptr,
                           std::vector<ExitPoint>* exitsOut = nullptr, std::vector<PathState>* keptOut = nullptr) const {
    PhotonStore all(t0, t1);
    all.reserve(expected);
    std::atomic<uint64_t> rays{0};
    std::atomic<size_t> done{0};
    const uint64_t batches = endBatch - firstBatch;
    // Counted in photon paths emitted (the bar's unit for "... photons" stages).
    const size_t paths = size_t(batches) * kPathsPerBatch;
    progress(stage, 0, paths);
    std::vector<PhotonStore> parts;
    std::vector<std::vector<ExitPoint>> partExits;
    std::vector<std::vector<PathState>> partKept;
    for (uint64_t first = firstBatch; first < endBatch; first += kBatchesPerChunk) {
      size_t count = size_t(std::min<uint64_t>(kBatchesPerChunk, endBatch - first));
      parts.assign(count, PhotonStore(t0, t1));
      partExits.assign(exitsOut ? count : 0, {});
      partKept.assign(keptOut ? count : 0, {});
      tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t b = r.begin(); b != r.end(); ++b) {
          rays += traceBatch(first + b, energyScale, parts[b], exitsOut ? &partExits[b] : nullptr,
                             keptOut ? &partKept[b] : nullptr);
          progress(stage, (done.fetch_add(1) + 1) * kPathsPerBatch, paths);
        }
      });
      all.appendBatches(parts);
      for (const std::vector<ExitPoint>& e : partExits) exitsOut->insert(exitsOut->end(), e.begin(), e.end());
      if (keptOut) {  // grown once per chunk, to its size: no doubling slack on top of the parts
        size_t n = keptOut->size();
        for (const std::vector<PathState>& k : partKept) n += k.size();
        keptOut->reserve(n);
        for (std::vector<PathState>& k : partKept) {
          keptOut->insert(keptOut->end(), k.begin(), k.end());
          std::vector<PathState>().swap(k);
        }
      }
    }
    if (raysOut) *raysOut = rays.load();
    return all;
  }
};

// Every rank's photons, concatenated in rank order (= batch order, as each
// rank traced a contiguous block of batches), on every rank.
void allgatherStore(dist::Comm& comm, PhotonStore& store) {
  if (!comm.distributed()) return;
  std::vector<uint64_t> counts = comm.allgather(store.size());
  uint64_t total = 0;
  for (uint64_t c : counts) total += c;
  PhotonStore all(store.t0(), store.t1());
  PhotonStore::RawArrays a = all.resizeForFill(size_t(total));
  auto gather = [&](const void* mine, void* out, uint64_t elementBytes) {
    std::vector<uint64_t> bytes(counts.size());
    for (size_t r = 0; r < counts.size(); ++r) bytes[r] = counts[r] * elementBytes;
    comm.allgatherv(mine, out, bytes);
  };
  gather(store.xs(), a.x, 4);
  gather(store.ys(), a.y, 4);
  gather(store.zs(), a.z, 4);
  gather(store.energies(), a.energy, 4);
  gather(store.directions(), a.direction, 2);
  gather(store.flags(), a.flags, 2);
  store = std::move(all);
}

// Batches of a distributed fixed-budget render taken from a work queue
// (dist::SharedCounter): each rank takes chunks of kQueueChunk batches as it
// gets through them (a rank on a faster core takes more), then every rank
// receives every chunk's photons and puts them in chunk order, which is
// batch order: the store one process makes, whoever traced what.
constexpr uint64_t kQueueChunk = 4;

PhotonStore traceQueuedBatches(const Tracer& tracer, dist::Comm& comm, uint64_t batches, double energyScale,
                               const Progress& progress, const char* stage, size_t expected, uint64_t* raysOut) {
  PhotonStore mine(tracer.t0, tracer.t1);
  mine.reserve(expected);
  std::vector<uint64_t> chunks, counts;  // this rank's chunk numbers and their photon counts
  uint64_t rays = 0;
  const uint64_t chunkCount = (batches + kQueueChunk - 1) / kQueueChunk;
  const size_t paths = size_t(batches) * kPathsPerBatch;
  progress(stage, 0, paths);
  {
    std::unique_ptr<dist::SharedCounter> queue = comm.sharedCounter();
    for (;;) {
      const uint64_t c = queue->fetchAdd(1);  // main thread only: the batches inside run in parallel
      if (c >= chunkCount) break;
      const uint64_t lo = c * kQueueChunk, hi = std::min(batches, lo + kQueueChunk);
      uint64_t r = 0;
      PhotonStore part = tracer.traceBatches(lo, hi, energyScale, Progress{}, stage, 0, &r);
      rays += r;
      chunks.push_back(c);
      counts.push_back(part.size());
      mine.appendBatches(&part, 1);
      progress(stage, size_t(hi) * kPathsPerBatch, paths);  // the job's progress, roughly
    }
  }
  progress(stage, paths, paths);  // every chunk taken
  *raysOut = rays;
  // Who traced which chunk, and how many photons each chunk stored.
  std::vector<uint64_t> perRank = comm.allgather(uint64_t(chunks.size()));
  std::vector<uint64_t> bytes(perRank.size());
  uint64_t listed = 0;
  for (size_t r = 0; r < perRank.size(); ++r) {
    bytes[r] = perRank[r] * sizeof(uint64_t);
    listed += perRank[r];
  }
  TDPM_ASSERT(listed == chunkCount, "every chunk of photon batches traced once");
  std::vector<uint64_t> allChunks(static_cast<size_t>(listed)), allCounts(static_cast<size_t>(listed));
  comm.allgatherv(chunks.data(), allChunks.data(), bytes);
  comm.allgatherv(counts.data(), allCounts.data(), bytes);
  allgatherStore(comm, mine);  // rank order
  // Where chunk c starts in the rank-order store.
  std::vector<uint64_t> start(static_cast<size_t>(chunkCount)), size(static_cast<size_t>(chunkCount));
  uint64_t at = 0;
  for (size_t k = 0; k < allChunks.size(); ++k) {
    start[size_t(allChunks[k])] = at;
    size[size_t(allChunks[k])] = allCounts[k];
    at += allCounts[k];
  }
  TDPM_ASSERT(at == mine.size(), "photon counts of the chunks add up to the gathered store");
  PhotonStore ordered(mine.t0(), mine.t1());
  PhotonStore::RawArrays a = ordered.resizeForFill(mine.size());
  size_t to = 0;
  for (size_t c = 0; c < start.size(); ++c) {
    const size_t from = size_t(start[c]), n = size_t(size[c]);
    std::copy_n(mine.xs() + from, n, a.x + to);
    std::copy_n(mine.ys() + from, n, a.y + to);
    std::copy_n(mine.zs() + from, n, a.z + to);
    std::copy_n(mine.energies() + from, n, a.energy + to);
    std::copy_n(mine.directions() + from, n, a.direction + to);
    std::copy_n(mine.flags() + from, n, a.flags + to);
    to += n;
  }
  return ordered;
}

}  // namespace

MotionBounds motionBoundsOver(const Scene& scene, float u0, float u1) {
  MotionBounds m;
  size_t movingObjects = 0;
  for (const SceneObject& o : scene.objects)
    if (o.motion.moving()) {
      m.boxes.push_back(boundsOver(o, u0, u1));
      ++movingObjects;
    }
  // Scene::build lists the moving objects' swept bounds first, then the
  // moving area lights' (over the whole shutter: conservative).
  TDPM_ASSERT(scene.movingBounds.size() >= movingObjects, "moving objects' bounds listed first");
  for (size_t i = movingObjects; i < scene.movingBounds.size(); ++i) m.boxes.push_back(scene.movingBounds[i]);
  // A photon stored on a moving box's face ends its segment exactly on the
  // bounds' face, where the slab test can miss by a rounding error: the
  // boxes are grown by a hair (1e-4 of their size, plus the scene's
  // epsilon) so that such a segment always meets them.
  for (Bounds3f& b : m.boxes) {
    Vec3f grow = b.diagonal() * 1e-4f + Vec3f(scene.epsilon(b.center()));
    b.lo = b.lo - grow;
    b.hi = b.hi + grow;
  }
  return m;
}

void photonTimeRange(const Scene& scene, float& t0, float& t1) {
  t0 = scene.shutter.open;
  t1 = scene.shutter.instant() ? scene.shutter.open + 1.0f : scene.shutter.close;
}

bool sceneHasSpecular(const Scene& scene, bool glossy) {
  for (const SceneObject& o : scene.objects)
    if (scene.materials[o.material].causticTarget(glossy))
      return true;
  return false;
}

namespace {

// What the entry points add to TraceSettings (each caller its own part).
struct TraceExtras {
  PathRange range;           // tracePassPhotons
  bool segment = false;      // traceSegmentPhotons: `store` applies
  SegmentStore store;
  bool guide = false;        // traceGuidePhotons: area lights only, exit points kept
};

TraceResult traceMap(const Scene& scene, const TraceSettings& settings, const TraceExtras& extras,
                     const Progress& progress) {
  Timer timer;
  TraceResult result;
  float t0, t1;
  photonTimeRange(scene, t0, t1);
  float ts = t1 - t0, u0 = 0.0f, u1 = 1.0f;
  if (std::isfinite(settings.timeOpen)) {  // a segment of an animation's timeline
    ts = settings.timeClose - settings.timeOpen;
    u0 = scene.shutter.normalized(settings.timeOpen);
    u1 = scene.shutter.normalized(settings.timeClose);
    t0 = settings.timeOpen;
    t1 = settings.timeClose;
  }
  if (extras.segment) {
    t0 = extras.store.storeT0;
    t1 = extras.store.storeT1;
  }
  result.store = PhotonStore(t0, t1);
  std::vector<Target> targets;
  if (settings.kind == MapKind::Caustic) targets = specularTargets(scene, settings.glossyCaustics, u0, u1);
  Tracer tracer{scene, settings, targets,
                makeLightTable(scene, settings.kind == MapKind::Caustic && settings.projection ? &targets : nullptr,
                               extras.guide),
                t0,
                t1, ts,
                uint32_t(mix64(settings.seed ^ 0x7173ull)), u0, u1};
  TDPM_ASSERT(settings.invariant == InvariantPhotons::All || settings.motion, "time-invariance needs the motion bounds");
  TDPM_ASSERT(!settings.keepMoving || (settings.invariant == InvariantPhotons::Only && !settings.comm->distributed() &&
                                       !scene.hasMedia() && extras.range.paths == 0),
              "kept path states: a block pass of one process, without media");
  if (settings.storedWanted == 0 || tracer.lights.empty()) return result;
  if (settings.kind == MapKind::Caustic && !sceneHasSpecular(scene, settings.glossyCaustics)) return result;
  if (settings.kind == MapKind::Volume && !scene.hasMedia()) return result;  // nowhere to scatter
  const char* stage = settings.kind == MapKind::Caustic  ? "caustic photons"
                      : settings.kind == MapKind::Global ? "global photons"
                                                         : "volume photons";
  const PathRange& range = extras.range;
  if (range.paths > 0) {
    // A progressive pass: the count is fixed (pass 0's pilot chose it).
    TDPM_ASSERT(range.paths % kPathsPerBatch == 0 && range.firstPath % kPathsPerBatch == 0,
                "progressive photon paths must be whole batches");
    tracer.batchOffset = range.firstPath / kPathsPerBatch;
    uint64_t batches = range.paths / kPathsPerBatch;
    result.emitted = range.paths;
    double energyScale = double(tracer.ts) / double(result.emitted);
    size_t expected = settings.storedWanted + size_t(4.0 * std::sqrt(double(settings.storedWanted))) + 1024;
    result.store = tracer.traceBatches(0, batches, energyScale, progress, stage, expected, &result.rays,
                                       extras.guide ? &result.exitPoints : nullptr);
    result.store.shrinkToFit();
    result.seconds = timer.seconds();
    return result;
  }

  // Pilot: how many photons does a path store on average? Grow the pilot
  // (8x a round) until something is stored or a round would exceed the
  // path or ray budget; then the scene is taken to store nothing.
  // Distributed, every rank traces its block of each round and the counts
  // are summed (integers), so every rank takes the same decisions.
  dist::Comm& comm = *settings.comm;
  uint64_t pilotBatches = std::max<uint32_t>(1, settings.pilotBatches);
  size_t stored = 0;
  uint64_t pilotRays = 0;
  for (;;) {
    if (extras.store.storedPerPath > 0) break;  // measured before
    uint64_t rays = 0, lo = 0, hi = 0;
    dist::blockRange(pilotBatches, comm.rank(), comm.size(), lo, hi);
    PhotonStore pilot = tracer.traceBatches(lo, hi, 1.0, Progress{}, stage, 0, &rays);
    uint64_t sums[2] = {pilot.size(), rays};
    comm.allreduceSum(sums, 2);
    rays = sums[1];
    pilotRays += rays;
    stored = size_t(sums[0]);
    if (stored > 0) break;
    double raysPerBatch = std::max(1.0, double(rays) / double(pilotBatches));
    uint64_t next = std::min({pilotBatches * 8, kMaxPilotPaths / kPathsPerBatch,
                              uint64_t(double(kMaxPilotRays) / raysPerBatch)});
    if (next <= pilotBatches) break;
    pilotBatches = next;
  }
  if (stored == 0 && !(extras.store.storedPerPath > 0)) {
    // Zero of n: the rate is below 3 / n at 95% confidence.
    uint64_t paths = pilotBatches * kPathsPerBatch;
    result.rays = pilotRays;
    result.seconds = timer.seconds();
    result.warning = std::string(stage) + ": none of " + std::to_string(paths) + " paths (" +
                     std::to_string(pilotRays) + " rays in all) stored a photon, so fewer than 1 in " +
                     std::to_string(paths / 3) + " would (95% confidence); the map is empty";
    return result;
  }
  double perPath = extras.store.storedPerPath > 0 ? extras.store.storedPerPath
                                              : double(stored) / double(pilotBatches * kPathsPerBatch);
  result.storedPerPath = perPath;
  double pathsNeeded = double(settings.storedWanted) / perPath;
  double pathsCap = kMaxPathsPerPhoton * double(settings.storedWanted);
  if (pathsNeeded > pathsCap) {
    pathsNeeded = pathsCap;
    result.warning = std::string(stage) + ": only " + std::to_string(perPath * 100.0).substr(0, 6) +
                     "% of paths store a photon; emission capped at " + std::to_string(uint64_t(pathsCap)) + " paths";
  }
  uint64_t batches = std::max<uint64_t>(1, uint64_t(std::ceil(pathsNeeded / kPathsPerBatch)));

  result.emitted = batches * kPathsPerBatch;
  // Q = flux * ts / n_e (method.md section 2).
  double energyScale = double(tracer.ts) / double(result.emitted);
  // The final count is Poisson-like around the wanted one: reserve a few
  // standard deviations more so the store rarely needs to grow.
  size_t expected = settings.storedWanted + size_t(4.0 * std::sqrt(double(settings.storedWanted))) + 1024;
  TDPM_ASSERT(!extras.guide || !comm.distributed(), "exit points are kept by one process's maps only");
  if (comm.distributed()) {
    expected = size_t(double(expected) / double(comm.size())) + 1024;
    result.store = traceQueuedBatches(tracer, comm, batches, energyScale, progress, stage, expected, &result.rays);
    comm.allreduceSum(&result.rays, 1);
  } else {
    result.store = tracer.traceBatches(0, batches, energyScale, progress, stage, expected, &result.rays,
                                       extras.guide ? &result.exitPoints : nullptr,
                                       settings.keepMoving ? &result.kept.states : nullptr);
  }
  if (settings.keepMoving) {
    result.kept.states.shrink_to_fit();  // held for the block: not the growth's slack
    result.kept.emitted = result.emitted;
    result.kept.sobolSeed = hashCombine(settings.seed, uint64_t(settings.kind) + 1, 0x9407ull);
  }
  result.rays += pilotRays;
  result.store.shrinkToFit();
  result.seconds = timer.seconds();
  return result;
}

}  // namespace

TraceResult tracePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress) {
  return traceMap(scene, settings, TraceExtras{}, progress);
}

TraceResult tracePassPhotons(const Scene& scene, const TraceSettings& settings, const PathRange& range,
                             const Progress& progress) {
  TraceExtras x;
  x.range = range;
  return traceMap(scene, settings, x, progress);
}

TraceResult traceSegmentPhotons(const Scene& scene, const TraceSettings& settings, const SegmentStore& segment,
                                const Progress& progress) {
  TraceExtras x;
  x.segment = true;
  x.store = segment;
  return traceMap(scene, settings, x, progress);
}

namespace {

// One continued path of a segment: a kept state, its virtual index j in the
// segment (its time and, with the random sampler, its numbers) and its
// round (how many times the block's paths were gone through before it).
struct ContinuedPath {
  uint32_t state;
  uint32_t round;
  uint64_t j;
};
constexpr size_t kContinuedPerBatch = 256;

}  // namespace

TraceResult continuePaths(const Scene& scene, const TraceSettings& settings, const KeptPaths& kept,
                          const Continuation& c, const Progress& progress) {
  Timer timer;
  TraceResult result;
  TDPM_ASSERT(!scene.hasMedia() && std::isfinite(settings.timeOpen) && settings.timeClose > settings.timeOpen,
              "continued photon paths: a segment's times, no media");
  const float u0 = scene.shutter.normalized(settings.timeOpen), u1 = scene.shutter.normalized(settings.timeClose);
  result.store = PhotonStore(c.storeT0, c.storeT1);
  result.emitted = c.virtualPaths;
  const uint64_t n = kept.emitted;
  if (c.virtualPaths == 0 || n == 0 || kept.states.empty()) return result;
  // The kept states whose block path some virtual path j takes, in j order
  // within each pass over the block's paths (states are in path order).
  std::vector<ContinuedPath> work;
  work.reserve(std::min<uint64_t>(kept.states.size(), c.virtualPaths));
  for (uint64_t v = c.firstVirtual, end = c.firstVirtual + c.virtualPaths; v < end;) {
    const uint64_t round = v / n, a = v % n, b = std::min(n, a + (end - v));
    auto byIndex = [](const PathState& st, uint64_t i) { return st.pathIndex < i; };
    auto lo = std::lower_bound(kept.states.begin(), kept.states.end(), a, byIndex);
    auto hi = std::lower_bound(lo, kept.states.end(), b, byIndex);
    for (auto it = lo; it != hi; ++it)
      work.push_back({uint32_t(it - kept.states.begin()), uint32_t(round), round * n + it->pathIndex - c.firstVirtual});
    v += b - a;
  }
  result.continued = work.size();
  std::vector<Target> targets;
  if (settings.kind == MapKind::Caustic) targets = specularTargets(scene, settings.glossyCaustics, u0, u1);
  // The light table is not drawn from (a state keeps its light and the
  // block's choice probability); the tracer needs one.
  Tracer tracer{scene, settings, targets,
                makeLightTable(scene, settings.kind == MapKind::Caustic && settings.projection ? &targets : nullptr, false),
                c.storeT0, c.storeT1, settings.timeClose - settings.timeOpen,
                uint32_t(mix64(settings.seed ^ 0x7173ull)), u0, u1};
  // Q = power x ts / (the segment's virtual paths): path j stands for one
  // of them, as the paths of a full trace of the segment do.
  const double energyScale = double(tracer.ts) / double(c.virtualPaths);
  const size_t batches = (work.size() + kContinuedPerBatch - 1) / kContinuedPerBatch;
  std::vector<PhotonStore> parts(batches, PhotonStore(c.storeT0, c.storeT1));
  std::atomic<uint64_t> rays{0};
  progress("continued photons", 0, work.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, batches, 1), [&](const tbb::blocked_range<size_t>& r) {
    std::array<SobolStream::GroupSeeds, kSeedTableGroups> seedTable;
    uint64_t tableSeed = 0;
    bool tableFilled = false;
    for (size_t bi = r.begin(); bi != r.end(); ++bi) {
      uint64_t here = 0;
      for (size_t w = bi * kContinuedPerBatch; w < std::min(work.size(), (bi + 1) * kContinuedPerBatch); ++w) {
        const ContinuedPath& cp = work[w];
        const PathState& st = kept.states[cp.state];
        const float time01 = u0 + scrambledVanDerCorput(uint32_t(cp.j), tracer.timeScramble) * (u1 - u0);
        const float time = scene.shutter.fromNormalized(time01);
        auto run = [&](auto& rng) -> uint64_t {
          Vec3f origin = st.origin, dir = st.dir;
          Rgb power = st.power;
          if (st.fromLight) {  // a moving light: emitted at the continuation's time
            const Light& light = scene.lights[st.light];
            EmittedRay ray;
            if (settings.kind == MapKind::Caustic && settings.projection) {
              if (!emitTowardTargets(light, tracer.targets, time01, scene.bounds, rng, ray)) return 0;
            } else {
              Vec2f uPos = rng.get2D(dims::kPhotonPosition);
              Vec2f uDir = rng.get2D(dims::kPhotonDirection);
              if (!emitFromLight(light, time01, scene.bounds, uPos, uDir, ray)) return 0;
            }
            power = ray.flux * st.power;
            origin = scene.spawnOrigin(ray.origin, ray.direction, ray.direction);
            dir = ray.direction;
          }
          return tracer.bounces(st.bounce, origin, dir, power, st.allSpecular, false, time01, time, st.light,
                                st.pathIndex, rng, energyScale, parts[bi], nullptr, nullptr);
        };
        if (settings.sampler == SamplerKind::Sobol) {
          // Round 0 of a frame drawing what every frame draws: the block
          // path's own sequence (its later dimensions, which the block pass
          // did not use); otherwise a sequence of its own.
          uint64_t seed = cp.round == 0 && c.streamKey == 0 ? kept.sobolSeed
                                                            : hashCombine(kept.sobolSeed, c.streamKey, cp.round);
          if (uint64_t high = st.pathIndex >> 32) seed = hashCombine(seed, high);
          if (!tableFilled || seed != tableSeed) {
            SobolStream::fillSeedTable(seed, seedTable.data(), kSeedTableGroups);
            tableSeed = seed;
            tableFilled = true;
          }
          SobolStream s{seed, uint32_t(st.pathIndex)};
          s.table = seedTable.data();
          s.tableSize = kSeedTableGroups;
          here += run(s);
        } else {
          Rng rng(hashCombine(settings.seed, uint64_t(settings.kind) + 1, cp.j), 0xc047);
          RandomStream s{&rng};
          here += run(s);
        }
      }
      rays += here;
    }
  });
  result.store.reserve([&] {
    size_t t = 0;
    for (const PhotonStore& p : parts) t += p.size();
    return t;
  }());
  result.store.appendBatches(parts);
  progress("continued photons", work.size(), work.size());
  result.rays = rays.load();
  result.seconds = timer.seconds();
  return result;
}

TraceResult traceGuidePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress) {
  TraceExtras x;
  x.guide = true;
  return traceMap(scene, settings, x, progress);
}

}  // namespace tdpm::photon
