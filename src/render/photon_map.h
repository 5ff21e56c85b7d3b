// render/photon_map.h — a traced photon map ready for gathering: the store,
// its kd-tree (3D, or 4D for the space-time search, with a 3D copy for the
// standard estimate on paths that meet no motion), and what it cost.
// Held by pointer: a KdTree points into its store, so a map never moves.
#pragma once
#include <memory>
#include <string>

#include "core/progress.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "render/map_kinds.h"
#include "render/render_options.h"

namespace tdpm {

struct PhotonMap {
  photon::PhotonStore store;   // ordered for `tree`
  photon::KdTree tree;         // 3D, or 4D when built for the space-time search
  photon::PhotonStore store3;  // 4D maps only: a 3D-ordered copy
  photon::KdTree tree3;
  // Animations (render/animation.h): store3/tree3 hold only the frame's own
  // shutter, for the standard estimate, while `tree` spans the frame's time
  // window (its shutter plus what the time kernel may reach).
  bool separateStandard = false;
  uint64_t emitted = 0;
  double traceSeconds = 0, buildSeconds = 0;
  std::string warning;  // from tracing: empty map, or fewer photons than wanted

  const photon::KdTree& spatialTree() const { return tree.spaceTime() || separateStandard ? tree3 : tree; }
  size_t size() const { return store.size(); }
  double bytesPerPhoton() const;
};

struct PhotonMapSettings {
  photon::TraceSettings trace;
  photon::PathRange pass;  // a progressive pass's paths; pass.paths 0: sized by the tracer's pilot
  bool spaceTime = false;  // build the 4D tree (plus a 3D copy)
  float kappa = 1.0f;
};

// Whether the options gather from a global map at all (final gather rays,
// or --global-direct): if not, none is traced.
inline bool wantsGlobalMap(const RenderOptions& opt) { return opt.visualizeGlobal || opt.gatherRays > 0; }

// Stored photons the options ask of each kind: its count (render/map_kinds.h
// table), 0 for a map the render does not gather from.
PerMap<size_t> photonsWanted(const RenderOptions& opt);

// The one trace set-up of every photon map (fixed-budget renders,
// accumulation frames, progressive passes, animation segments): the kind,
// the photons wanted, the seed, the bounces and the sampler from the
// options. Callers add when the paths happen and what else is theirs.
photon::TraceSettings traceSettingsFor(const RenderOptions& opt, MapKind kind, size_t wanted, uint64_t seed);

// Every map of a render from the options: photonsWanted (or `wanted`), and
// when the paths happen (spread over the shutter, or all at fixedTime01).
// The callers add the communicator and the 4D tree (a fixed-budget render,
// render/renderer.cpp), or the pass's path range (render/progressive.cpp).
PerMap<PhotonMapSettings> photonMapSettingsFor(const RenderOptions& opt, const PerMap<size_t>& wanted, uint64_t seed,
                                               bool spreadInTime, float fixedTime01);

std::unique_ptr<PhotonMap> buildPhotonMap(const Scene& scene, const PhotonMapSettings& settings,
                                          const Progress& progress);

// The maps of one render, accumulation frame or progressive pass, one per
// kind (a kind not wanted is an empty map, never null).
struct PhotonMaps {
  PerMap<std::unique_ptr<PhotonMap>> maps;
  const PhotonMap* operator[](MapKind k) const { return maps[k].get(); }
  PerMap<const PhotonMap*> view() const;
  // Bytes per stored photon over all maps (0 when none is stored).
  double bytesPerPhoton() const;
};

// The one builder: every kind's map, traced and built in kind order.
PhotonMaps buildPhotonMaps(const Scene& scene, const PerMap<PhotonMapSettings>& settings, const Progress& progress);

// The maps' figures into `st`: stored and emitted per kind, photon seconds,
// tracing warnings, bytes per photon.
void addMapFigures(RenderStats& st, const PhotonMaps& maps);

}  // namespace tdpm
