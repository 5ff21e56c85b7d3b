// photon/tracer.h — emission and tracing of photon paths in time.
// Each path draws one time (a scrambled van der Corput sequence over the
// shutter, or a fixed time for the static and accumulation methods) and is
// traced through the scene as it is at that time; every stored photon keeps
// it. Photons carry radiant energy Q = flux * ts / n_emitted (method.md
// section 2). Three maps, traced separately so each gets its own budget:
//  * caustic: paths L S+ D, stored at the first non-delta surface;
//  * global: every non-delta surface hit;
//  * volume (scenes with media): every scattering event in a medium,
//    never at surfaces; emission unaimed.
// In scenes with media every path walks through them (free flight,
// interfaces, scattering): photon/tracer_media.h, where the rules are.
// Work is split into fixed batches with their own seeds and concatenated in
// batch order, so the maps are identical for any thread count.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/progress.h"
#include "distributed/comm.h"
#include "math/bounds.h"
#include "photon/map_kind.h"
#include "photon/store.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm::photon {

// Time-invariant photons (animations, docs/animation.md section 7). A
// photon is time-invariant over a window of time when its light does not
// move and every segment of its path up to it misses the swept bounds of
// everything that moves over that window: then the path, and so the light
// it carries, is the same at every instant of the window. The test is the
// eye paths' (Scene::segmentMeetsMotion), over the window's bounds.
struct MotionBounds {
  std::vector<Bounds3f> boxes;  // each moving object's and area light's, over the window
  bool meets(Vec3f o, Vec3f d, float tMax) const {
    if (boxes.empty()) return false;
    Vec3f inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
    for (const Bounds3f& b : boxes)
      if (b.intersectsSegment(o, inv, 0.0f, tMax)) return true;
    return false;
  }
};
// The swept bounds over normalised times [u0, u1] of the scene's shutter:
// moving objects' over the interval, moving area lights' over the whole
// shutter (conservative).
MotionBounds motionBoundsOver(const Scene& scene, float u0, float u1);

// Which photons a trace keeps (TraceSettings::invariant).
enum class InvariantPhotons : uint8_t {
  All,   // every photon, unclassified
  Only,  // time-invariant photons only (a path ends where it first meets motion)
  None,  // photons whose path met motion (or whose light moves) only
};

struct TraceSettings {
  MapKind kind = MapKind::Caustic;
  size_t storedWanted = 100000;  // photons to store (the emitted count is chosen to reach it)
  uint64_t seed = 1;
  int maxBounces = 16;
  bool spreadInTime = true;      // false: every path at fixedTime01
  float fixedTime01 = 0.0f;
  // Caustic map: emit only toward the specular objects' swept bounding
  // spheres (projection maps). Same expected energies, far fewer wasted
  // paths; off only to measure that.
  bool projection = true;
  // Where a path's emission, bounce and roulette numbers come from
  // (docs/sampling.md): random = one PCG32 per batch (the maps of old),
  // sobol = Owen-scrambled Sobol indexed by the global path index.
  SamplerKind sampler = SamplerKind::Random;
  // Distributed: every rank traces a contiguous block of the batches (pilot
  // included) and receives everyone's photons in batch order, so each rank
  // holds the map one process would trace (distributed/comm.h).
  dist::Comm* comm = &dist::local();
  // When the paths happen, if not over the whole shutter (animation
  // segments and progressive animation frames): path times spread over
  // [timeOpen, timeClose] (scene seconds, inside the scene's shutter; NaN:
  // the whole shutter). Energies use ts = timeClose - timeOpen.
  float timeOpen = std::numeric_limits<float>::quiet_NaN(), timeClose = std::numeric_limits<float>::quiet_NaN();
  // Caustic map: sharp metals (Material::isGlossy) bounce caustic paths
  // like mirrors, so L (S|G)+ D is stored (photons are aimed at them too);
  // false: L S+ D with delta surfaces only (the path tracer's guide, whose
  // cones aim at the last delta exit point).
  bool glossyCaustics = true;
  // Animations: keep photons by whether they are time-invariant over
  // `motion` (required unless All). Emission counts and energies are as for
  // All: the kept photons are exactly those All would store of their kind.
  InvariantPhotons invariant = InvariantPhotons::All;
  const MotionBounds* motion = nullptr;
  // With InvariantPhotons::Only: keep, for every path that meets motion, its
  // state before the first segment that does (TraceResult::kept), so that
  // frames can continue it at their own times (continuePaths).
  bool keepMoving = false;
  // The pilot's first round, in batches (it grows 8x a round while nothing
  // is stored): the stored photons per path it measures size the emission.
  uint32_t pilotBatches = 16;
};

// A path of a block's pass (InvariantPhotons::Only, keepMoving) at its last
// time-invariant vertex: everything before the segment that first meets
// the motion bounds, which is the same at every instant of the block
// (docs/animation.md section 8). `power` is the flux over the densities so
// far (no energy scale); a path from a moving light has no invariant part
// and keeps only its light (fromLight: power = 1 / the light's choice
// probability, the emission redone at the continuation's time).
struct PathState {
  Vec3f origin, dir;     // the ray of the segment that meets motion (origin spawned off its surface)
  Rgb power;
  uint64_t pathIndex = 0;  // the block path's global index (Sobol sample index)
  uint32_t light = 0;
  uint16_t bounce = 0;     // the loop's vertex count at that segment
  bool allSpecular = true;
  bool fromLight = false;
};

