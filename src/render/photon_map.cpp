// render/photon_map.cpp — the one set-up and builder of a render's photon
// maps: trace each kind, then build its tree(s).
#include "render/photon_map.h"

#include <algorithm>
#include <cmath>

#include "core/timer.h"
#include "estimate/estimators.h"
#include "scene/render_method.h"

namespace tdpm {

PerMap<size_t> photonsWanted(const RenderOptions& opt) {
  PerMap<size_t> wanted;
  for (MapKind k : kAllMapKinds) {
    const MapKindInfo& row = mapKindInfo(k);
    wanted[k] = row.onlyWhenGathered && !wantsGlobalMap(opt) ? 0 : opt.*row.photons;
  }
  return wanted;
}

photon::TraceSettings traceSettingsFor(const RenderOptions& opt, MapKind kind, size_t wanted, uint64_t seed) {
  photon::TraceSettings ts;
  ts.kind = kind;
  ts.storedWanted = wanted;
  ts.seed = seed;
  // A volume photon stored at its (b+1)-th scattering event is read along
  // an eye segment, where it closes a path of b + 1 scattering vertices:
  // max_depth D keeps events b < D, as the volumetric path tracer's D
  // vertices (max_depth 1: single scattering in both). Surface maps keep
  // their bounce count.
  ts.maxBounces = kind == MapKind::Volume ? std::max(0, opt.maxDepth - 1) : opt.maxDepth;
  ts.sampler = opt.sampler;
  return ts;
}

PerMap<PhotonMapSettings> photonMapSettingsFor(const RenderOptions& opt, const PerMap<size_t>& wanted, uint64_t seed,
                                               bool spreadInTime, float fixedTime01) {
  PerMap<PhotonMapSettings> all;
  for (MapKind k : kAllMapKinds) {
    PhotonMapSettings& ms = all[k];
    ms.trace = traceSettingsFor(opt, k, wanted[k], seed);
    ms.trace.spreadInTime = spreadInTime;
    ms.trace.fixedTime01 = fixedTime01;
  }
  all[MapKind::Volume].beam = beamOptionsFor(opt);
  all[MapKind::Volume].maxDtFraction = opt.maxDtFraction;
  return all;
}

photon::BeamBuildOptions beamOptionsFor(const RenderOptions& opt) {
  photon::BeamBuildOptions beam;
  beam.kind = renderMethodTraits(opt.method).timeDependentEstimate ? photon::BeamBuildOptions::Kind::Time
                                                                   : photon::BeamBuildOptions::Kind::Standard;
  beam.ks = opt.effectiveVolumeK();
  beam.fraction = opt.estimate.fraction;
  beam.maxTimeDistance = opt.estimate.maxTimeDistance;
  beam.minTimePhotons = estimate::kMinTimePhotons;
  return beam;
}

photon::BeamBuildOptions resolvedBeamOptions(photon::BeamBuildOptions beam, const Scene& scene, float maxDtFraction,
                                             float shutterLength) {
  if (beam.kind == photon::BeamBuildOptions::Kind::Time && !scene.hasMotion)
    beam.kind = photon::BeamBuildOptions::Kind::Standard;
  if (!std::isfinite(beam.maxTimeDistance)) beam.maxTimeDistance = maxDtFraction * shutterLength;
  return beam;
}

double PhotonMap::bytesPerPhoton() const {
  if (store.empty()) return 0.0;
  if (beams.size() > 0)
    return beams.bytesPerPhoton() + beams3.bytesPerPhoton() * double(store3.size()) / double(store.size());
  double bytes = double(store.bytesAllocated()) + double(store3.bytesAllocated());
  return bytes / double(store.size());
}

std::unique_ptr<PhotonMap> buildPhotonMap(const Scene& scene, const PhotonMapSettings& settings,
                                          const Progress& progress) {
  auto map = std::make_unique<PhotonMap>();
  photon::TraceResult traced = photon::tracePassPhotons(scene, settings.trace, settings.pass, progress);
  map->store = std::move(traced.store);
  map->emitted = traced.emitted;
  map->traceSeconds = traced.seconds;
  map->warning = traced.warning;
  Timer timer;
  photon::KdBuildOptions opt;
  opt.spaceTime = settings.spaceTime;
  opt.kappa = settings.kappa;
  opt.comm = settings.trace.comm;  // under mpirun the ranks share the build
  if (settings.trace.kind == MapKind::Volume) {
    const float ts = std::isfinite(settings.trace.timeOpen) ? settings.trace.timeClose - settings.trace.timeOpen
                                                            : scene.shutter.length();
    const photon::BeamBuildOptions beam = resolvedBeamOptions(settings.beam, scene, settings.maxDtFraction, ts);
    if (!map->store.empty()) map->beams = photon::VolumeBeamMap::build(map->store, beam);
    map->buildSeconds = timer.seconds();
    return map;
  }
  if (settings.spaceTime) {
    map->store3 = map->store;
    photon::KdBuildOptions opt3;
    opt3.comm = settings.trace.comm;
    map->tree3 = photon::KdTree::build(map->store3, opt3);
  }
  map->tree = photon::KdTree::build(map->store, opt);
  map->buildSeconds = timer.seconds();
  return map;
}

PerMap<const PhotonMap*> PhotonMaps::view() const {
  PerMap<const PhotonMap*> v;
  for (MapKind k : kAllMapKinds) v[k] = maps[k].get();
  return v;
}

double PhotonMaps::bytesPerPhoton() const {
  size_t n = 0;
  for (MapKind k : kAllMapKinds) n += maps[k]->size();
  if (n == 0) return 0.0;
  double bytes = 0.0;
  for (MapKind k : kAllMapKinds) bytes += maps[k]->bytesPerPhoton() * double(maps[k]->size());
  return bytes / double(n);
}

PhotonMaps buildPhotonMaps(const Scene& scene, const PerMap<PhotonMapSettings>& settings, const Progress& progress) {
  PhotonMaps maps;
  for (MapKind k : kAllMapKinds) maps.maps[k] = buildPhotonMap(scene, settings[k], progress);
  return maps;
}

void addMapFigures(RenderStats& st, const PhotonMaps& maps) {
  for (MapKind k : kAllMapKinds) {
    const PhotonMap& m = *maps[k];
    st.photonSeconds += m.traceSeconds + m.buildSeconds;
    if (!m.warning.empty()) st.warnings.push_back(m.warning);
    st.maps[k].stored += m.size();
    st.maps[k].emitted += m.emitted;
  }
  size_t n = 0;
  for (MapKind k : kAllMapKinds) n += maps[k]->size();
  if (n > 0) st.bytesPerPhoton = maps.bytesPerPhoton();  // else an earlier frame's stands
}

}  // namespace tdpm
