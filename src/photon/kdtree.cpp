// photon/kdtree.cpp — parallel build of the left-balanced kd-tree and the
// k-nearest-neighbour search (3D and 4D share one template).
#include "photon/kdtree.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "distributed/comm.h"
#include "photon/knn_heap.h"

namespace tdpm::photon {

KnnQuery::KnnQuery(int capacity) { reserve(capacity); }

void KnnQuery::reserve(int capacity) {
  if (capacity <= capacity_) return;
  capacity_ = capacity;
  index_.resize(size_t(capacity) + 4);  // + the heap's sentinel slots
  dist2_.resize(size_t(capacity) + 4);
  stack_.resize(128);  // > tree height for any size_t photon count
}

// ---- build ----

namespace {

// Number of nodes in the left subtree of a left-balanced (complete, filled
// left to right) binary tree of n >= 2 nodes: the levels above the last are
// full; the last level fills the left subtree first.
size_t leftSubtreeSize(size_t n) {
  int h = 63 - __builtin_clzll(uint64_t(n));  // floor(log2 n) >= 1
  size_t half = size_t(1) << (h - 1);         // last-level capacity of the left subtree
  size_t full = (size_t(1) << h) - 1;         // nodes in the full levels
  size_t last = n - full;
  return half - 1 + std::min(last, half);
}

// The builder works on a compact copy of the keys (16 or 20 bytes per
// photon, freed after the build): nth_element on contiguous records is much
// faster than on indices into the store's separate arrays.
template <int D>
struct Item {
  float k[D];
  uint32_t idx;
};

template <int D>
struct Box {
  float lo[D], hi[D];
  Box() {
    for (int a = 0; a < D; ++a) {
      lo[a] = std::numeric_limits<float>::infinity();
      hi[a] = -std::numeric_limits<float>::infinity();
    }
  }
  Box& extend(const Item<D>* it, size_t n) {
    for (size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) {
        lo[a] = std::min(lo[a], it[i].k[a]);
        hi[a] = std::max(hi[a], it[i].k[a]);
      }
    return *this;
  }
  Box& merge(const Box& b) {
    for (int a = 0; a < D; ++a) {
      lo[a] = std::min(lo[a], b.lo[a]);
      hi[a] = std::max(hi[a], b.hi[a]);
    }
    return *this;
  }
};

template <int D>
struct Builder {
  Item<D>* items;
  uint32_t* order;  // order[heap node] = original photon index
  uint8_t* axes;    // split axis per heap node
  size_t cutoff;

  // Subtree rooted at heap node `node` holds it[0, n). The split axis is
  // the widest extent of the photons' actual bounds: Jensen's cell bounds
  // cut at each split are cheaper, but on surfaces (a floor at y = 0 under a
  // wall) they keep a phantom extent in y and split on it, which for equal
  // keys is an arbitrary partition: overlapping cells that every query must
  // enter on both sides. The scan costs less than the nth_element after it.
  void build(Item<D>* it, size_t n, size_t node) const {
    if (n == 0) return;
    if (n == 1) {
      order[node] = it[0].idx;
      axes[node] = 0;
      return;
    }
    size_t m = split(it, n, node);
    auto left = [&] { build(it, m, 2 * node + 1); };
    auto right = [&] { build(it + m + 1, n - m - 1, 2 * node + 2); };
    if (n >= cutoff) {
      tbb::parallel_invoke(left, right);
    } else {
      left();
      right();
    }
  }

