// tests/test_motion.cpp — motion/: keyframe resampling, and that Embree's
// hits at time t are exactly where Motion::atNormalized(t) puts the object.
#include <doctest/doctest.h>

#include <cmath>

#include "motion/motion.h"
#include "scene_fixtures.h"

using namespace tdpm;

TEST_CASE("motion: keyframes at aligned times are reproduced exactly") {
  std::vector<MotionKey> keys(3);
  keys[0] = {0.0f, {0, 0, 0}, {}, {1, 1, 1}};
  keys[1] = {0.25f, {1, 0, 0}, {}, {1, 1, 1}};
  keys[2] = {1.0f, {1, 2, 0}, {}, {2, 2, 2}};
  Shutter sh{0, 1};
  Motion m = Motion::keyframed(MotionKey{}, keys, sh);
  CHECK(m.stepCount() == 5);  // smallest grid with 0.25 on it
  for (float t : {0.0f, 0.1f, 0.25f, 0.6f, 1.0f}) {
    Affine3f a = m.atNormalized(t), b = Motion::poseAt(MotionKey{}, keys, t);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) CHECK(a.m[i][j] == doctest::Approx(b.m[i][j]).epsilon(1e-5));
  }
}

TEST_CASE("motion: rotation is subdivided so the blended chord stays on the arc") {
  std::vector<MotionKey> keys(2);
  keys[0] = {0.0f, {0, 0, 0}, Quaternion::fromAxisAngle({0, 0, 1}, 0), {1, 1, 1}};
  keys[1] = {1.0f, {0, 0, 0}, Quaternion::fromAxisAngle({0, 0, 1}, kPi / 2), {1, 1, 1}};
  Motion m = Motion::keyframed(MotionKey{}, keys, {0, 1});
  CHECK(m.stepCount() >= 46);  // 90 degrees / 2 degrees per step
  for (int i = 0; i <= 100; ++i) {
    float u = float(i) / 100.0f;
    Vec3f p = m.atNormalized(u).point({1, 0, 0});
    CHECK(std::fabs(length(p) - 1.0f) < 2e-4f);
    float angle = std::atan2(p.y, p.x);
    CHECK(std::fabs(angle - u * kPi / 2) < 2e-3f);
  }
}

TEST_CASE("motion: swept bounds contain the object at every time") {
  std::vector<MotionKey> keys(2);
  keys[0] = {0.0f, {-2, 0, 0}, {}, {1, 1, 1}};
  keys[1] = {1.0f, {3, 1, 0}, Quaternion::fromAxisAngle({1, 1, 0}, 2.0f), {1, 1, 1}};
  Motion m = Motion::keyframed(MotionKey{}, keys, {0, 1});
  Bounds3f local{{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}};
  Bounds3f swept = m.sweptBounds(local);
  for (int i = 0; i <= 50; ++i) {
    Bounds3f b = transformBounds(m.atNormalized(float(i) / 50.0f), local);
    CHECK(swept.contains(b.lo));
    CHECK(swept.contains(b.hi));
  }
}

namespace {

// Fires a ray straight down -z at (x, y) and returns the hit point.
bool hitAt(const Scene& s, float x, float y, float t01, Hit& h) {
  return s.intersect({x, y, 10.0f}, {0, 0, -1}, 100.0f, t01, h);
}

}  // namespace

TEST_CASE("motion: a translating sphere is hit where the interpolated transform puts it") {
  auto d = test::emptyScene(8, 8);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  auto o = test::sphere(0.5f, {0, 0, 0}, 0);
  o.motion = test::translation({-2, 0, 0}, {2, 1, 0});
  d.objects.push_back(o);
  auto s = Scene::build(d);
  REQUIRE(s->hasMotion);
  for (float t : {0.0f, 0.2f, 0.5f, 0.77f, 1.0f}) {
    Vec3f c = s->objects[0].motion.atNormalized(t).point({0, 0, 0});
    Hit h;
    REQUIRE(hitAt(*s, c.x, c.y, t, h));
    CHECK(h.p.z == doctest::Approx(0.5f).epsilon(1e-4));  // top of the sphere
    CHECK(h.n.z == doctest::Approx(1.0f).epsilon(1e-4));
    // Just outside the radius at this time: a miss.
    CHECK_FALSE(hitAt(*s, c.x + 0.51f, c.y, t, h));
    CHECK(hitAt(*s, c.x + 0.49f, c.y, t, h));
  }
}

