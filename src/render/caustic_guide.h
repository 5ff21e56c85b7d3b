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
// photons come from its grid sub-cell's list of 8, filled the first time a
// vertex lands in the sub-cell (a k-NN per vertex cost 0.14-0.24x of an
// unguided path's instructions; the cones still aim from the vertex
// itself, docs/sampling.md). The guide, and
// each list, is a fixed function of the scene and the seed (a list holds
// the photons nearest its sub-cell's centre, whichever vertex asks first),
// so images stay identical across threads and MPI ranks.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/huge_pages.h"
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
  size_t photonCount() const { return photonCount_; }
  uint64_t photonsEmitted() const { return emitted_; }  // paths traced for the guide
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
  // from the vertex) instead of a k-NN of its own. A list is filled the
  // first time a vertex lands in its sub-cell (most sub-cells lie off every
  // surface and are never asked for), into zeroed memory from the system.
  int cacheSubdivision() const { return cacheSub_; }
  size_t cacheEntries() const { return cacheEntries_; }
  // Bytes reserved (address space; resident only where filled).
  size_t cacheBytes() const { return cacheEntries_ * kNeighbours * sizeof(uint32_t) + occupancy_.bytes(); }
  size_t cacheFilled() const;  // sub-cells whose list has been filled (a scan: for stats and tests)
  // Bytes of the photon records and tree nodes kept for rendering.
  size_t photonBytes() const {
    return photonCount_ * (sizeof(GuidePhoton) + 2 * sizeof(uint32_t)) + nodes_.size() * sizeof(Node) +
           (store_ ? store_->bytesAllocated() : 0);
  }
  // The photons a vertex at p takes its cones from, as record indices
  // (treeIndexOfRecord maps them to tree()'s): the cache's list, or its own
  // k-NN without a cache. Returns count.
  int candidates(Vec3f p, uint32_t* index, float* dist2) const;
  uint32_t treeIndexOfRecord(uint32_t record) const { return treeOfRecord_[record]; }
  // Sub-cells per occupancy cell and axis for the cache; 0: no cache.
  static CausticGuide build(const Scene& scene, const CausticGuideSettings& settings, const Progress& progress,
                            int cacheSubdivision);

 private:
  float fraction_ = 0.0f;
  uint64_t emitted_ = 0;
  float radius2_ = 0.0f;
  float trust2_ = 0.0f;  // (median k-NN radius)^2: beyond it c falls
  std::unique_ptr<photon::PhotonStore> store_;  // positions, in the tree's order
  photon::KdTree tree_;
  struct Node {  // tree node i = photon i: position and split axis
    float x, y, z;
    uint32_t axis;
  };
  std::vector<Node> nodes_;
  // What a vertex reads of each of its photons, in one 32-byte record
  // aligned to 32 (never split over two cache lines).
  struct alignas(32) GuidePhoton {
    Vec3f position;     // where it was stored (the cache's distance test)
    Vec3f exit;         // last specular vertex
    float oneMinusCos;  // 1 - cos of its cone's half-angle
    // Normal of the surface it was stored on, facing its arrival, x127
    // rounded: only tested against 60 degrees (kMinNormalCosine), where
    // the rounding moves the test by < 1 degree.
    int8_t normal[3];
    uint8_t unused;
    Vec3f facing() const { return Vec3f(float(normal[0]), float(normal[1]), float(normal[2])) * (1.0f / 127.0f); }
  };
  static_assert(sizeof(GuidePhoton) == 32, "one guide photon record is 32 bytes");
  // The records: photons_ in the tree's order while building; then
  // records_, in Morton order of position (orderRecords; treeOfRecord_ and
  // recordOfTree_ map between the two), on 2 MB pages (core/huge_pages.h).
  std::vector<GuidePhoton> photons_;
  HugePageBuffer recordMemory_;
  const GuidePhoton* records_ = nullptr;
  size_t photonCount_ = 0;
  std::vector<uint32_t> treeOfRecord_, recordOfTree_;
  void orderRecords();
  void setConeAngles();  // every photon's cone half-angle (build)
  int nearestWithin(Vec3f p, float r2, uint32_t* index, float* dist2) const;
  void allocateCache(int subdivision);
  // The sub-cell's list (record indices, in the k-NN's heap order), filled now
  // if no vertex has asked for it yet. Returns its length.
  int cachedList(size_t entry, Vec3f centre, uint32_t* list) const;
  int cacheSub_ = 0;
  float cacheReach2_ = 0.0f;  // (radius + half a sub-cell's diagonal)^2, a little more
  // kNeighbours slots per sub-cell (one 32-byte record), by occupancy rank
  // then sub-cell. A slot holds a record index + 1, 0 after the list's last;
  // slot 0 is 0 while the list is unfilled and kFilledEmpty for a filled
  // empty list. Slot 0 is written last (release) and read first (acquire),
  // so a reader sees a whole list or none; two threads filling one list
  // write the same values.
  static constexpr uint32_t kFilledEmpty = 0xffffffffu;
  HugePageBuffer cacheMemory_;
  std::atomic<uint32_t>* cache_ = nullptr;
  size_t cacheEntries_ = 0;
  // Where a vertex cannot find kMinFound photons within the radius: there
  // conesAt skips the k-NN (same result, most vertices are such).
  GuideOccupancy occupancy_;
};

}  // namespace tdpm