  // Node `node` of n >= 2 photons it[0, n): partitions them around the
  // median of the widest axis, records the node; returns the left subtree's size.
  size_t split(Item<D>* it, size_t n, size_t node) const {
    Box<D> box = n >= cutoff ? tbb::parallel_reduce(
                                   tbb::blocked_range<size_t>(0, n, 1 << 14), Box<D>{},
                                   [it](const tbb::blocked_range<size_t>& r, Box<D> b) {
                                     return b.extend(it + r.begin(), r.size());
                                   },
                                   [](Box<D> a, const Box<D>& b) { return a.merge(b); })
                             : Box<D>{}.extend(it, n);
    const float *lo = box.lo, *hi = box.hi;
    int axis = 0;
    float ext = hi[0] - lo[0];
    for (int a = 1; a < D; ++a)
      if (hi[a] - lo[a] > ext) { ext = hi[a] - lo[a]; axis = a; }
    size_t m = leftSubtreeSize(n);
    std::nth_element(it, it + m, it + n, [axis](const Item<D>& a, const Item<D>& b) { return a.k[axis] < b.k[axis]; });
    order[node] = it[m].idx;
    axes[node] = uint8_t(axis);
    return m;
  }
};

// ---- the build split over the ranks of an mpirun job ----

// Below this many photons every rank builds the whole tree (the exchange
// would cost more than it saves).
constexpr size_t kDistributedBuildMin = size_t(1) << 14;

// A subtree below the top splits: its heap root and its photons' range in
// the items array.
struct Subtree {
  size_t node, first, n;
};

// Heap slots of the subtree rooted at `root` in a heap of `total` nodes,
// level by level (each level's slots are contiguous).
template <class Fn>
void forEachSlot(size_t root, size_t total, Fn&& fn) {
  for (size_t lo = root, width = 1; lo < total; lo = 2 * lo + 1, width *= 2)
    for (size_t i = lo; i < std::min(lo + width, total); ++i) fn(i);
}

template <int D>
void topSplits(const Builder<D>& b, Item<D>* items, size_t first, size_t n, size_t node, int depth,
               std::vector<Subtree>& out) {
  if (depth == 0 || n < 2) {
    out.push_back({node, first, n});
    return;
  }
  size_t m = b.split(items + first, n, node);
  topSplits(b, items, first, m, 2 * node + 1, depth - 1, out);
  topSplits(b, items, first + m + 1, n - m - 1, 2 * node + 2, depth - 1, out);
}

template <int D>
void buildDistributed(const Builder<D>& b, Item<D>* items, size_t n, dist::Comm& comm) {
  const int ranks = comm.size();
  // Two subtrees per rank or more, dealt largest first to the least loaded
  // rank: balanced within a few percent however lopsided the left-balanced
  // split (the root's left subtree may hold 2/3 of the photons).
  int depth = 1;
  while ((1 << depth) < 2 * ranks) ++depth;
  std::vector<Subtree> subtrees;
  topSplits(b, items, 0, n, 0, depth, subtrees);
  std::vector<size_t> byWork(subtrees.size());
  for (size_t i = 0; i < byWork.size(); ++i) byWork[i] = i;
  std::stable_sort(byWork.begin(), byWork.end(), [&](size_t a, size_t c) { return subtrees[a].n > subtrees[c].n; });
  std::vector<int> owner(subtrees.size());
  std::vector<uint64_t> load(static_cast<size_t>(ranks), 0);
  for (size_t i : byWork) {
    int r = int(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = r;
    load[size_t(r)] += subtrees[i].n;
  }
  // Build this rank's subtrees, pack their slots (index, then axis), in subtree order.
  std::vector<uint64_t> bytes(static_cast<size_t>(ranks));
  for (int r = 0; r < ranks; ++r) bytes[size_t(r)] = load[size_t(r)] * 5;
  std::vector<uint8_t> mine(static_cast<size_t>(bytes[static_cast<size_t>(comm.rank())]));
  size_t packed = 0;
  for (size_t i = 0; i < subtrees.size(); ++i) {
    if (owner[i] != comm.rank()) continue;
    const Subtree& t = subtrees[i];
    b.build(items + t.first, t.n, t.node);
    forEachSlot(t.node, n, [&](size_t slot) {
      TDPM_ASSERT(packed + 5 <= mine.size(), "distributed kd-tree: subtree slots miscounted");
      std::memcpy(&mine[packed], &b.order[slot], 4);
      mine[packed + 4] = b.axes[slot];
      packed += 5;
    });
  }
  TDPM_ASSERT(packed == mine.size(), "distributed kd-tree: subtree slots miscounted");
  uint64_t total = 0;
  for (uint64_t x : bytes) total += x;
  std::vector<uint8_t> all(static_cast<size_t>(total));
  comm.allgatherv(mine.data(), all.data(), bytes);
  // Unpack every other rank's subtrees: rank r's bytes hold its subtrees in subtree order.
  std::vector<size_t> offset(static_cast<size_t>(ranks), 0);
  for (int r = 1; r < ranks; ++r) offset[size_t(r)] = offset[size_t(r - 1)] + size_t(bytes[size_t(r - 1)]);
  for (size_t i = 0; i < subtrees.size(); ++i) {
    size_t& at = offset[size_t(owner[i])];
    if (owner[i] == comm.rank()) {
      at += subtrees[i].n * 5;
      continue;
    }
    forEachSlot(subtrees[i].node, n, [&](size_t slot) {
      std::memcpy(&b.order[slot], &all[at], 4);
      b.axes[slot] = all[at + 4];
      at += 5;
    });
  }
}

template <int D>
void buildTree(const PhotonStore& store, const float* timeKey, size_t cutoff, dist::Comm* comm,
               std::vector<uint32_t>& order, std::vector<uint8_t>& axes) {
  size_t n = store.size();
  std::vector<Item<D>> items(n);
  const float *X = store.xs(), *Y = store.ys(), *Z = store.zs();
  const uint16_t* F = store.flags();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      Item<D>& t = items[i];
      t.k[0] = X[i];
      t.k[1] = Y[i];
      t.k[2] = Z[i];
      if constexpr (D == 4) t.k[3] = timeKey[F[i] & kTimeMask];
      t.idx = uint32_t(i);
    }
  });
  order.resize(n);
  axes.resize(n);
  Builder<D> b{items.data(), order.data(), axes.data(), std::max<size_t>(cutoff, 2)};
  if (comm && comm->distributed() && n >= kDistributedBuildMin)
    buildDistributed(b, items.data(), n, *comm);
  else
    b.build(items.data(), n, 0);
}

}  // namespace

