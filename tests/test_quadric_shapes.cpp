// tests/test_quadric_shapes.cpp — the analytic disk and cylinder
// (scene/quadric.h): ray hits against the surface's equation, normals and
// reverse_orientation, motion, a diffuse render against a finely
// tessellated mesh of the same shapes, the JSON keys and their errors, and
// the pbrt import of disk, cylinder, ReverseOrientation and curved
// bilinear patches.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "error_capture.h"
#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/bsdf.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/quadric.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

constexpr float kTwoPi = 6.2831853f;

scene::ObjectDesc diskObject(float radius, float inner, float height, float phiMaxDeg, uint32_t material) {
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Disk;
  o.shape.radius = radius;
  o.shape.innerRadius = inner;
  o.shape.height = height;
  o.shape.phiMax = phiMaxDeg;
  o.material = material;
  return o;
}

scene::ObjectDesc cylinderObject(float radius, float zMin, float zMax, float phiMaxDeg, uint32_t material) {
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Cylinder;
  o.shape.radius = radius;
  o.shape.zMin = zMin;
  o.shape.zMax = zMax;
  o.shape.phiMax = phiMaxDeg;
  o.material = material;
  return o;
}

// A cheap deterministic sequence in [0, 1).
struct Lcg {
  uint64_t s = 12345;
  float next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return float((s >> 40) & 0xffffff) / float(1 << 24);
  }
};

std::string errorOf(const std::string& json) {
  return test::errorMessageOf([&] { scene::parseScene(json, "dir/s.json"); });
}

std::string sceneWithShape(const std::string& shape) {
  return R"({"camera": {"resolution": [4, 4]}, "objects": [{"shape": )" + shape + "}]}";
}

}  // namespace

TEST_CASE("disk: every hit lies on the annulus, and rays through the hole or the cut miss") {
  Quadric q;
  q.kind = Quadric::Kind::Disk;
  q.radius = 2.0f;
  q.innerRadius = 0.5f;
  q.height = 0.25f;
  q.phiMax = 0.75f * kTwoPi;  // phi in (270, 360) degrees is cut away
  Lcg r;
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    Vec3f target{4 * r.next() - 2, 4 * r.next() - 2, q.height};
    Vec3f o{3 * r.next() - 1.5f, 3 * r.next() - 1.5f, 3.0f};
    Vec3f d = target - o;
    float s = 0;
    bool hit = intersectQuadric(q, o, d, 0.0f, 1e30f, s);
    float rr = std::sqrt(target.x * target.x + target.y * target.y);
    float phi = std::atan2(target.y, target.x);
    if (phi < 0) phi += kTwoPi;
    bool inside = rr <= q.radius && rr >= q.innerRadius && phi <= q.phiMax;
    // Away from the boundaries (float rounding), the hit is exactly the test.
    bool nearEdge = std::fabs(rr - q.radius) < 1e-4f || std::fabs(rr - q.innerRadius) < 1e-4f ||
                    std::fabs(phi - q.phiMax) < 1e-4f || phi < 1e-4f;
    if (!nearEdge) CHECK(hit == inside);
    if (hit) {
      ++hits;
      Vec3f p = o + d * s;
      CHECK(std::fabs(p.z - q.height) < 1e-5f);
      CHECK(std::fabs(s - 1.0f) < 1e-5f);  // the ray reaches its target at s = 1
    }
  }
  CHECK(hits > 1000);
  // Parallel to the plane: no hit; behind the origin (s < 0): no hit.
  float s;
  CHECK_FALSE(intersectQuadric(q, {0, 1, 0.25f}, {1, 0, 0}, 0.0f, 1e30f, s));
  CHECK_FALSE(intersectQuadric(q, {1, 0, 1}, {0, 0, 1}, 0.0f, 1e30f, s));
  CHECK(quadricNormal(q, {1, 0, q.height}).z == 1.0f);
  CHECK(quadricArea(q) == doctest::Approx(0.5 * 0.75 * 2 * 3.14159265 * (4 - 0.25)).epsilon(1e-5));
}

