// render/photon_map.cpp — trace, then build the tree(s).
#include "render/photon_map.h"

#include "core/timer.h"

namespace tdpm {

PhotonMapSettings photonMapSettingsFor(const RenderOptions& opt, photon::MapKind kind, size_t wanted, uint64_t seed,
                                       bool spreadInTime, float fixedTime01) {
  PhotonMapSettings ms;
  ms.trace.kind = kind;
  ms.trace.storedWanted = wanted;
  ms.trace.seed = seed;
  ms.trace.maxBounces = opt.maxDepth;
  ms.trace.spreadInTime = spreadInTime;
  ms.trace.fixedTime01 = fixedTime01;
  ms.trace.sampler = opt.sampler;
  return ms;
}

double PhotonMap::bytesPerPhoton() const {
  if (store.empty()) return 0.0;
  double bytes = double(store.bytesAllocated()) + double(store3.bytesAllocated());
  return bytes / double(store.size());
}

std::unique_ptr<PhotonMap> buildPhotonMap(const Scene& scene, const PhotonMapSettings& settings,
                                          const Progress& progress) {
  auto map = std::make_unique<PhotonMap>();
  photon::TraceResult traced = photon::tracePhotons(scene, settings.trace, progress);
  map->store = std::move(traced.store);
  map->emitted = traced.emitted;
  map->traceSeconds = traced.seconds;
  map->warning = traced.warning;
  Timer timer;
  photon::KdBuildOptions opt;
  opt.spaceTime = settings.spaceTime;
  opt.kappa = settings.kappa;
  opt.comm = settings.trace.comm;  // under mpirun the ranks share the build
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

}  // namespace tdpm
