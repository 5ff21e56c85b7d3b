// render/caustic_guide.h — where the path tracer should aim to find
// caustics from area lights, learned from a small caustic photon map.
//
// Why: a caustic path (eye -> diffuse -> glass/mirror ... -> area light) is
// found by the path tracer only when a BSDF sample at the diffuse vertex
// happens to leave along the specular chain that ends on the light;
// next-event estimation cannot cross a delta interface. On
// scenes/cube-caustic.json such paths carry ~90% of the per-sample variance
// (/work/notes/sampling2.md). Seen from the floor through the ball, the
// 0.15 m lamp is an image ~1 degree across: aiming at the ball does not help
// (it fills a 36-degree cone over the box), and aiming along stored photon
// directions does not either (their 16-bit encoding errs by ~1.2 degrees).
// What does: each guide photon keeps the point where it left the last
// specular surface, so from a vertex x the direction toward that point is
// the direction a path must leave x in to retrace the photon's chain back
// to the light, corrected for x not being where the photon landed (Jensen
// 1995, "Importance driven path tracing using the photon map", with exit
// points instead of directions).
//
// At the first two diffuse-like vertices of an eye path, the k nearest
// guide photons within a radius, stored on surfaces facing about the same
// way, give k cones around the directions toward their exit points (as wide as those
// directions' spread, or as the photons' own spacing if wider), mixed with
// BSDF sampling by render/guided_sampling.h, which keeps the estimate
// unbiased whatever the guide holds. Where the photons are far, the guide's
// share of the mixture falls. An occupancy grid (render/guide_occupancy.h)
// answers for the many vertices with no photon near; elsewhere a vertex's
// photons come from its grid sub-cell's list of 8, cached before the first
// pixel (a k-NN per vertex cost 0.14-0.24x of an unguided path's instructions;
// the cones still aim from the vertex itself, docs/sampling.md). The
// guide is a fixed function of the scene and the seed,
// built before any pixel by every process alike, so images stay identical
// across threads and MPI ranks.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/progress.h"
#include "photon/kdtree.h"
#include "photon/store.h"
#include "render/guide_occupancy.h"
#include "render/guided_sampling.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

struct CausticGuideSettings {
  float fraction = 0.5f;    // c of the mixture; 0: no guide
  size_t photons = 50000;   // stored caustic photons wanted
  uint64_t seed = 1;
  SamplerKind sampler = SamplerKind::Sobol;
};

class CausticGuide {
 public:
  static constexpr int kNeighbours = 8;

  CausticGuide() = default;  // disabled
  // Traces the guide's photons (nothing when c = 0, or the scene has no
  // specular object or no area light).
  static CausticGuide build(const Scene& scene, const CausticGuideSettings& settings, const Progress& progress);

  bool enabled() const { return fraction_ > 0.0f; }
  size_t photonCount() const { return photons_.size(); }
  float radius() const { return std::sqrt(radius2_); }
  const GuideOccupancy& occupancy() const { return occupancy_; }
  // Cones for a vertex at p on material m with shading normal n (on the
  // side the path arrived from), and the mixture weight c there (at most
  // the settings' fraction); none for other than diffuse and plastic
  // materials, or with fewer than 2 usable guide photons within radius().
  void conesAt(const Material& m, Vec3f p, Vec3f n, GuideCones& out) const;

  // The kNeighbours nearest guide photons to p within radius(): their tree
  // indices and squared distances, in the order photon::KdTree::knn gives
  // (same traversal, same comparisons, so the same result bit for bit),
  // read from one 16-byte record per tree node instead of the store's four
  // arrays: at random places of a 200k-photon guide the k-NN waits on
  // memory, one cache miss per visited node instead of four. Returns count.
  int nearest(Vec3f p, uint32_t* index, float* dist2) const { return nearestWithin(p, radius2_, index, dist2); }
  const photon::KdTree& tree() const { return tree_; }

  // The neighbour cache: cells of the occupancy grid cut into
  // cacheSubdivision()^3 sub-cells; conesAt takes a vertex's photons from
  // its sub-cell's list (the kNeighbours nearest to the sub-cell's centre
  // within radius() + the sub-cell's half diagonal, filtered by distance
  // from the vertex) instead of a k-NN of its own.
  int cacheSubdivision() const { return cacheSub_; }
  size_t cacheEntries() const { return cacheIndex_.size() / kNeighbours; }
  size_t cacheBytes() const { return cacheIndex_.size() * sizeof(uint32_t) + occupancy_.cellCount() / 16; }
  // The photons (tree indices) a vertex at p takes its cones from: the
  // cache's list, or its own k-NN without a cache. Returns count.
  int candidates(Vec3f p, uint32_t* index, float* dist2) const;
  // Sub-cells per occupancy cell and axis for the cache; 0: no cache.
  static CausticGuide build(const Scene& scene, const CausticGuideSettings& settings, const Progress& progress,
                            int cacheSubdivision);

 private:
  float fraction_ = 0.0f;
  float radius2_ = 0.0f;
  float trust2_ = 0.0f;  // (median k-NN radius)^2: beyond it c falls
  std::unique_ptr<photon::PhotonStore> store_;  // positions, in the tree's order
  photon::KdTree tree_;
  struct Node {  // tree node i = photon i: position and split axis
    float x, y, z;
    uint32_t axis;
  };
  std::vector<Node> nodes_;
  // What a vertex reads of each of its photons, in one record (one cache
  // line fetch per photon), in the tree's order.
  struct GuidePhoton {
    Vec3f position;     // where it was stored (the cache's distance test)
    Vec3f exit;         // last specular vertex
    Vec3f normal;       // of the surface it was stored on, facing its arrival
    float oneMinusCos;  // 1 - cos of its cone's half-angle
  };
  std::vector<GuidePhoton> photons_;
  int nearestWithin(Vec3f p, float r2, uint32_t* index, float* dist2) const;
  void buildCache(int subdivision);
  int cacheSub_ = 0;
  // kNeighbours per sub-cell (one 32-byte record), by occupancy rank then
  // sub-cell; kNoPhoton after the last.
  static constexpr uint32_t kNoPhoton = 0xffffffffu;
  std::vector<uint32_t> cacheIndex_;
  // Where a vertex cannot find kMinFound photons within the radius: there
  // conesAt skips the k-NN (same result, most vertices are such).
  GuideOccupancy occupancy_;
};

}  // namespace tdpm