TEST_CASE("cylinder: hits at the analytic distance, both walls, z range and phi cut") {
  Quadric q;
  q.kind = Quadric::Kind::Cylinder;
  q.radius = 0.5f;
  q.zMin = -1.0f;
  q.zMax = 2.0f;
  float s = 0;
  // Head-on from x = -5: the near wall at s = 4.5, from inside the far wall at 0.5.
  REQUIRE(intersectQuadric(q, {-5, 0, 0.3f}, {1, 0, 0}, 0.0f, 1e30f, s));
  CHECK(s == doctest::Approx(4.5f).epsilon(1e-6));
  REQUIRE(intersectQuadric(q, {0, 0, 0.3f}, {1, 0, 0}, 0.0f, 1e30f, s));
  CHECK(s == doctest::Approx(0.5f).epsilon(1e-6));
  // Above z_max: no hit; along the axis: no hit.
  CHECK_FALSE(intersectQuadric(q, {-5, 0, 2.1f}, {1, 0, 0}, 0.0f, 1e30f, s));
  CHECK_FALSE(intersectQuadric(q, {0, 0, -5}, {0, 0, 1}, 0.0f, 1e30f, s));
  // A slanted ray from far away: the hit is on x^2 + y^2 = r^2 (double inside).
  Lcg r;
  for (int i = 0; i < 2000; ++i) {
    Vec3f o{200 * r.next() - 100, 200 * r.next() - 100, 6 * r.next() - 3};
    Vec3f target{r.next() - 0.5f, r.next() - 0.5f, 3 * r.next() - 1};
    Vec3f d = target - o;
    if (!intersectQuadric(q, o, d, 0.0f, 1e30f, s)) continue;
    Vec3f p = o + d * s;
    CHECK(std::fabs(std::sqrt(p.x * p.x + p.y * p.y) - q.radius) < 2e-4f * length(d));
    CHECK(p.z >= q.zMin - 1e-3f);
    CHECK(p.z <= q.zMax + 1e-3f);
    Vec3f n = quadricNormal(q, p);
    CHECK(std::fabs(n.z) == 0.0f);
    CHECK(length(n) == doctest::Approx(1.0f));
  }
  // phi_max 180: the half at y < 0 is gone, so a ray from -y meets the far (y > 0) wall.
  q.phiMax = 0.5f * kTwoPi;
  REQUIRE(intersectQuadric(q, {0, -5, 0}, {0, 1, 0}, 0.0f, 1e30f, s));
  CHECK(s == doctest::Approx(5.5f).epsilon(1e-6));
  CHECK(quadricArea(q) == doctest::Approx(3.14159265 * 0.5 * 3).epsilon(1e-5));
}