// A block pass's kept states (in path order) and what a continuation needs
// to draw the rest of their numbers as the block pass would have.
struct KeptPaths {
  std::vector<PathState> states;  // sorted by pathIndex
  uint64_t emitted = 0;           // N: the block pass's paths
  uint64_t sobolSeed = 0;         // its paths' Sobol "pixel" seed
};

// A frame segment's continuation (continuePaths): `virtualPaths` paths
// over the segment's time, path j taking block path (firstVirtual + j) mod
// N; those that met motion are continued from their state at time j's
// stratified time, the others carry invariant light, which the block's
// shared set holds. Round r = (firstVirtual + j) / N > 0 reuses a block
// path with fresh numbers (Sobol seed hashed with r and streamKey).
struct Continuation {
  float storeT0 = 0, storeT1 = 1;
  uint64_t firstVirtual = 0, virtualPaths = 0;
  uint64_t streamKey = 0;  // 0: a frame draws what every frame draws (common random numbers)
};

// What one caller alone adds to a trace: each has its own entry point below.
// Progressive passes (render/progressive.h): exactly `paths` paths (a
// multiple of kPathsPerBatch), no pilot, with global path indices
// [firstPath, firstPath + paths) (firstPath a multiple of kPathsPerBatch
// too): pass i continues the sequences of the passes before.
struct PathRange {
  uint64_t firstPath = 0;
  uint64_t paths = 0;
};
// Animation segments (render/animation.h) share one grid of time bins: the
// store quantises time over [storeT0, storeT1], and the emission is sized
// by `storedPerPath` (> 0: photons stored per emitted path, measured by a
// pilot over the frame period) instead of a pilot run of its own.
struct SegmentStore {
  float storeT0 = 0, storeT1 = 1;
  double storedPerPath = 0;
};

// Paths per batch: the unit of emission counts and of PathRange::firstPath.
constexpr uint64_t kPathsPerBatch = 1024;
// A map emits at most this many paths per wanted photon (a scene that
// stores almost nothing stops there, with a warning): also the bound a
// progressive state's paths per pass must keep (render/progressive_check.h).
constexpr double kMaxPathsPerPhoton = 1000.0;

// A caustic photon's last specular vertex, and the normal of the surface
// it was stored on, facing the side it arrived from.
struct ExitPoint {
  Vec3f point;
  Vec3f normal;
};

struct TraceResult {
  PhotonStore store;
  uint64_t emitted = 0;  // n_e: paths emitted from all lights
  uint64_t rays = 0;     // rays cast, pilot included (throughput of the whole pass)
  double seconds = 0;
  std::string warning;   // set when the map is empty or smaller than wanted
  double storedPerPath = 0;  // the pilot's rate (or the one given), 0 when nothing is stored
  std::vector<ExitPoint> exitPoints;  // traceGuidePhotons: photon i's, in store order
  KeptPaths kept;                     // TraceSettings::keepMoving
  uint64_t continued = 0;             // continuePaths: states continued
};

// Shutter interval the photon store quantises time over. A zero-length
// shutter uses a nominal 1-second range (energies and estimates use the
// same length, so it cancels).
void photonTimeRange(const Scene& scene, float& t0, float& t1);

// Traces one map. An empty result (no lights, or no specular surface for a
// caustic map) is valid; a scene that stores almost nothing stops after a
// bounded number of paths instead of hanging.
TraceResult tracePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress);
// A progressive pass's paths (PathRange); `range.paths` 0 traces as above.
TraceResult tracePassPhotons(const Scene& scene, const TraceSettings& settings, const PathRange& range,
                             const Progress& progress);
// An animation segment's paths (SegmentStore).
TraceResult traceSegmentPhotons(const Scene& scene, const TraceSettings& settings, const SegmentStore& segment,
                                const Progress& progress);
// A segment's photons of the paths that meet motion, continued from a
// block pass's states (settings: the segment's times and seed, the kind,
// sampler and bounces of the block pass; InvariantPhotons is not used:
// every photon after the state is kept). Energies Q = power x (timeClose -
// timeOpen) / virtualPaths. Scenes without media only.
TraceResult continuePaths(const Scene& scene, const TraceSettings& settings, const KeptPaths& kept,
                          const Continuation& continuation, const Progress& progress);
// The path tracer's caustic guide (render/caustic_guide.h): emitted from
// area lights only (point, spot and sun caustics are not paths a path
// tracer can find), each stored photon's last specular vertex kept in
// TraceResult::exitPoints with the normal of the surface it was stored on.
// One process only (not under MPI).
TraceResult traceGuidePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress);

// Whether any path could contribute to a caustic map (a delta-only surface).
// Has a caustic generator: a mirror or glass, or (glossy) a sharp metal.
bool sceneHasSpecular(const Scene& scene, bool glossy = true);

}  // namespace tdpm::photon
