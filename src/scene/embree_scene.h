// scene/embree_scene.h — the only place that talks to Embree 3.
// Still geometry goes in as world-space vertices; a rigidly moving mesh as
// its object-space vertices and its object-to-world transform at each of N
// equally spaced time steps, from which the vertices of every step are
// made (Embree blends them linearly in ray time, the blend
// motion/Motion::atNormalized defines). Geometry is kept in layers, each
// its own Embree scene, and a ray visits the sphere, quadric and moving layers only
// where their bounds are (embree_scene.cpp says why). Rays come back as
// raw hits. Device and scene handles are owned here.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "math/transform.h"
#include "math/vec.h"
#include "motion/motion.h"
#include "scene/quadric.h"

namespace tdpm {

struct RawHit {
  float t;
  uint32_t geometryId, primitiveId;
  float u, v;  // triangles: barycentrics of vertices 1 and 2 (textures' uv)
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
  // One disk or cylinder (scene/quadric.h) under `motion` (still or moving):
  // Embree user geometry whose callbacks take each ray into object space.
  uint32_t addQuadric(const Quadric& shape, const Motion& motion);

  // One disc (a disk area light): centre, unit normal and radius per time
  // step, in the sphere layer (Embree's oriented disc points).
  uint32_t addOrientedDisc(const std::vector<Vec3f>& centres, const std::vector<Vec3f>& normals,
                           const std::vector<float>& radii);
  void commit();

  // time01: normalised shutter time in [0,1].
  // hit.geometryId is the id the add* call returned (0, 1, 2, ... in call
  // order, whatever the layer), hit.primitiveId the triangle's index in its mesh.
  bool intersect(Vec3f origin, Vec3f direction, float tFar, float time01, RawHit& hit) const;
  bool occluded(Vec3f origin, Vec3f direction, float tFar, float time01) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tdpm