TEST_CASE("disk and cylinder in a scene: placed hits, outward normals, reverse_orientation flips them") {
  auto d = test::emptyScene(4, 4);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  scene::ObjectDesc cyl = cylinderObject(1.0f, 0.0f, 2.0f, 360, 0);
  cyl.placement.translate = {3, 0, 0};
  cyl.placement.rotate = Quaternion::fromAxisAngle({1, 0, 0}, -0.5f * 3.14159265f);  // axis +z -> +y
  cyl.placement.scale = {2, 1, 1};  // an elliptic cylinder: x semi-axis 2
  d.objects.push_back(cyl);
  scene::ObjectDesc disk = diskObject(1.0f, 0.0f, 0.0f, 360, 0);
  disk.placement.translate = {-3, 1, 0};
  disk.shape.reverseOrientation = true;  // normal -z instead of +z
  d.objects.push_back(disk);
  auto s = Scene::build(d);
  Hit h;
  // From +x toward the elliptic cylinder's side (x semi-axis 2 around x = 3).
  REQUIRE(s->intersect({10, 1, 0}, {-1, 0, 0}, 1e30f, 0.5f, h));
  CHECK(h.object == 0);
  CHECK(h.p.x == doctest::Approx(5.0f).epsilon(1e-5));
  CHECK(h.n.x == doctest::Approx(1.0f).epsilon(1e-5));
  // Off-axis: the normal is the ellipse's, (x/4, z/1) normalised, in the x-z plane.
  REQUIRE(s->intersect({3 + 1.2f, 1.5f, 10}, {0, 0, -1}, 1e30f, 0.5f, h));
  float x = 1.2f, z = std::sqrt(1 - x * x / 4);
  CHECK(h.p.z == doctest::Approx(z).epsilon(1e-5));
  Vec3f expect = normalize(Vec3f{x / 4, 0, z});
  CHECK(dot(h.n, expect) == doctest::Approx(1.0f).epsilon(1e-5));
  // Beyond the cylinder's height (world y in [0, 2]): a miss.
  CHECK_FALSE(s->intersect({10, 2.5f, 0}, {-1, 0, 0}, 1e30f, 0.5f, h));
  // The reversed disk: hit from +z, its normal is -z.
  REQUIRE(s->intersect({-3, 1.2f, 5}, {0, 0, -1}, 1e30f, 0.5f, h));
  CHECK(h.object == 1);
  CHECK(h.t == doctest::Approx(5.0f));
  CHECK(h.n.z == doctest::Approx(-1.0f));
  CHECK(s->occluded({-3, 1.2f, 5}, {0, 0, -1}, 6.0f, 0.5f));
  CHECK_FALSE(s->occluded({-3, 1.2f, 5}, {0, 0, -1}, 4.0f, 0.5f));
  // reverse_orientation on a sphere and a quad too.
  auto d2 = test::emptyScene(4, 4);
  d2.materials.push_back(test::diffuse(Rgb(0.5f)));
  d2.objects.push_back(test::sphere(1.0f, {0, 0, 0}, 0));
  d2.objects.back().shape.reverseOrientation = true;
  d2.objects.push_back(test::quad({1, 1}, {5, 0, 0}, 0));
  d2.objects.back().shape.reverseOrientation = true;
  auto s2 = Scene::build(d2);
  REQUIRE(s2->intersect({0, 0, 5}, {0, 0, -1}, 1e30f, 0.5f, h));
  CHECK(h.n.z == doctest::Approx(-1.0f));
  REQUIRE(s2->intersect({5, 5, 0}, {0, -1, 0}, 1e30f, 0.5f, h));
  CHECK(h.n.y == doctest::Approx(-1.0f));
}

TEST_CASE("reverse_orientation turns glass inside out: total internal reflection where light would enter") {
  // A glass disk (ior 1.5) hit from +z at 60 degrees: entering, Fresnel
  // F = 0.0894 (fresnelDielectric); reversed, the ray is taken to leave the
  // glass, and sin t = 1.5 sin 60 > 1: total internal reflection, F = 1.
  for (bool reversed : {false, true}) {
    CAPTURE(reversed);
    auto d = test::emptyScene(4, 4);
    scene::MaterialDesc glass;
    glass.type = scene::MaterialDesc::Type::Dielectric;
    glass.ior = 1.5f;
    d.materials.push_back(glass);
    d.objects.push_back(diskObject(1.0f, 0.0f, 0.0f, 360, 0));
    d.objects.back().shape.reverseOrientation = reversed;
    auto s = Scene::build(d);
    Vec3f dir = normalize(Vec3f{std::sin(1.0471976f), 0, -std::cos(1.0471976f)});
    Hit h;
    REQUIRE(s->intersect(Vec3f{0, 0, 0} - dir * 2.0f, dir, 1e30f, 0.5f, h));
    const Material& m = s->materials[0];
    ShadingContext c = makeShadingContext(m, Rgb(1.0f), h.n, -dir);
    BsdfSample refl, refr;
    float F = dielectricBranches(c, Transport::Radiance, refl, refr);
    if (reversed) {
      CHECK(F == 1.0f);
    } else {
      CHECK(F == doctest::Approx(fresnelDielectric(0.5f, 1.5f)));
      CHECK(F < 0.1f);
      CHECK(refr.wi.z < 0);  // transmitted: through the disk
    }
  }
}

