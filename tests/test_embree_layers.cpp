// tests/test_embree_layers.cpp — scene/embree_scene's layers (still meshes,
// spheres, moving meshes, the bounds gates in front of the
// last two) give the closest hit a brute-force search over every primitive
// gives, with the id the add* call returned, at any ray time; and occlusion
// agrees with it.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.h"
#include "math/transform.h"
#include "scene/embree_scene.h"

using namespace tdpm;

namespace {

struct Mesh {
  std::vector<Vec3f> vertices;  // object space (world space when still)
  std::vector<uint32_t> indices;
  std::vector<Affine3f> steps;  // empty: still
  uint32_t id = 0;
};
struct Sphere {
  std::vector<Vec3f> centres;
  std::vector<float> radii;
  uint32_t id = 0;
};

Mesh box(Vec3f half) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({i & 1 ? half.x : -half.x, i & 2 ? half.y : -half.y, i & 4 ? half.z : -half.z});
  const uint32_t faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

// The blend Embree applies between time steps: a time u in [0, 1] falls
// between steps i and i + 1 of n equally spaced ones.
template <class T, class Blend>
T atTime(const std::vector<T>& steps, float u, Blend blend) {
  if (steps.size() == 1) return steps[0];
  float x = u * float(steps.size() - 1);
  size_t i = std::min(size_t(x), steps.size() - 2);
  return blend(steps[i], steps[i + 1], x - float(i));
}

// Double-precision ray-triangle distance (Moller-Trumbore), inf on a miss.
double triangleT(Vec3f o, Vec3f d, Vec3f a, Vec3f b, Vec3f c) {
  double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
  double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
  double D[3] = {d.x, d.y, d.z};
  double p[3] = {D[1] * e2[2] - D[2] * e2[1], D[2] * e2[0] - D[0] * e2[2], D[0] * e2[1] - D[1] * e2[0]};
  double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
  if (std::fabs(det) < 1e-15) return INFINITY;
  double s[3] = {double(o.x) - a.x, double(o.y) - a.y, double(o.z) - a.z};
  double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
  double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  double v = (D[0] * q[0] + D[1] * q[1] + D[2] * q[2]) / det;
  double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return INFINITY;
  return t;
}

double sphereT(Vec3f o, Vec3f d, Vec3f c, float r) {
  double oc[3] = {double(o.x) - c.x, double(o.y) - c.y, double(o.z) - c.z};
  double A = double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z;
  double B = oc[0] * d.x + oc[1] * d.y + oc[2] * d.z;
  double C = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - double(r) * r;
  double disc = B * B - A * C;
  if (disc < 0) return INFINITY;
  double sq = std::sqrt(disc);
  double t0 = (-B - sq) / A, t1 = (-B + sq) / A;
  if (t0 > 0) return t0;
  return t1 > 0 ? t1 : INFINITY;
}

struct Nearest {
  double t = INFINITY, second = INFINITY;  // closest and next-closest distance
  uint32_t id = ~0u;
  void offer(double t2, uint32_t id2) {
    if (t2 < t) {
      second = t;
      t = t2;
      id = id2;
    } else if (t2 < second) {
      second = t2;
    }
  }
};

struct World {
  EmbreeScene embree;
  std::vector<Mesh> meshes;
  std::vector<Sphere> spheres;