TEST_CASE("motion: a rotating and translating box (mesh) is hit where the transform puts it") {
  auto d = test::emptyScene(8, 8);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  auto o = test::box({2, 1, 1}, {0, 0, 0}, 0);
  o.motion.times = {0.0f, 0.5f, 1.0f};
  o.motion.poses.resize(3);
  o.motion.poses[0].translate = {0, 0, 0};
  o.motion.poses[1].translate = {1, 0, 0};
  o.motion.poses[1].rotate = Quaternion::fromAxisAngle({0, 0, 1}, kPi / 4);
  o.motion.poses[2].translate = {1, 1, 0};
  o.motion.poses[2].rotate = Quaternion::fromAxisAngle({0, 0, 1}, kPi / 2);
  d.objects.push_back(o);
  auto s = Scene::build(d);
  for (float t : {0.0f, 0.3f, 0.5f, 0.8f, 1.0f}) {
    Affine3f m = s->objects[0].motion.atNormalized(t);
    // Points on the top face (local z = +0.5) in object space, mapped to world.
    for (Vec3f local : {Vec3f{0.9f, 0.4f, 0.5f}, Vec3f{-0.7f, -0.3f, 0.5f}, Vec3f{0, 0, 0.5f}}) {
      Vec3f w = m.point(local);
      Hit h;
      REQUIRE(hitAt(*s, w.x, w.y, t, h));
      CHECK(h.p.z == doctest::Approx(w.z).epsilon(1e-4));
      CHECK(h.localP.x == doctest::Approx(local.x).epsilon(1e-3));
      CHECK(h.localP.y == doctest::Approx(local.y).epsilon(1e-3));
      CHECK(h.n.z == doctest::Approx(1.0f).epsilon(1e-4));
    }
    // A point just beyond the long edge (local x = 1.05) misses.
    Vec3f outside = m.point({1.05f, 0, 0.5f});
    Hit h;
    CHECK_FALSE(hitAt(*s, outside.x, outside.y, t, h));
  }
}

TEST_CASE("motion: keyframe rotation spins an object about its own placed centre") {
  std::vector<MotionKey> keys(2);
  keys[0] = {0.0f, {0, 0, 0}, {}, {1, 1, 1}};
  keys[1] = {1.0f, {2, 0, 0}, Quaternion::fromAxisAngle({0, 0, 1}, kPi / 2), {2, 2, 2}};
  MotionKey placement{0.0f, {0, 1, 0}, Quaternion::fromAxisAngle({0, 1, 0}, kPi / 2), {1, 1, 1}};
  Motion m = Motion::keyframed(placement, keys, {0, 1});
  for (float u : {0.0f, 0.3f, 1.0f}) {
    // The centre only translates: from (0,1,0) along world x.
    Vec3f c = m.atNormalized(u).point({0, 0, 0});
    CHECK(c.x == doctest::Approx(2.0f * u).epsilon(1e-4));
    CHECK(c.y == doctest::Approx(1.0f).epsilon(1e-4));
    CHECK(std::fabs(c.z) < 1e-4f);
  }
  // At the end: local +z -> (placement: 90 deg about y) +x -> (key: 90 deg
  // about z) +y, scaled by 2, around the centre (2, 1, 0).
  Vec3f p = m.atNormalized(1.0f).point({0, 0, 1});
  CHECK(std::fabs(p.x - 2.0f) < 1e-4f);
  CHECK(p.y == doctest::Approx(3.0f).epsilon(1e-4));
  CHECK(std::fabs(p.z) < 1e-4f);
}
