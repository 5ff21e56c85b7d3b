// scene/embree_scene.h — the only place that talks to Embree 3.
// Geometry goes in as per-time-step vertex arrays (Embree blends them
// linearly in ray time, the same blend motion/Motion::atNormalized defines),
// rays come back as raw hits. Device and scene handles are owned here.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "math/vec.h"

namespace tdpm {

struct RawHit {
  float t;
  uint32_t geometryId, primitiveId;
};

class EmbreeScene {
 public:
  EmbreeScene();
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // steps[s] holds the world-space vertices at time step s (one step: static).
  uint32_t addTriangles(const std::vector<std::vector<Vec3f>>& steps, const std::vector<uint32_t>& indices);
  // One sphere: centre and radius per time step.
  uint32_t addSphere(const std::vector<Vec3f>& centres, const std::vector<float>& radii);
  void commit();

  // time01: normalised shutter time in [0,1].
  bool intersect(Vec3f origin, Vec3f direction, float tFar, float time01, RawHit& hit) const;
  bool occluded(Vec3f origin, Vec3f direction, float tFar, float time01) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tdpm