  Nearest bruteForce(Vec3f o, Vec3f d, float u) const {
    Nearest n;
    for (const Mesh& m : meshes) {
      auto blendPoint = [&](size_t v) {
        if (m.steps.empty()) return m.vertices[v];
        Affine3f x = atTime(m.steps, u, [](const Affine3f& a, const Affine3f& b, float f) { return lerp(a, b, f); });
        return x.point(m.vertices[v]);
      };
      for (size_t i = 0; i < m.indices.size(); i += 3)
        n.offer(triangleT(o, d, blendPoint(m.indices[i]), blendPoint(m.indices[i + 1]), blendPoint(m.indices[i + 2])),
                m.id);
    }
    for (const Sphere& s : spheres) {
      Vec3f c = atTime(s.centres, u, [](Vec3f a, Vec3f b, float f) { return a + (b - a) * f; });
      float r = atTime(s.radii, u, [](float a, float b, float f) { return a + (b - a) * f; });
      n.offer(sphereT(o, d, c, r), s.id);
    }
    return n;
  }
};

// Still floor and wall, a still sphere, a sphere moving across, a box
// translating and turning, a still box; `extraSpheres` small still spheres
// (more than the listed-bounds limit puts the sphere layer behind one union
// box).
void build(World& w, int extraSpheres) {
  Mesh floor;
  floor.vertices = {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  w.meshes.push_back(floor);
  Mesh still = box({0.4f, 0.3f, 0.5f});
  for (Vec3f& v : still.vertices) v = v + Vec3f(-2.0f, 0.3f, 1.0f);
  w.meshes.push_back(still);
  Mesh moving = box({0.5f, 0.5f, 0.5f});
  for (int s = 0; s < 5; ++s) {
    float u = float(s) / 4.0f;
    moving.steps.push_back(Affine3f::fromTRS({1.0f - 2.0f * u, 1.0f + u, 0.0f},
                                             Quaternion::fromAxisAngle(normalize(Vec3f(1, 1, 0)), 1.2f * u), {1, 1, 1}));
  }
  w.meshes.push_back(moving);
  w.spheres.push_back({{{0.5f, 2.5f, -1.0f}}, {0.6f}, 0});
  w.spheres.push_back({{{-1.5f, 1.0f, -0.5f}, {1.5f, 1.5f, -0.5f}}, {0.4f, 0.5f}, 0});
  for (int i = 0; i < extraSpheres; ++i)
    w.spheres.push_back({{{-3.0f + 0.6f * float(i), 0.2f, 2.5f}}, {0.2f}, 0});
  for (Mesh& m : w.meshes)
    m.id = m.steps.empty() ? w.embree.addTriangles(m.vertices, m.indices)
                           : w.embree.addMovingTriangles(m.vertices, m.indices, m.steps);
  for (Sphere& s : w.spheres) s.id = w.embree.addSphere(s.centres, s.radii);
  w.embree.commit();
}

void checkAgainstBruteForce(int extraSpheres) {
  World w;
  build(w, extraSpheres);
  // Ids are handed out in call order, whatever layer holds the geometry.
  for (size_t i = 0; i < w.meshes.size(); ++i) CHECK(w.meshes[i].id == i);
  for (size_t i = 0; i < w.spheres.size(); ++i) CHECK(w.spheres[i].id == w.meshes.size() + i);
  Rng rng(20261129, uint64_t(extraSpheres));
  int compared = 0, hits = 0, movingHits = 0, sphereHits = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3f o{6 * rng.uniform() - 3, 4 * rng.uniform() - 0.5f, 6 * rng.uniform() - 3};
    float z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
    float sr = std::sqrt(std::max(0.0f, 1 - z * z));
    Vec3f d{sr * std::cos(phi), z, sr * std::sin(phi)};
    float u = rng.uniform();
    float tFar = 8 * rng.uniform();
    Nearest n = w.bruteForce(o, d, u);
    // Skip near-ties and grazing cases, where float rounding may pick either.
    if (n.second - n.t < 1e-3 || std::fabs(n.t - tFar) < 1e-3) continue;
    ++compared;
    RawHit hit;
    bool got = w.embree.intersect(o, d, INFINITY, u, hit);
    REQUIRE(got == std::isfinite(n.t));
    if (got) {
      ++hits;
      CHECK(hit.geometryId == n.id);
      CHECK(std::fabs(double(hit.t) - n.t) < 1e-4 * (1 + n.t));
      movingHits += n.id == 2 || n.id == 4;
      sphereHits += n.id >= w.meshes.size();
    }
    CHECK(w.embree.occluded(o, d, tFar, u) == (n.t < tFar));
  }
  // The rays reach every layer, the moving ones included.
  CHECK(compared > 19000);
  CHECK(hits > 5000);
  CHECK(movingHits > 500);
  CHECK(sphereHits > 400);
}

}  // namespace

TEST_CASE("embree layers: closest hits and occlusion match a brute-force search (gates per geometry)") {
  checkAgainstBruteForce(0);
}

TEST_CASE("embree layers: the same with more spheres than listed bounds (one union gate)") {
  checkAgainstBruteForce(10);
}