TEST_CASE("a moving cylinder is where its motion puts it at the ray's time") {
  auto d = test::emptyScene(4, 4);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  scene::ObjectDesc cyl = cylinderObject(0.5f, -1.0f, 1.0f, 360, 0);
  cyl.motion = test::translation({0, 0, 0}, {2, 0, 0});
  d.objects.push_back(cyl);
  auto s = Scene::build(d);
  Hit h;
  for (float t : {0.0f, 0.25f, 1.0f}) {
    REQUIRE(s->intersect({-10, 0, 0}, {1, 0, 0}, 1e30f, t, h));
    CHECK(h.p.x == doctest::Approx(2 * t - 0.5f).epsilon(1e-5));
    CHECK(h.n.x == doctest::Approx(-1.0f).epsilon(1e-5));
  }
  // Swept bounds cover the whole path.
  CHECK(s->objects[0].sweptBounds.lo.x <= -0.5f);
  CHECK(s->objects[0].sweptBounds.hi.x >= 2.5f);
}

namespace {

// The same cylinder (axis z, z in [0, h]) and disk (at z = 0) as triangles:
// 720 sides, so the area differs from the analytic shapes' by ~1e-5.
scene::ObjectDesc tessellatedCylinder(float r, float h, uint32_t material) {
  const int n = 720;
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Mesh;
  o.material = material;
  for (int i = 0; i < n; ++i) {
    float phi = kTwoPi * float(i) / float(n);
    o.shape.vertices.push_back({r * std::cos(phi), r * std::sin(phi), 0});
    o.shape.vertices.push_back({r * std::cos(phi), r * std::sin(phi), h});
  }
  for (uint32_t i = 0; i < uint32_t(n); ++i) {
    uint32_t a = 2 * i, b = 2 * i + 1, c = 2 * ((i + 1) % n), e = 2 * ((i + 1) % n) + 1;
    o.shape.indices.insert(o.shape.indices.end(), {a, c, e, a, e, b});  // outward
  }
  return o;
}

scene::ObjectDesc tessellatedDisk(float r, uint32_t material) {
  const int n = 720;
  scene::ObjectDesc o;
  o.shape.type = scene::ShapeDesc::Type::Mesh;
  o.material = material;
  o.shape.vertices.push_back({0, 0, 0});
  for (int i = 0; i < n; ++i) {
    float phi = kTwoPi * float(i) / float(n);
    o.shape.vertices.push_back({r * std::cos(phi), r * std::sin(phi), 0});
  }
  for (uint32_t i = 0; i < uint32_t(n); ++i) o.shape.indices.insert(o.shape.indices.end(), {0, 1 + i, 1 + (i + 1) % n});
  return o;
}

scene::SceneDescription quadricStage(bool analytic) {
  auto d = test::emptyScene(48, 36);
  d.camera.position = {0, -6, 3};
  d.camera.target = {0, 0, 0.6f};
  d.camera.up = {0, 0, 1};
  d.camera.fovDegrees = 40;
  d.materials.push_back(test::diffuse(Rgb(0.7f)));
  d.materials.push_back(test::diffuse(Rgb(0.4f, 0.6f, 0.3f)));
  if (analytic) {
    d.objects.push_back(diskObject(3.0f, 0.0f, 0.0f, 360, 0));
    d.objects.push_back(cylinderObject(0.8f, 0.0f, 1.5f, 360, 1));
  } else {
    d.objects.push_back(tessellatedDisk(3.0f, 0));
    d.objects.push_back(tessellatedCylinder(0.8f, 1.5f, 1));
  }
  d.objects.back().placement.translate = {0.3f, 0.2f, 0};
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {2, -3, 4};
  l.power = Rgb(600.0f);
  d.lights.push_back(l);
  return d;
}

}  // namespace

