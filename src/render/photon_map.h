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
  bool spaceTime = false;  // build the 4D tree (plus a 3D copy)
  float kappa = 1.0f;
};

std::unique_ptr<PhotonMap> buildPhotonMap(const Scene& scene, const PhotonMapSettings& settings,
                                          const Progress& progress);

}  // namespace tdpm
