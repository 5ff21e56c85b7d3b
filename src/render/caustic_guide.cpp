// render/caustic_guide.cpp — building the guide from a caustic map with exit
// points, and the cones of one vertex.
#include "render/caustic_guide.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdlib>

#include "core/rng.h"
#include "photon/tracer.h"

namespace tdpm {

namespace {

constexpr int kMinFound = 2;               // fewer photons near a vertex: no guide there
constexpr float kMinCosine = 0.05f;        // a cone's axis must be above the surface
constexpr float kMinHalfAngle = 0.0044f;   // 0.25 degrees
constexpr float kMaxHalfAngle = 0.14f;     // 8 degrees: wider is no longer a guide
// Search radius: 4x the median k-NN radius. Where the caustic is dim (the
// box's shadow on the floor, which the ball's halo reaches) photons are
// sparse, but those pixels are dark, so their rare caustic paths are what
// the relative error is made of; the exit points keep far photons' cones
// pointing right (measured on cube-caustic, 8 seeds x 64 spp: 2x the
// radius and at least 4 photons gave relMSE mean 31 / MSE 0.85, this
// 2.2 / 0.74; unguided 31.6 / 1.46).
constexpr float kRadiusScale = 4.0f;

bool diffuseLike(const Material& m) {
  return m.type == Material::Type::Diffuse || m.type == Material::Type::Plastic;
}

}  // namespace

CausticGuide CausticGuide::build(const Scene& scene, const CausticGuideSettings& s, const Progress& progress) {
  CausticGuide g;
  if (!(s.fraction > 0.0f) || s.photons == 0 || !photon::sceneHasSpecular(scene)) return g;
  photon::TraceSettings t;
  t.kind = photon::MapKind::Caustic;
  t.storedWanted = s.photons;
  t.seed = hashCombine(s.seed, 0x6775696465ull);  // "guide": apart from the render's own streams
  t.sampler = s.sampler;
  t.areaLightsOnly = true;
  t.keepExitPoints = true;
  t.comm = &dist::local();  // every rank traces the same guide itself
  photon::TraceResult traced = photon::tracePhotons(scene, t, progress);
  if (traced.store.size() < size_t(kNeighbours) || traced.exitPoints.size() != traced.store.size()) return g;

  g.store_ = std::make_unique<photon::PhotonStore>(std::move(traced.store));
  std::vector<uint32_t> order;
  photon::KdBuildOptions options;
  options.order = &order;
  g.tree_ = photon::KdTree::build(*g.store_, options);
  g.exits_.resize(order.size());
  for (size_t i = 0; i < order.size(); ++i) g.exits_[i] = traced.exitPoints[order[i]];

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
  if (!(radius > 0.0f) || !std::isfinite(radius)) return CausticGuide();
  g.radius2_ = radius * radius;

  // Each photon's cone half-angle, once: 1.5x the median angle, seen from
  // the photon, between its k nearest photons' exit directions and their
  // own nearest other, so the cones join into one cover of the light's
  // image. A vertex takes the median of its photons' half-angles.
  g.halfAngle_.resize(g.exits_.size());
  photon::KnnQuery nq(kNeighbours);
  for (size_t i = 0; i < g.exits_.size(); ++i) {
    Vec3f p = g.store_->position(i);
    int found = g.tree_.knn(p, kNeighbours, g.radius2_, nq);
    Vec3f axis[kNeighbours];
    int count = 0;
    for (int j = 0; j < found; ++j) {
      Vec3f d = g.exits_[nq.index()[j]] - p;
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
    g.halfAngle_[i] = half;
  }
  std::vector<Vec3f> positions(g.store_->size());
  for (size_t i = 0; i < positions.size(); ++i) positions[i] = g.store_->position(i);
  g.occupancy_ = GuideOccupancy::build(positions, radius, kMinFound);
  g.fraction_ = s.fraction;
  return g;
}

void CausticGuide::conesAt(const Material& m, Vec3f p, Vec3f n, photon::KnnQuery& q, GuideCones& out) const {
  out.count = 0;
  out.totalSolidAngle = 0.0f;
  out.fraction = 0.0f;
  if (!enabled() || !diffuseLike(m)) return;
  if (!occupancy_.mayHaveNear(p)) return;  // the k-NN would find < kMinFound
  int found = tree_.knn(p, kNeighbours, radius2_, q);
  if (found < kMinFound) return;
  Vec3f axis[kNeighbours];
  int count = 0;
  for (int i = 0; i < found; ++i) {
    Vec3f d = exits_[q.index()[i]] - p;
    float len = length(d);
    if (!(len > 0.0f)) continue;
    d = d / len;
    if (dot(d, n) > kMinCosine) axis[count++] = d;
  }
  if (count < kMinFound) return;
  float halves[kNeighbours];
  for (int i = 0; i < found; ++i) halves[i] = halfAngle_[q.index()[i]];
  std::nth_element(halves, halves + found / 2, halves + found);
  float half = halves[found / 2];
  float s = std::sin(0.5f * half);
  float oneMinusCos = 2.0f * s * s;
  float omega = 2.0f * kPi * oneMinusCos;
  for (int i = 0; i < count; ++i) out.cone[size_t(i)] = {axis[i], oneMinusCos, omega};
  out.count = count;
  out.totalSolidAngle = omega * float(count);
  out.fraction = fraction_;
}

}  // namespace tdpm