KdTree KdTree::build(PhotonStore& store, const KdBuildOptions& options) {
  TDPM_ASSERT(store.size() < (size_t(1) << 32), "kd-tree indices are 32-bit");
  TDPM_ASSERT(!options.spaceTime || options.kappa > 0.0f, "4D kd-tree needs kappa > 0");
  KdTree tree;
  tree.store_ = &store;
  tree.n_ = store.size();
  tree.spaceTime_ = options.spaceTime;
  tree.kappa_ = options.kappa;
  float sk = std::sqrt(options.kappa);
  tree.timeBase_ = sk * store.time().binCentre(0);
  tree.timeStep_ = sk * store.time().binWidth;
  float timeKey[kTimeBins];
  for (int q = 0; q < kTimeBins; ++q) timeKey[q] = tree.timeBase_ + float(q) * tree.timeStep_;

  std::vector<uint32_t> localOrder;
  std::vector<uint32_t>& order = options.order ? *options.order : localOrder;
  std::vector<uint8_t> axes;
  if (options.spaceTime)
    buildTree<4>(store, timeKey, options.parallelCutoff, options.comm, order, axes);
  else
    buildTree<3>(store, timeKey, options.parallelCutoff, options.comm, order, axes);
  store.permute(order.data());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tree.n_, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) store.setSplitAxis(i, axes[i]);
  });
  return tree;
}

double KdTree::bytesPerPhoton() const {
  if (n_ == 0) return 0.0;
  return store_->bytesPerPhoton();
}

// ---- k-nearest-neighbour search (heap: photon/knn_heap.h) ----

