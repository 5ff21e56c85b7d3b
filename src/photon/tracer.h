// photon/tracer.h — emission and tracing of photon paths in time.
// Each path draws one time (a scrambled van der Corput sequence over the
// shutter, or a fixed time for the static and accumulation methods) and is
// traced through the scene as it is at that time; every stored photon keeps
// it. Photons carry radiant energy Q = flux * ts / n_emitted (method.md
// section 2). Two maps, traced separately so each gets its own budget:
//  * caustic: paths L S+ D, stored at the first non-delta surface;
//  * global: every non-delta surface hit.
// Work is split into fixed batches with their own seeds and concatenated in
// batch order, so the maps are identical for any thread count.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/progress.h"
#include "distributed/comm.h"
#include "photon/map_kind.h"
#include "photon/store.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm::photon {

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
  // Animations (render/animation.h) trace the timeline in segments: path
  // times spread over [timeOpen, timeClose] (scene seconds, inside the
  // scene's shutter; NaN: the whole shutter) and the store quantises time
  // over [storeT0, storeT1] (NaN: the path times' range), so that segments
  // share one grid of time bins. Energies use ts = timeClose - timeOpen.
  float timeOpen = std::numeric_limits<float>::quiet_NaN(), timeClose = std::numeric_limits<float>::quiet_NaN();
  float storeT0 = std::numeric_limits<float>::quiet_NaN(), storeT1 = std::numeric_limits<float>::quiet_NaN();
  // > 0: photons stored per emitted path, measured before (a pilot over the
  // whole timeline): the pilot run is skipped and the emission sized by it.
  double storedPerPath = 0;
  // Progressive passes (render/progressive.h): paths > 0 traces exactly
  // that many paths (a multiple of kPathsPerBatch), no pilot, with global
  // path indices [firstPath, firstPath + paths) (firstPath a multiple of
  // kPathsPerBatch too): pass i continues the sequences of the passes before.
  uint64_t firstPath = 0;
  uint64_t paths = 0;
  // The path tracer's caustic guide (render/caustic_guide.h): emit from area
  // lights only (point, spot and sun caustics are not paths a path tracer
  // can find), and keep each stored photon's last specular vertex in
  // TraceResult::exitPoints, with the normal of the surface it was stored
  // on (one process only, not under MPI).
  bool areaLightsOnly = false;
  bool keepExitPoints = false;
  // Caustic map: sharp metals (Material::isGlossy) bounce caustic paths
  // like mirrors, so L (S|G)+ D is stored (photons are aimed at them too);
  // false: L S+ D with delta surfaces only (the path tracer's guide, whose
  // cones aim at the last delta exit point).
  bool glossyCaustics = true;
};

// Paths per batch: the unit of emission counts and of TraceSettings::firstPath.
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
  std::vector<ExitPoint> exitPoints;  // keepExitPoints: photon i's, in store order
};

// Shutter interval the photon store quantises time over. A zero-length
// shutter uses a nominal 1-second range (energies and estimates use the
// same length, so it cancels).
void photonTimeRange(const Scene& scene, float& t0, float& t1);

// Traces one map. An empty result (no lights, or no specular surface for a
// caustic map) is valid; a scene that stores almost nothing stops after a
// bounded number of paths instead of hanging.
TraceResult tracePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress);

// Whether any path could contribute to a caustic map (a delta-only surface).
// Has a caustic generator: a mirror or glass, or (glossy) a sharp metal.
bool sceneHasSpecular(const Scene& scene, bool glossy = true);

}  // namespace tdpm::photon
