// photon/kdtree.h — the left-balanced kd-tree over a PhotonStore (Jensen,
// "Realistic Image Synthesis Using Photon Mapping", 2001): a heap layout in
// which node i has children 2i+1 and 2i+2 and *is* photon i. Building
// reorders the store in place and writes only the split axis into the
// photons' flag bits, so the tree costs no memory beyond the store.
//
// Two variants share the layout and the code:
//  * 3D: keys x, y, z; k-nearest-neighbour search in space.
//  * 4D (space-time): a fourth key sqrt(kappa) * t_p (bin centre), so that
//    squared distances are d^2 = |x_p - x|^2 + kappa (t_p - t)^2
//    (method.md section 4, the alternative search). Split axis 3 = time.
// A store is ordered for one variant at a time (they reorder differently).
//
// Queries write into a KnnQuery, a per-thread object with fixed-capacity
// arrays (max-heap of candidates, traversal stack): no allocation per query.
#pragma once
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "math/vec.h"
#include "photon/store.h"

namespace tdpm::dist {
class Comm;
}

namespace tdpm::photon {

// Reusable per-thread query state and results. After a query, the first
// `count` entries of index/dist2 are the photons found (in heap order, not
// sorted), and radius2 is the squared radius of the search ball:
//  * count == k: the largest squared distance among them (the k-th nearest);
//  * count <  k: every photon within the maximum radius was found, and
//    radius2 is the maximum radius squared (the ball that holds them).
class KnnQuery {
 public:
  explicit KnnQuery(int capacity = 512);
  int capacity() const { return capacity_; }
  void reserve(int capacity);

  int count = 0;
  float radius2 = 0.0f;     // see above
  float maxFound2 = 0.0f;   // largest squared distance among the found
  uint32_t* index() { return index_.data(); }
  float* dist2() { return dist2_.data(); }
  const uint32_t* index() const { return index_.data(); }
  const float* dist2() const { return dist2_.data(); }

 private:
  friend class KdTree;
  int capacity_ = 0;
  std::vector<uint32_t> index_;
  std::vector<float> dist2_;
  // A deferred internal node: the node itself (tested after its near
  // subtree, when the radius has shrunk) and its far child (0 if none), the
  // squared distance from the query to the far cell -- a lower bound for the
  // node too, which lies on the splitting plane -- and the far cell's
  // per-axis offsets that sum to it (Arya & Mount's incremental distance).
  struct StackEntry {
    uint32_t node, far;
    float cellDist2;
    float offset[4];
  };
  std::vector<StackEntry> stack_;  // never deeper than the tree
};

// Moves the farthest of the first `found` results to slot 0 (a swap of
// index and distance): the estimators that leave out the photon on the
// search ball's boundary (the (k-1)/V rule) skip slot 0 after this.
inline void moveFarthestFirst(KnnQuery& q, int found) {
  uint32_t* idx = q.index();
  float* d2 = q.dist2();
  int far = 0;
  for (int i = 1; i < found; ++i)
    if (d2[i] > d2[far]) far = i;
  std::swap(idx[0], idx[far]);
  std::swap(d2[0], d2[far]);
}

// Reusable per-thread results of a fixed-radius query (KdTree::range): every
// photon within the radius, in traversal order. The arrays grow to the
// largest result seen and are then reused: no allocation per query after
// warm-up.
class RangeQuery {
 public:
  int count = 0;
  const uint32_t* index() const { return index_.data(); }
  const float* dist2() const { return dist2_.data(); }
  size_t capacity() const { return index_.size(); }

 private:
  friend class KdTree;
  void grow();
  std::vector<uint32_t> index_;
  std::vector<float> dist2_;
};

struct KdBuildOptions {
  bool spaceTime = false;  // build the 4D variant
  float kappa = 1.0f;      // 4D metric weight (distance^2 per second^2)
  size_t parallelCutoff = 1 << 15;  // subtrees smaller than this build serially
  // If set, receives order[i] = the index photon i had before the build
  // (lets callers keep side data, e.g. float times in tests, in step).
  std::vector<uint32_t>* order = nullptr;
  // Under mpirun (a distributed Comm; every rank holds the same store):
  // every rank makes the top splits, each builds its share of the subtrees
  // below them, and the subtrees' heap slots (photon index and split axis,
  // 5 bytes a photon) are allgathered. The tree is the one-process tree,
  // bit for bit (docs/distributed.md). Collective: every rank calls build.
  dist::Comm* comm = nullptr;
};

class KdTree {
 public:
  KdTree() = default;
  // Reorders `store` into heap order and records split axes; `store` must
  // outlive the tree and not change until the next build. Parallel (TBB).
  static KdTree build(PhotonStore& store, const KdBuildOptions& options = {});

  const PhotonStore& store() const { return *store_; }
  size_t size() const { return n_; }
  bool spaceTime() const { return spaceTime_; }
  float kappa() const { return kappa_; }
  // Heap bytes per photon of store + tree. The tree allocates nothing (the
  // split axes live in the store's flag bits), so this is the store's
  // figure; the KdTree object itself is a few bytes, independent of n.
  double bytesPerPhoton() const;

  // k nearest photons to p within maxRadius2 (3D variant). Returns count.
  int knn(Vec3f p, int k, float maxRadius2, KnnQuery& q) const;
  // k nearest in the space-time metric around (p, t) within maxDist2
  // (4D variant): dist2 entries are |dx|^2 + kappa dt^2.
  int knn4(Vec3f p, float t, int k, float maxDist2, KnnQuery& q) const;
  // Every photon with |x_p - p|^2 <= radius2 (3D variant), into q.
  // Returns q.count. A plain depth-first walk: the radius never shrinks, so
  // unlike knn there is no heap and no deferred node test.
  int range(Vec3f p, float radius2, RangeQuery& q) const;

 private:
  template <int D>
  int knnImpl(const float* key, int k, float maxRadius2, KnnQuery& q) const;

  const PhotonStore* store_ = nullptr;
  size_t n_ = 0;
  bool spaceTime_ = false;
  float kappa_ = 1.0f;
  // 4D time key of bin q: sqrt(kappa) * binCentre(q) = timeBase_ + q * timeStep_.
  float timeBase_ = 0.0f, timeStep_ = 0.0f;
};

}  // namespace tdpm::photon
