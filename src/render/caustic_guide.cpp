// render/caustic_guide.cpp — building the guide from a caustic map with exit
// points, and the cones of one vertex.
#include "render/caustic_guide.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdlib>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/rng.h"
#include "photon/knn_heap.h"
#include "photon/tracer.h"

namespace tdpm {

namespace {

constexpr int kMinFound = 2;               // fewer photons near a vertex: no guide there
constexpr float kMinCosine = 0.05f;        // a cone's axis must be above the surface
// A photon counts for a vertex when the normal of the surface it was
// stored on is within 60 degrees of the vertex's: where two faces meet
// (the box's side and top, the floor and the box's side low in the
// shutter), a photon on the other face landed by another geometry. (Not
// measured alone: cube-caustic's points 1 cm below the box top's edge get
// no cones either way, their exit directions point into the box.)
constexpr float kMinNormalCosine = 0.5f;
constexpr float kMinHalfAngle = 0.0044f;   // 0.25 degrees
constexpr float kMaxHalfAngle = 0.14f;     // 8 degrees: wider is no longer a guide
// Search radius: 4x the median k-NN radius r0. Where the caustic is dim (the
// box's shadow on the floor, which the ball's halo reaches) photons are
// sparse, but those pixels are dark, so their rare caustic paths are what
// the relative error is made of; the exit points keep far photons' cones
// pointing right (measured on cube-caustic at 1024 spp, seed 1: 2x the
// radius gave relMSE 0.81 against refA, this 0.29: shadow pixels without
// cones then, docs/sampling.md).
constexpr float kRadiusScale = 4.0f;
// Trust: where the vertex's photons lie farther than r0 (median distance),
// their cones are less sure to hold the lamp's image, and a guide that
// misses makes the BSDF's own finds weigh 1/(1 - c): c falls as
// (r0 / distance)^2, to c/16 at the search radius.
constexpr float kTrustRadiusScale = 1.0f;

// Sub-cells per occupancy cell and axis of the neighbour cache (0: a k-NN
// per vertex).
constexpr int kCacheSubdivision = 2;

const float kMaxOneMinusCos = 2.0f * std::sin(0.5f * kMaxHalfAngle) * std::sin(0.5f * kMaxHalfAngle);

// The upper median of v[0..n) (1 <= n <= 8, v has room for 8): v padded
// with +inf and sorted by the 19-comparator network for 8 (min/max, no
// data-dependent branch: an insertion sort here mispredicted ~4 branches a
// call), so v[n/2] is the same value an insertion sort gives.
float median(float* v, int n) {
  static_assert(CausticGuide::kNeighbours == 8, "the network sorts 8");
  for (int i = n; i < 8; ++i) v[i] = std::numeric_limits<float>::infinity();
  auto cx = [v](int a, int b) {
    float lo = std::min(v[a], v[b]), hi = std::max(v[a], v[b]);
    v[a] = lo;
    v[b] = hi;
  };
  cx(0, 2), cx(1, 3), cx(4, 6), cx(5, 7);
  cx(0, 4), cx(1, 5), cx(2, 6), cx(3, 7);
  cx(0, 1), cx(2, 3), cx(4, 5), cx(6, 7);
  cx(2, 4), cx(3, 5);
  cx(1, 4), cx(3, 6);
  cx(1, 2), cx(3, 4), cx(5, 6);
  return v[n / 2];
}

int8_t quantizeUnit(float x) { return int8_t(std::lround(std::clamp(x, -1.0f, 1.0f) * 127.0f)); }

bool diffuseLike(const Material& m) {
  using T = Material::Type;
  return m.type == T::Diffuse || m.type == T::Plastic || m.type == T::Uber || m.type == T::Substrate ||
         m.type == T::CoatedDiffuse;
}

}  // namespace

CausticGuide CausticGuide::build(const Scene& scene, const CausticGuideSettings& s, const Progress& progress) {
  return build(scene, s, progress, kCacheSubdivision);
}

CausticGuide CausticGuide::build(const Scene& scene, const CausticGuideSettings& s, const Progress& progress,
                                 int cacheSubdivision) {
  CausticGuide g;
  if (!(s.fraction > 0.0f) || s.photons == 0 || !photon::sceneHasSpecular(scene, false)) return g;
  photon::TraceSettings t;
  t.kind = photon::MapKind::Caustic;
  t.storedWanted = s.photons;
  t.seed = hashCombine(s.seed, 0x6775696465ull);  // "guide": apart from the render's own streams
  t.sampler = s.sampler;
  t.glossyCaustics = false;  // cones aim at delta exit points only
  t.comm = &dist::local();  // every rank traces the same guide itself
  photon::TraceResult traced = photon::traceGuidePhotons(scene, t, progress);  // area lights, exit points kept
  if (traced.store.size() < size_t(kNeighbours) || traced.exitPoints.size() != traced.store.size()) return g;

  g.emitted_ = traced.emitted;
  g.store_ = std::make_unique<photon::PhotonStore>(std::move(traced.store));
  std::vector<uint32_t> order;
  photon::KdBuildOptions options;
  options.order = &order;
  g.tree_ = photon::KdTree::build(*g.store_, options);
  g.nodes_.resize(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    Vec3f x = g.store_->position(i);
    g.nodes_[i] = {x.x, x.y, x.z, uint32_t(g.store_->splitAxis(i))};
  }
  g.photons_.resize(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    g.photons_[i].position = g.store_->position(i);
    g.photons_[i].exit = traced.exitPoints[order[i]].point;
    Vec3f n = traced.exitPoints[order[i]].normal;
    g.photons_[i].normal[0] = quantizeUnit(n.x);
    g.photons_[i].normal[1] = quantizeUnit(n.y);
    g.photons_[i].normal[2] = quantizeUnit(n.z);
    g.photons_[i].unused = 0;
  }

  // Search radius: the k-NN radius at (up to) 256 photons spread through
  // the map, median, doubled: where the caustic is, a vertex finds its k.
  photon::KnnQuery q(kNeighbours);
  std::vector<float> r;
  size_t step = std::max<size_t>(1, g.store_->size() / 256);
  for (size_t i = 0; i < g.store_->size(); i += step)
    if (g.tree_.knn(g.store_->position(i), kNeighbours, std::numeric_limits<float>::infinity(), q) == kNeighbours)
      r.push_back(std::sqrt(q.maxFound2));
  if (r.empty()) return CausticGuide();
  std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
  float radius = kRadiusScale * r[r.size() / 2];
  g.trust2_ = kTrustRadiusScale * kTrustRadiusScale * r[r.size() / 2] * r[r.size() / 2];
  if (!(radius > 0.0f) || !std::isfinite(radius)) return CausticGuide();
  g.radius2_ = radius * radius;

  g.setConeAngles();
  std::vector<Vec3f> positions(g.store_->size());
  for (size_t i = 0; i < positions.size(); ++i) positions[i] = g.store_->position(i);
  g.occupancy_ = GuideOccupancy::build(positions, radius, kMinFound);
  g.orderRecords();
  g.fraction_ = s.fraction;
  g.allocateCache(cacheSubdivision);
  return g;
}

// Each photon's cone half-angle, once: 1.5x the median angle, seen from
// the photon, between its k nearest photons' exit directions and their
// own nearest other, so the cones join into one cover of the light's
// image. A vertex takes the median of its photons' half-angles (or the
// spread of its own photons' directions, if wider). Kept as 1 - cos.
// (The compact k-NN: the kd-tree's result, read from one record a node.)
void CausticGuide::setConeAngles() {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, photons_.size(), 1024),
                    [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Vec3f p = store_->position(i);
      uint32_t nearIndex[kNeighbours + 1];
      float nearDist2[kNeighbours + 1];
      int found = nearestWithin(p, radius2_, nearIndex, nearDist2);
      Vec3f axis[kNeighbours];
      int count = 0;
      const Vec3f facing = photons_[i].facing();
      for (int j = 0; j < found; ++j) {
        const GuidePhoton& o = photons_[nearIndex[j]];
        if (!(dot(o.facing(), facing) > kMinNormalCosine)) continue;
        Vec3f d = o.exit - p;
        float len = length(d);
        if (len > 0.0f) axis[count++] = d / len;
      }
      float half = kMaxHalfAngle;
      if (count >= 2) {
        float nearest[kNeighbours];
        for (int a = 0; a < count; ++a) {
          float best = 4.0f;
          for (int b = 0; b < count; ++b)
            if (a != b) best = std::min(best, lengthSquared(axis[a] - axis[b]));
          nearest[a] = best;  // squared chord to the nearest other axis
        }
        std::nth_element(nearest, nearest + count / 2, nearest + count);
        float angle = 2.0f * std::asin(std::min(1.0f, 0.5f * std::sqrt(nearest[count / 2])));
        half = std::clamp(1.5f * angle, kMinHalfAngle, kMaxHalfAngle);
      }
      float sh = std::sin(0.5f * half);
      photons_[i].oneMinusCos = 2.0f * sh * sh;
    }
  });
}