template <int D>
int KdTree::knnImpl(const float* key, int k, float maxRadius2, KnnQuery& q) const {
  q.count = 0;
  q.radius2 = maxRadius2;
  q.maxFound2 = 0.0f;
  if (n_ == 0 || k <= 0 || !(maxRadius2 > 0.0f)) return 0;
  q.reserve(k);
  const float *X = store_->xs(), *Y = store_->ys(), *Z = store_->zs();
  const uint16_t* F = store_->flags();
  uint32_t* idx = q.index_.data();
  float* d2 = q.dist2_.data();
  KnnQuery::StackEntry* stack = q.stack_.data();
  const uint32_t n = uint32_t(n_);
  const float kx = key[0], ky = key[1], kz = key[2];
  const float kt = D == 4 ? key[3] : 0.0f;

  float r2 = maxRadius2;
  int count = 0, sp = 0;
  // Offsets of the query from the current cell per axis (0 inside its slab);
  // cellDist2 = sum of their squares bounds every photon of the subtree.
  float off[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  float cellDist2 = 0.0f;

  auto test = [&](uint32_t p) {
    float dx = X[p] - kx, dy = Y[p] - ky, dz = Z[p] - kz;
    float dist = dx * dx + dy * dy + dz * dz;
    if constexpr (D == 4) {
      float dt = timeBase_ + float(F[p] & kTimeMask) * timeStep_ - kt;
      dist += dt * dt;
    }
    if (dist < r2) knnOffer(d2, idx, k, count, r2, p, dist);
  };

  uint32_t node = 0;
  for (;;) {
    // ---- descend to a leaf along the query's side, deferring each node
    //      (tested later, like Jensen's recursion) and its far side ----
    for (;;) {
      uint32_t left = 2 * node + 1;
      if (left >= n) {
        test(node);
        break;
      }
      // The subtree four levels down is 16 consecutive nodes: fetch them
      // early, the descent is otherwise a chain of dependent cache misses.
      uint32_t ahead = 16 * node + 15;
      if (ahead < n) {
        __builtin_prefetch(X + ahead);
        __builtin_prefetch(Y + ahead);
        __builtin_prefetch(Z + ahead);
        __builtin_prefetch(F + ahead);
      }
      int axis = (F[node] & kAxisMask) >> kAxisShift;
      float split;
      if constexpr (D == 4)
        split = axis == 0 ? X[node] : axis == 1 ? Y[node] : axis == 2 ? Z[node]
                                                          : timeBase_ + float(F[node] & kTimeMask) * timeStep_;
      else
        split = axis == 0 ? X[node] : axis == 1 ? Y[node] : Z[node];
      // delta > 0: the query is on the left (<= split) side.
      float delta = split - key[axis];
      uint32_t nearC = delta > 0.0f ? left : left + 1;
      uint32_t farC = delta > 0.0f ? left + 1 : left;
      // The far cell (and the node, on the plane) lie beyond the plane: the
      // offset on this axis becomes |delta|, never less than the current one.
      float farDist2 = cellDist2 - off[axis] * off[axis] + delta * delta;
      if (farDist2 < r2) {
        KnnQuery::StackEntry& e = stack[sp++];
        e.node = node;
        e.far = farC < n ? farC : 0;
        e.cellDist2 = farDist2;
        for (int a = 0; a < D; ++a) e.offset[a] = off[a];
        e.offset[axis] = delta;
      }
      if (nearC >= n) break;
      node = nearC;
    }
    // ---- pop the next deferred node still within the current radius ----
    bool found = false;
    while (sp > 0) {
      const KnnQuery::StackEntry& e = stack[--sp];
      if (e.cellDist2 < r2) {
        test(e.node);
        if (e.far == 0 || !(e.cellDist2 < r2)) continue;
        node = e.far;
        cellDist2 = e.cellDist2;
        for (int a = 0; a < D; ++a) off[a] = e.offset[a];
        found = true;
        break;
      }
    }
    if (!found) break;
  }

  q.count = count;
  float mx = 0.0f;
  for (int i = 0; i < count; ++i) mx = std::max(mx, d2[i]);
  q.maxFound2 = mx;
  q.radius2 = count == k ? r2 : maxRadius2;
  return count;
}

void RangeQuery::grow() {
  size_t n = std::max<size_t>(256, index_.size() * 2);
  index_.resize(n);
  dist2_.resize(n);
}

int KdTree::range(Vec3f p, float radius2, RangeQuery& q) const {
  TDPM_ASSERT(!spaceTime_, "range() needs the 3D tree");
  q.count = 0;
  if (n_ == 0 || !(radius2 > 0.0f)) return 0;
  if (q.index_.empty()) q.grow();
  const float *X = store_->xs(), *Y = store_->ys(), *Z = store_->zs();
  const uint16_t* F = store_->flags();
  const uint32_t n = uint32_t(n_);
  const float key[3] = {p.x, p.y, p.z};
  uint32_t stack[128];  // far children waiting: at most one per level
  int sp = 0, count = 0;
  uint32_t cap = uint32_t(q.index_.size());
  uint32_t* idx = q.index_.data();
  float* d2 = q.dist2_.data();
  uint32_t node = 0;
  for (;;) {
    for (;;) {
      float dx = X[node] - key[0], dy = Y[node] - key[1], dz = Z[node] - key[2];
      float dist = dx * dx + dy * dy + dz * dz;
      if (dist <= radius2) {
        if (uint32_t(count) == cap) {
          q.grow();
          cap = uint32_t(q.index_.size());
          idx = q.index_.data();
          d2 = q.dist2_.data();
        }
        idx[count] = node;
        d2[count] = dist;
        ++count;
      }
      uint32_t left = 2 * node + 1;
      if (left >= n) break;
      int axis = (F[node] & kAxisMask) >> kAxisShift;
      float delta = key[axis] - (axis == 0 ? X[node] : axis == 1 ? Y[node] : Z[node]);
      // Left holds keys <= split, right >= split: the far side is at least
      // |delta| away on this axis.
      uint32_t nearC = delta < 0.0f ? left : left + 1;
      uint32_t farC = delta < 0.0f ? left + 1 : left;
      if (delta * delta <= radius2 && farC < n) stack[sp++] = farC;
      if (nearC >= n) break;
      node = nearC;
    }
    if (sp == 0) break;
    node = stack[--sp];
  }
  q.count = count;
  return count;
}

int KdTree::knn(Vec3f p, int k, float maxRadius2, KnnQuery& q) const {
  TDPM_ASSERT(!spaceTime_, "knn() needs the 3D tree; this one is space-time (use knn4)");
  float key[3] = {p.x, p.y, p.z};
  return knnImpl<3>(key, k, maxRadius2, q);
}

int KdTree::knn4(Vec3f p, float t, int k, float maxDist2, KnnQuery& q) const {
  TDPM_ASSERT(spaceTime_, "knn4() needs the space-time tree (KdBuildOptions::spaceTime)");
  float key[4] = {p.x, p.y, p.z, std::sqrt(kappa_) * t};
  return knnImpl<4>(key, k, maxDist2, q);
}

}  // namespace tdpm::photon
