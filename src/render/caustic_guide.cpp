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

// The upper median of v[0..n) (n <= kNeighbours), by insertion sort.
float median(float* v, int n) {
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && v[j] < v[j - 1]; --j) std::swap(v[j], v[j - 1]);
  return v[n / 2];
}

bool diffuseLike(const Material& m) {
  return m.type == Material::Type::Diffuse || m.type == Material::Type::Plastic;
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
  t.areaLightsOnly = true;
  t.keepExitPoints = true;
  t.glossyCaustics = false;  // cones aim at delta exit points only
  t.comm = &dist::local();  // every rank traces the same guide itself
  photon::TraceResult traced = photon::tracePhotons(scene, t, progress);
  if (traced.store.size() < size_t(kNeighbours) || traced.exitPoints.size() != traced.store.size()) return g;

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
    g.photons_[i].normal = traced.exitPoints[order[i]].normal;
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

  // Each photon's cone half-angle, once: 1.5x the median angle, seen from
  // the photon, between its k nearest photons' exit directions and their
  // own nearest other, so the cones join into one cover of the light's
  // image. A vertex takes the median of its photons' half-angles (or the
  // spread of its own photons' directions, if wider). Kept as 1 - cos.
  photon::KnnQuery nq(kNeighbours);
  for (size_t i = 0; i < g.photons_.size(); ++i) {
    Vec3f p = g.store_->position(i);
    int found = g.tree_.knn(p, kNeighbours, g.radius2_, nq);
    Vec3f axis[kNeighbours];
    int count = 0;
    for (int j = 0; j < found; ++j) {
      const GuidePhoton& o = g.photons_[nq.index()[j]];
      if (!(dot(o.normal, g.photons_[i].normal) > kMinNormalCosine)) continue;
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
    g.photons_[i].oneMinusCos = 2.0f * sh * sh;
  }
  std::vector<Vec3f> positions(g.store_->size());
  for (size_t i = 0; i < positions.size(); ++i) positions[i] = g.store_->position(i);
  g.occupancy_ = GuideOccupancy::build(positions, radius, kMinFound);
  g.fraction_ = s.fraction;
  g.buildCache(cacheSubdivision);
  return g;
}

void CausticGuide::buildCache(int sub) {
  cacheSub_ = 0;
  cacheIndex_.clear();
  if (sub < 1 || !occupancy_.built()) return;
  const std::vector<Vec3f> corners = occupancy_.setCellCorners();
  const size_t per = size_t(sub) * size_t(sub) * size_t(sub);
  const size_t entries = corners.size() * per;
  cacheIndex_.assign(entries * kNeighbours, kNoPhoton);
  const float step = occupancy_.cellSize() / float(sub);
  // A photon within the radius of any point of the sub-cell lies within
  // this of its centre (a little more for rounding).
  const float reach = (std::sqrt(radius2_) + 0.5f * std::sqrt(3.0f) * step) * 1.0001f;
  const float reach2 = reach * reach;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, entries, 256), [&](const tbb::blocked_range<size_t>& range) {
    uint32_t index[kNeighbours + 1];
    float d2[kNeighbours + 1];
    for (size_t e = range.begin(); e != range.end(); ++e) {
      size_t j = e % per;
      Vec3f c = corners[e / per];
      Vec3f centre(c.x + (float(j % size_t(sub)) + 0.5f) * step, c.y + (float((j / size_t(sub)) % size_t(sub)) + 0.5f) * step,
                   c.z + (float(j / (size_t(sub) * size_t(sub))) + 0.5f) * step);
      int found = nearestWithin(centre, reach2, index, d2);
      for (int i = 0; i < found; ++i) cacheIndex_[e * kNeighbours + size_t(i)] = index[i];
    }
  });
  cacheSub_ = sub;
}

int CausticGuide::candidates(Vec3f p, uint32_t* index, float* dist2) const {
  if (cacheSub_ == 0) {
    if (!occupancy_.mayHaveNear(p)) return 0;  // the k-NN would find < kMinFound
    return nearest(p, index, dist2);
  }
  size_t rank;
  Vec3f local;
  if (!occupancy_.locate(p, rank, local)) return 0;
  const int sub = cacheSub_;
  int jx = std::min(sub - 1, int(local.x * float(sub)));
  int jy = std::min(sub - 1, int(local.y * float(sub)));
  int jz = std::min(sub - 1, int(local.z * float(sub)));
  size_t e = rank * size_t(sub) * size_t(sub) * size_t(sub) + size_t((jz * sub + jy) * sub + jx);
  const uint32_t* cached = &cacheIndex_[e * kNeighbours];
  int found = 0;
  for (int i = 0; i < kNeighbours && cached[i] != kNoPhoton; ++i) {
    const Vec3f q = photons_[cached[i]].position;
    float dx = q.x - p.x, dy = q.y - p.y, dz = q.z - p.z;
    float d = dx * dx + dy * dy + dz * dz;
    if (d < radius2_) {
      index[found] = cached[i];
      dist2[found++] = d;
    }
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
  Vec3f axis[kNeighbours];
  float omc[kNeighbours], dist2[kNeighbours];
  int count = 0;
  for (int i = 0; i < found; ++i) {
    const GuidePhoton& o = photons_[index[i]];
    if (!(dot(o.normal, n) > kMinNormalCosine)) continue;
    Vec3f d = o.exit - p;
    float len = length(d);
    if (!(len > 0.0f)) continue;
    d = d / len;
    if (dot(d, n) > kMinCosine) {
      omc[count] = o.oneMinusCos;
      dist2[count] = d2[i];
      axis[count++] = d;
    }
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
