// render/photon_map.h — a traced photon map ready for gathering: the store,
// its kd-tree (3D, or 4D for the space-time search, with a 3D copy for the
// standard estimate on paths that meet no motion), and what it cost.
// Held by pointer: a KdTree points into its store, so a map never moves.
//
// The volume map (MapKind::Volume, scenes with media only) is a beam map
// instead: `beams` (photon/volume_beam_map.h) holds the kd-tree over
// `store` and every photon's disc radius and time half-width; `tree`,
// `store3` and `tree3` stay empty. Its kernels (PhotonMapSettings::beam):
//   time      Kind::Time, k_s = the render's ks, the fraction the surface's,
//             max time distance the surface's (max_dt, else maxDtFraction
//             of the shutter), where the method is time-dependent and the
//             scene moves;
//   standard  Kind::Standard (k = ks) otherwise (static, standard,
//             accumulation frames, a still scene);
//   pass      Kind::Fixed with the pass's kernel (render/progressive.cpp).
// The eye side reads maps[MapKind::Volume]->beams (volumeBeams); it is
// empty (size 0) when the scene has no media (no volume map traced).
// Animation frames with the Time kernel hold two (render/animation.cpp
// frameMap): `beams` over the frame's time map, `beams3` (Standard, over
// `store3`, the shutter's photons alone) for the skip rule's standard form,
// as the surface maps' tree3.
#pragma once
#include <memory>
#include <string>

#include "core/progress.h"
#include "photon/kdtree.h"
#include "photon/tracer.h"
#include "photon/volume_beam_map.h"
#include "render/map_kinds.h"
#include "render/render_options.h"

namespace tdpm {

struct PhotonMap {
  photon::PhotonStore store;   // ordered for `tree`
  photon::KdTree tree;         // 3D, or 4D when built for the space-time search
  photon::PhotonStore store3;  // 4D maps only: a 3D-ordered copy
  photon::KdTree tree3;
  photon::VolumeBeamMap beams;   // MapKind::Volume only: built over `store` (see the top)
  photon::VolumeBeamMap beams3;  // animation frames' Time volume maps: the shutter's, over `store3`
  // Animations (render/animation.h): store3/tree3 hold only the frame's own
  // shutter, for the standard estimate, while `tree` spans the frame's time
  // window (its shutter plus what the time kernel may reach).
  bool separateStandard = false;
  size_t ownPhotons = 0;  // animations: the photons of the frame's own shutter (its stats)
  uint64_t emitted = 0;
  double traceSeconds = 0, buildSeconds = 0;
  std::string warning;  // from tracing: empty map, or fewer photons than wanted

  const photon::KdTree& spatialTree() const { return tree.spaceTime() || separateStandard ? tree3 : tree; }
  // The volume map the beam estimate reads: its time-dependent form reads
  // `beams`, its standard form the shutter's own where a frame keeps one.
  const photon::VolumeBeamMap& volumeBeams(bool timeDependent) const {
    return separateStandard && !timeDependent ? beams3 : beams;
  }
  size_t size() const { return store.size(); }
  double bytesPerPhoton() const;
};

struct PhotonMapSettings {
  photon::TraceSettings trace;
  photon::PathRange pass;  // a progressive pass's paths; pass.paths 0: sized by the tracer's pilot
  bool spaceTime = false;  // build the 4D tree (plus a 3D copy)
  float kappa = 1.0f;
  // MapKind::Volume: the beam kernels (see the top). A Time kernel on a
  // scene without motion is built as Standard; an infinite
  // maxTimeDistance becomes maxDtFraction of the shutter.
  photon::BeamBuildOptions beam;
  float maxDtFraction = 0.1f;
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

// The volume map's k-NN beam kernels from the options (render/photon_map.h
// top): Time for a time-dependent method, else Standard; k_s, the
// fraction, --max-dt. resolvedBeamOptions then fits them to the photons: a
// Time kernel on a scene without motion becomes Standard, an infinite max
// time distance maxDtFraction x shutterLength (the photons' shutter: the
// render's, a progressive frame's, an animation frame's).
photon::BeamBuildOptions beamOptionsFor(const RenderOptions& opt);
photon::BeamBuildOptions resolvedBeamOptions(photon::BeamBuildOptions beam, const Scene& scene, float maxDtFraction,
                                             float shutterLength);

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