TEST_CASE("a diffuse disk and cylinder render as a finely tessellated mesh of them does") {
  // Depth 1 (direct light from the point light): the same seed gives the
  // same camera rays, so the images differ only where the surfaces do
  // (720-gon: silhouettes within 1e-5 of the radius, facet normals within
  // 0.25 degrees). The analytic shapes' hits, normals and shadows must match.
  RenderOptions o1 = test::smallRenderOptions(RenderMethod::PathTrace, 8, 1, 7);
  Film a = test::renderOnce(quadricStage(true), o1);
  Film m = test::renderOnce(quadricStage(false), o1);
  double sa = test::imageSum(a), sm = test::imageSum(m);
  REQUIRE(sm > 0);
  CHECK(std::fabs(sa - sm) / sm < 1e-3);  // measured 5.4e-6
  double absDiff = 0;
  for (size_t i = 0; i < a.color.size(); ++i)
    absDiff += std::fabs(a.color[i].r - m.color[i].r) + std::fabs(a.color[i].g - m.color[i].g) + std::fabs(a.color[i].b - m.color[i].b);
  CHECK(absDiff / sm < 1e-3);  // measured 5.1e-5
  // Depth 2 adds the bounce between the cylinder and the floor: the sums'
  // relative noise at 16 spp is well under 0.5%.
  RenderOptions o2 = test::smallRenderOptions(RenderMethod::PathTrace, 16, 2, 7);
  double s2a = test::imageSum(test::renderOnce(quadricStage(true), o2));
  double s2m = test::imageSum(test::renderOnce(quadricStage(false), o2));
  CHECK(s2a > 1.02 * sa);  // the bounce is there
  CHECK(std::fabs(s2a - s2m) / s2m < 5e-3);  // measured 2.0e-4
  // Reversed, a diffuse cylinder looks the same (diffuse shading faces the
  // viewer whichever way the normal points; glass is what the flag is for).
  auto rev = quadricStage(true);
  rev.objects[1].shape.reverseOrientation = true;
  Film r = test::renderOnce(rev, o1);
  CHECK(std::fabs(test::imageSum(r) - sa) / sa < 1e-3);
}

TEST_CASE("JSON disk and cylinder: keys, defaults, round trip through the writer, errors") {
  scene::SceneDescription d = scene::parseScene(
      sceneWithShape(R"({"type": "disk", "radius": 2, "inner_radius": 0.5, "height": 0.25, "phi_max": 270, "reverse_orientation": true})"),
      "dir/s.json");
  REQUIRE(d.objects.size() == 1);
  const scene::ShapeDesc& s = d.objects[0].shape;
  CHECK(s.type == scene::ShapeDesc::Type::Disk);
  CHECK(s.radius == 2.0f);
  CHECK(s.innerRadius == 0.5f);
  CHECK(s.height == 0.25f);
  CHECK(s.phiMax == 270.0f);
  CHECK(s.reverseOrientation);
  scene::SceneDescription c = scene::parseScene(sceneWithShape(R"({"type": "cylinder"})"), "dir/s.json");
  CHECK(c.objects[0].shape.type == scene::ShapeDesc::Type::Cylinder);
  CHECK(c.objects[0].shape.zMin == -1.0f);
  CHECK(c.objects[0].shape.zMax == 1.0f);
  CHECK(c.objects[0].shape.phiMax == 360.0f);
  CHECK_FALSE(c.objects[0].shape.reverseOrientation);
  // Written and read back: the same fields.
  for (const scene::SceneDescription* src : {&d, &c}) {
    pbrt::SceneJson j = pbrt::sceneToJson(*src, "dir/out.json");
    scene::SceneDescription back = scene::parseScene(j.json, "dir/out.json");
    const scene::ShapeDesc &x = src->objects[0].shape, &y = back.objects[0].shape;
    CHECK(x.type == y.type);
    CHECK(x.radius == y.radius);
    CHECK(x.innerRadius == y.innerRadius);
    CHECK(x.height == y.height);
    CHECK(x.zMin == y.zMin);
    CHECK(x.zMax == y.zMax);
    CHECK(x.phiMax == y.phiMax);
    CHECK(x.reverseOrientation == y.reverseOrientation);
  }
  CHECK(errorOf(sceneWithShape(R"({"type": "disk", "radius": -1})")).find("objects[0].shape.radius: radius must be positive, got -1") !=
        std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "disk", "inner_radius": 1})")).find("inner_radius 1 must be below radius 1") !=
        std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "disk", "inner_radius": -0.5})")).find("inner_radius must be >= 0") != std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "cylinder", "z_min": 2, "z_max": 1})")).find("z_min 2 must be below z_max 1") !=
        std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "cylinder", "phi_max": 400})")).find("phi_max must be in (0, 360] degrees") !=
        std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "sphere", "reverse_orientation": 1})")).find("reverse_orientation: expected true or false") !=
        std::string::npos);
  CHECK(errorOf(sceneWithShape(R"({"type": "cylinder", "height": 1})")).find("height") != std::string::npos);
}

