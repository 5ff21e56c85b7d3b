// tests/scene_fixtures.h — small scenes built in code for the tests that
// should not depend on the scene-file parser.
#pragma once
#include <memory>

#include "scene/description.h"
#include "scene/scene.h"

namespace tdpm::test {

inline scene::MaterialDesc diffuse(Rgb c) {
  scene::MaterialDesc m;
  m.type = scene::MaterialDesc::Type::Diffuse;
  m.albedo.color = c;
  return m;
}

inline scene::ObjectDesc sphere(float radius, Vec3f centre, uint32_t material) {
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Sphere;
  o.shape.radius = radius;
  o.placement.translate = centre;
  o.material = material;
  return o;
}

inline scene::ObjectDesc quad(Vec2f size, Vec3f centre, uint32_t material) {
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Quad;
  o.shape.size = {size.x, 1, size.y};
  o.placement.translate = centre;
  o.material = material;
  return o;
}

inline scene::ObjectDesc box(Vec3f size, Vec3f centre, uint32_t material) {
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Box;
  o.shape.size = size;
  o.placement.translate = centre;
  o.material = material;
  return o;
}

// Two-key linear translation over the whole shutter [0, 1].
inline scene::MotionDesc translation(Vec3f from, Vec3f to) {
  scene::MotionDesc m;
  m.times = {0.0f, 1.0f};
  m.poses.resize(2);
  m.poses[0].translate = from;
  m.poses[1].translate = to;
  return m;
}

inline scene::SceneDescription emptyScene(int w, int h) {
  scene::SceneDescription d;
  d.sourcePath = "<test>";
  d.camera.width = w;
  d.camera.height = h;
  d.camera.shutterOpen = 0;
  d.camera.shutterClose = 1;
  return d;
}

}  // namespace tdpm::test
