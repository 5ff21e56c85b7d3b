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

// A black sphere of `radius` crossing a white sky along x, from -travel to
// +travel over the shutter, seen head-on from z = 10: every pixel's value is
// 1 - the fraction of its area and time the sphere covers.
inline scene::SceneDescription blackSphereAcrossSky(int w, int h, float fovDegrees, float radius, float travel) {
  auto d = emptyScene(w, h);
  d.background = Rgb(1.0f);
  d.camera.position = {0, 0, 10};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = fovDegrees;
  d.materials.push_back(diffuse(Rgb(0.0f)));
  auto ball = sphere(radius, {0, 0, 0}, 0);
  ball.motion = translation({-travel, 0, 0}, {travel, 0, 0});
  d.objects.push_back(ball);
  return d;
}

}  // namespace tdpm::test