TEST_CASE("pbrt disk and cylinder: parameters, placement and pbrt's orientation rules") {
  scene::SceneDescription d = pbrt::importPbrtText(R"(WorldBegin
Shape "disk" "float radius" 2 "float innerradius" 0.5 "float height" 0.25 "float phimax" 90
AttributeBegin
  Translate 1 2 3
  ReverseOrientation
  Shape "cylinder" "float radius" 0.5 "float zmin" -1 "float zmax" 2
  AttributeBegin
    ReverseOrientation
    Shape "disk"
  AttributeEnd
  Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0]
AttributeEnd
Shape "cylinder"
AttributeBegin
  Scale 1 1 -1
  Shape "sphere"
  Shape "disk"
AttributeEnd
)", "dir/t.pbrt").scene;
  REQUIRE(d.objects.size() == 7);
  const scene::ShapeDesc& disk = d.objects[0].shape;
  CHECK(disk.type == scene::ShapeDesc::Type::Disk);
  CHECK(disk.radius == 2.0f);
  CHECK(disk.innerRadius == 0.5f);
  CHECK(disk.height == 0.25f);
  CHECK(disk.phiMax == 90.0f);
  CHECK_FALSE(disk.reverseOrientation);
  const scene::ShapeDesc& cyl = d.objects[1].shape;
  CHECK(cyl.type == scene::ShapeDesc::Type::Cylinder);
  CHECK(cyl.zMin == -1.0f);
  CHECK(cyl.zMax == 2.0f);
  CHECK(cyl.reverseOrientation);                       // ReverseOrientation
  CHECK_FALSE(d.objects[2].shape.reverseOrientation);  // toggled back inside
  CHECK(d.objects[3].shape.reverseOrientation);        // AttributeEnd restored the outer state: meshes too
  CHECK_FALSE(d.objects[4].shape.reverseOrientation);  // and the outermost
  // Under a handedness-swapping transform pbrt flips an analytic shape's normal.
  CHECK(d.objects[5].shape.reverseOrientation);
  CHECK(d.objects[6].shape.reverseOrientation);
  // The import mirrors x (docs/pbrt-import.md, "Handedness"): translate x is negated.
  CHECK(d.objects[1].placement.translate.x == -1.0f);
  CHECK(d.objects[1].placement.translate.y == 2.0f);
  CHECK(d.objects[1].placement.translate.z == 3.0f);
  // Built alone: a ray down the world z axis meets the disk at z = 0.25
  // with normal +z where phi is in [0, 90] and passes where it is cut away.
  scene::SceneDescription one = pbrt::importPbrtText(
      "WorldBegin\nShape \"disk\" \"float radius\" 2 \"float innerradius\" 0.5 \"float height\" 0.25 \"float phimax\" 90\n",
      "dir/t.pbrt").scene;
  one.camera.width = one.camera.height = 4;
  auto s = Scene::build(one);
  Hit h;
  // pbrt (1, 0.3) (phi 17 degrees) is tdpm (-1, 0.3).
  REQUIRE(s->intersect({-1, 0.3f, 10}, {0, 0, -1}, 1e30f, 0.5f, h));
  CHECK(h.p.z == doctest::Approx(0.25f));
  CHECK(h.n.z == doctest::Approx(1.0f));
  CHECK_FALSE(s->intersect({1, 0.3f, 10}, {0, 0, -1}, 1e30f, 0.5f, h));   // pbrt phi 163: cut
  CHECK_FALSE(s->intersect({-0.2f, 0.2f, 10}, {0, 0, -1}, 1e30f, 0.5f, h));  // in the hole
}

