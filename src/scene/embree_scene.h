// scene/embree_scene.h — the only place that talks to Embree 3.
// Still geometry goes in as world-space vertices; a rigidly moving mesh as
// its object-space vertices and one 3x4 transform per time step, which
// Embree instances and blends linearly in ray time (the blend
// motion/Motion::atNormalized defines; the same points as blending the
// transformed vertices). Why instances: Embree's motion-blur triangle BVH
// cost ~1,030 instructions a ray on scenes/cube-caustic.json for a 12-
// triangle moving box, more than the rest of the scene together, and the
// render 1.75x the time of the same scene with the box still; an instance
// transforms the ray once and intersects a still BVH. Rays come back as
// raw hits. Device and scene handles are owned here.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "math/transform.h"
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

  // A still mesh, world-space vertices.
  uint32_t addTriangles(const std::vector<Vec3f>& vertices, const std::vector<uint32_t>& indices);
  // A rigidly moving mesh: object-space vertices and the object-to-world
  // transform at each of steps.size() >= 2 equally spaced time steps.
  uint32_t addMovingTriangles(const std::vector<Vec3f>& objectVertices, const std::vector<uint32_t>& indices,
                              const std::vector<Affine3f>& steps);
  // One sphere: centre and radius per time step.
  uint32_t addSphere(const std::vector<Vec3f>& centres, const std::vector<float>& radii);
  void commit();

  // time01: normalised shutter time in [0,1].
  // hit.geometryId is the id the add* call returned (for a moving mesh,
  // its instance's), hit.primitiveId the triangle's index in its mesh.
  bool intersect(Vec3f origin, Vec3f direction, float tFar, float time01, RawHit& hit) const;
  bool occluded(Vec3f origin, Vec3f direction, float tFar, float time01) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tdpm