// Spreads the low 10 bits of v over every third bit.
static uint32_t spreadBits10(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

void CausticGuide::orderRecords() {
  // Morton order of the positions over their bounds (10 bits an axis),
  // ties by tree index: a sub-cell's photons are neighbours in space, so
  // mostly neighbours in memory too.
  const size_t n = photons_.size();
  Vec3f lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (const GuidePhoton& r : photons_) {
    lo = vmin(lo, r.position);
    hi = vmax(hi, r.position);
  }
  std::vector<uint64_t> key(n);
  for (size_t i = 0; i < n; ++i) {
    uint32_t q[3];
    for (int a = 0; a < 3; ++a) {
      float extent = hi[a] - lo[a];
      float t = extent > 0.0f ? (photons_[i].position[a] - lo[a]) / extent : 0.0f;
      q[a] = uint32_t(std::clamp(t, 0.0f, 1.0f) * 1023.0f);
    }
    uint64_t morton = spreadBits10(q[0]) | (spreadBits10(q[1]) << 1) | (spreadBits10(q[2]) << 2);
    key[i] = (morton << 32) | uint64_t(i);
  }
  std::sort(key.begin(), key.end());
  std::vector<GuidePhoton> records(n);
  treeOfRecord_.resize(n);
  recordOfTree_.resize(n);
  for (size_t r = 0; r < n; ++r) {
    uint32_t t = uint32_t(key[r] & 0xffffffffu);
    records[r] = photons_[t];
    treeOfRecord_[r] = t;
    recordOfTree_[t] = uint32_t(r);
  }
  photons_.clear();
  photons_.shrink_to_fit();
  photonCount_ = n;
  recordMemory_ = HugePageBuffer(n * sizeof(GuidePhoton));
  if (recordMemory_.data()) {
    GuidePhoton* out = static_cast<GuidePhoton*>(recordMemory_.data());
    std::copy(records.begin(), records.end(), out);
    records_ = out;
  } else {
    photons_ = std::move(records);  // no mapping: the vector's memory
    records_ = photons_.data();
  }
}

void CausticGuide::allocateCache(int sub) {
  cacheSub_ = 0;
  cacheEntries_ = 0;
  cache_ = nullptr;
  cacheMemory_ = HugePageBuffer();
  if (sub < 1 || !occupancy_.built()) return;
  const size_t entries = occupancy_.setCount() * size_t(sub) * size_t(sub) * size_t(sub);
  if (entries == 0) return;
  // Zeroed memory from the system (huge pages: core/huge_pages.h).
  cacheMemory_ = HugePageBuffer(entries * kNeighbours * sizeof(std::atomic<uint32_t>));
  if (!cacheMemory_.data()) return;  // no cache: a k-NN per vertex, same cones
  static_assert(sizeof(std::atomic<uint32_t>) == sizeof(uint32_t) && std::atomic<uint32_t>::is_always_lock_free,
                "slots are plain 32-bit words");
  cache_ = static_cast<std::atomic<uint32_t>*>(cacheMemory_.data());
  cacheEntries_ = entries;
  // A photon within the radius of any point of the sub-cell lies within
  // this of its centre (a little more for rounding).
  const float step = occupancy_.cellSize() / float(sub);
  const float reach = (std::sqrt(radius2_) + 0.5f * std::sqrt(3.0f) * step) * 1.0001f;
  cacheReach2_ = reach * reach;
  cacheSub_ = sub;
}

size_t CausticGuide::cacheFilled() const {
  size_t n = 0;
  for (size_t e = 0; e < cacheEntries_; ++e) n += cache_[e * kNeighbours].load(std::memory_order_relaxed) != 0;
  return n;
}

int CausticGuide::cachedList(size_t entry, Vec3f centre, uint32_t* list) const {
  std::atomic<uint32_t>* slot = &cache_[entry * kNeighbours];
  uint32_t first = slot[0].load(std::memory_order_acquire);
  if (first != 0) {
    if (first == kFilledEmpty) return 0;
    list[0] = first - 1;
    int n = 1;
    for (; n < kNeighbours; ++n) {
      uint32_t v = slot[n].load(std::memory_order_relaxed);
      if (v == 0) break;
      list[n] = v - 1;
    }
    return n;
  }
  // First visit: the kNeighbours photons nearest the sub-cell's centre
  // (a function of the sub-cell alone, whoever asks), then published.
  float d2[kNeighbours + 1];
  uint32_t found[kNeighbours + 1];
  int n = nearestWithin(centre, cacheReach2_, found, d2);
  for (int i = 0; i < n; ++i) found[i] = recordOfTree_[found[i]];
  for (int i = 1; i < kNeighbours; ++i) slot[i].store(i < n ? found[i] + 1 : 0, std::memory_order_relaxed);
  slot[0].store(n > 0 ? found[0] + 1 : kFilledEmpty, std::memory_order_release);
  for (int i = 0; i < n; ++i) list[i] = found[i];
  return n;
}

int CausticGuide::candidates(Vec3f p, uint32_t* index, float* dist2) const {
  if (cacheSub_ == 0) {
    if (!occupancy_.mayHaveNear(p)) return 0;  // the k-NN would find < kMinFound
    int n = nearest(p, index, dist2);
    for (int i = 0; i < n; ++i) index[i] = recordOfTree_[index[i]];
    return n;
  }
  size_t rank;
  Vec3f local, corner;
  if (!occupancy_.locate(p, rank, local, &corner)) return 0;
  const int sub = cacheSub_;
  int jx = std::min(sub - 1, int(local.x * float(sub)));
  int jy = std::min(sub - 1, int(local.y * float(sub)));
  int jz = std::min(sub - 1, int(local.z * float(sub)));
  size_t e = rank * size_t(sub) * size_t(sub) * size_t(sub) + size_t((jz * sub + jy) * sub + jx);
  const float step = occupancy_.cellSize() / float(sub);
  Vec3f centre(corner.x + (float(jx) + 0.5f) * step, corner.y + (float(jy) + 0.5f) * step,
               corner.z + (float(jz) + 0.5f) * step);
  uint32_t list[kNeighbours];
  int n = cachedList(e, centre, list);
  // Keep those within the radius of p itself: distances first (independent
  // loads), then a branch-free compaction (as one loop, each store's place
  // waited for the previous photon's load).
  float d[kNeighbours];
  for (int i = 0; i < n; ++i) {
    const Vec3f q = records_[list[i]].position;
    float dx = q.x - p.x, dy = q.y - p.y, dz = q.z - p.z;
    d[i] = dx * dx + dy * dy + dz * dz;
  }
  int found = 0;
  for (int i = 0; i < n; ++i) {
    index[found] = list[i];
    dist2[found] = d[i];
    found += d[i] < radius2_;
  }
  return found;
}

// photon::KdTree::knnImpl<3> for k = kNeighbours over nodes_: the same
// descent, deferral, heap and tests in the same order (kept in step with
// it; tests/test_caustic_guide.cpp compares the two on random queries).
int CausticGuide::nearestWithin(Vec3f p, float radius2, uint32_t* idx, float* d2) const {
  constexpr int k = kNeighbours;
  const uint32_t n = uint32_t(nodes_.size());
  if (n == 0 || !(radius2 > 0.0f)) return 0;
  const Node* N = nodes_.data();
  const float key[3] = {p.x, p.y, p.z};
  struct Deferred {
    uint32_t node, far;
    float cellDist2;
    float offset[3];
  };
  Deferred stack[64];  // one per level at most; the tree is < 32 levels deep
  float r2 = radius2;
  int count = 0, sp = 0;
  float off[3] = {0.0f, 0.0f, 0.0f};
  float cellDist2 = 0.0f;
  auto test = [&](uint32_t q) {
    float dx = N[q].x - key[0], dy = N[q].y - key[1], dz = N[q].z - key[2];
    float dist = dx * dx + dy * dy + dz * dz;
    if (dist < r2) photon::knnOffer(d2, idx, k, count, r2, q, dist);
  };
  uint32_t node = 0;
  for (;;) {
    for (;;) {
      uint32_t left = 2 * node + 1;
      if (left >= n) {
        test(node);
        break;
      }
      uint32_t ahead = 16 * node + 15;
      if (ahead < n) __builtin_prefetch(N + ahead);
      int axis = int(N[node].axis);
      float split = axis == 0 ? N[node].x : axis == 1 ? N[node].y : N[node].z;
      float delta = split - key[axis];
      uint32_t nearC = delta > 0.0f ? left : left + 1;
      uint32_t farC = delta > 0.0f ? left + 1 : left;
      float farDist2 = cellDist2 - off[axis] * off[axis] + delta * delta;
      if (farDist2 < r2) {
        Deferred& e = stack[sp++];
        e.node = node;
        e.far = farC < n ? farC : 0;
        e.cellDist2 = farDist2;
        for (int a = 0; a < 3; ++a) e.offset[a] = off[a];
        e.offset[axis] = delta;
      }
      if (nearC >= n) break;
      node = nearC;
    }
    bool found = false;
    while (sp > 0) {
      const Deferred& e = stack[--sp];
      if (e.cellDist2 < r2) {
        test(e.node);
        if (e.far == 0 || !(e.cellDist2 < r2)) continue;
        node = e.far;
        cellDist2 = e.cellDist2;
        for (int a = 0; a < 3; ++a) off[a] = e.offset[a];
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return count;
}

void CausticGuide::conesAt(const Material& m, Vec3f p, Vec3f n, GuideCones& out) const {
  out.count = 0;
  out.totalSolidAngle = 0.0f;
  out.fraction = 0.0f;
  if (!enabled() || !diffuseLike(m)) return;
  uint32_t index[kNeighbours + 1];
  float d2[kNeighbours + 1];
  int found = candidates(p, index, d2);
  if (found < kMinFound) return;
  // Every photon's direction and tests first: no dependence between
  // photons, so their square roots and divisions overlap. Then the kept
  // ones are packed without a branch (the outcomes vary vertex to vertex;
  // as branches they mispredicted, and packing inside the first loop made
  // each photon wait for the previous one's tests). A zero length gives
  // NaN, kept by no test.
  Vec3f dir[kNeighbours];
  bool keep[kNeighbours];
  for (int i = 0; i < found; ++i) {
    const GuidePhoton& o = records_[index[i]];
    Vec3f d = o.exit - p;
    d = d * (1.0f / length(d));
    dir[i] = d;
    keep[i] = (dot(o.facing(), n) > kMinNormalCosine) & (dot(d, n) > kMinCosine);
  }
  Vec3f axis[kNeighbours];
  float omc[kNeighbours], dist2[kNeighbours];
  int count = 0;
  for (int i = 0; i < found; ++i) {
    omc[count] = records_[index[i]].oneMinusCos;
    dist2[count] = d2[i];
    axis[count] = dir[i];
    count += keep[i];
  }
  if (count < kMinFound) return;
  float fraction = fraction_;
  float medianDist2 = median(dist2, count);
  if (medianDist2 > trust2_) fraction *= trust2_ / medianDist2;
  // Cones as wide as the farthest of the vertex's own directions from
  // their mean, when that is wider than the photons' spacing: the
  // neighbours' exit directions spread over the lamp's whole image (~1
  // degree from the floor), and cones only as wide as their spacing left
  // gaps in it (docs/sampling.md). 1 - cos(angle) = chord^2 / 2.
  Vec3f mean(0.0f);
  for (int i = 0; i < count; ++i) mean += axis[i];
  mean = normalize(mean);
  float chord2 = 0.0f;
  for (int i = 0; i < count; ++i) chord2 = std::max(chord2, lengthSquared(axis[i] - mean));
  float oneMinusCos = std::min(kMaxOneMinusCos, std::max(median(omc, count), 0.5f * chord2));
  float omega = 2.0f * kPi * oneMinusCos;
  for (int i = 0; i < count; ++i) out.cone[size_t(i)] = {axis[i], oneMinusCos, omega};
  out.count = count;
  out.totalSolidAngle = omega * float(count);
  out.fraction = fraction;
}

}  // namespace tdpm