TEST_CASE("pbrt ReverseOrientation turns a rectangular area light's emitting side") {
  const std::string light =
      "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] "
      "\"integer indices\" [0 1 2 0 2 3]\n";
  auto emitDir = [](const scene::SceneDescription& d) {
    // The area light emits toward its local -y, or +y when reversed.
    const scene::LightDesc& l = d.lights.at(0);
    return Affine3f::rotate(l.placement.rotate).vector({0, l.reverseOrientation ? 1.0f : -1.0f, 0});
  };
  scene::SceneDescription plain = pbrt::importPbrtText("WorldBegin\n" + light, "dir/t.pbrt").scene;
  scene::SceneDescription reversed = pbrt::importPbrtText("WorldBegin\nReverseOrientation\n" + light, "dir/t.pbrt").scene;
  CHECK(emitDir(plain).z == doctest::Approx(1.0f));  // (p1 - p0) x (p2 - p0) = +z
  CHECK(emitDir(reversed).z == doctest::Approx(-1.0f));
}

TEST_CASE("pbrt bilinear patch: a curved patch's surface positions follow the bilinear formula") {
  // p(u, v) = (u, v, u v): a saddle, far from two triangles (gap 1/4 at the centre).
  pbrt::ImportResult r = pbrt::importPbrtText(
      "WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 1]\n", "dir/t.pbrt");
  scene::SceneDescription d = r.scene;
  REQUIRE(d.objects.size() == 1);
  // 1e-3 of the longest edge (sqrt 2): n = ceil(sqrt(|T| / (4e-3 sqrt 2))) = 14 cells a side.
  CHECK(d.objects[0].shape.indices.size() == 3u * 2 * 14 * 14);
  // Every vertex on the surface (the import mirrors x: pbrt's u is -x).
  for (Vec3f v : d.objects[0].shape.vertices) CHECK(std::fabs(v.z - (-v.x) * v.y) < 1e-6f);
  d.camera.width = d.camera.height = 4;
  auto s = Scene::build(d);
  Lcg g;
  double worst = 0;
  for (int i = 0; i < 400; ++i) {
    float u = 0.02f + 0.96f * g.next(), v = 0.02f + 0.96f * g.next();
    Hit h;
    REQUIRE(s->intersect({-u, v, 5}, {0, 0, -1}, 1e30f, 0.5f, h));
    worst = std::max(worst, double(std::fabs(h.p.z - u * v)));
  }
  // Within the stated tolerance (1e-3 x sqrt 2), and much closer than two triangles (0.25).
  CHECK(worst <= 1e-3 * std::sqrt(2.0));
  // A flat parallelogram stays two triangles; the note-free path.
  scene::SceneDescription flat =
      pbrt::importPbrtText("WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n", "dir/t.pbrt").scene;
  CHECK(flat.objects[0].shape.indices.size() == 6u);
}

TEST_CASE("disk and cylinder (u, v) are pbrt's: u = phi / phi_max, v from the rim inward / from z_min up") {
  auto d = test::emptyScene(4, 4);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(diskObject(2.0f, 0.5f, 0.0f, 180, 0));          // upper half annulus, z = 0
  scene::ObjectDesc cyl = cylinderObject(1.0f, 1.0f, 3.0f, 360, 0);  // r 1, z in [1, 3]
  cyl.placement.translate = {10, 0, 0};
  d.objects.push_back(cyl);
  auto s = Scene::build(d);
  Hit h;
  // Disk at (x, y) = (0, 1.25): phi = 90 deg of 180 -> u 0.5; r = 1.25 -> v = (2 - 1.25) / 1.5 = 0.5.
  REQUIRE(s->intersect({0, 1.25f, 5}, {0, 0, -1}, 1e30f, 0.5f, h));
  REQUIRE(h.object == 0);
  Vec2f uv = s->uvAt(h);
  CHECK(uv.x == doctest::Approx(0.5f).epsilon(1e-5));
  CHECK(uv.y == doctest::Approx(0.5f).epsilon(1e-5));
  // Cylinder hit from -y at z = 2.5: phi = 270 deg -> u 0.75; v = (2.5 - 1) / 2 = 0.75.
  REQUIRE(s->intersect({10, -5, 2.5f}, {0, 1, 0}, 1e30f, 0.5f, h));
  REQUIRE(h.object == 1);
  uv = s->uvAt(h);
  CHECK(uv.x == doctest::Approx(0.75f).epsilon(1e-5));
  CHECK(uv.y == doctest::Approx(0.75f).epsilon(1e-5));
}
