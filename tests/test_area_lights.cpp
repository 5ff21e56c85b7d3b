// tests/test_area_lights.cpp — area lights of every shape (scene/area_light.cpp):
// irradiance by next-event estimation against closed forms (a sphere: pi L
// (r/d)^2 cos theta while it is above the horizon, inside an inward one pi L;
// a disk on its axis pi L r^2 / (r^2 + h^2)), the density of every sample
// equal to the one MIS asks for at the same point, a mesh emitter's watts
// L pi A (twosided 2x) from the pbrt import and its photons' energy and
// spread by area, a moving sphere light's irradiance the time average of the
// closed form, a path-traced floor under each shape (and under a moving
// sphere: the time average) against the closed form (BSDF rays and light
// samples combined by MIS) and a photon method within a bound of it, `tdpm convert` writing the same pixels, and bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "import/pbrt_import.h"
#include "photon/tracer.h"
#include "render/fingerprint.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "cli_harness.h"
#include "render_fixtures.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

Vec2f u2(Rng& rng) {
  float a = rng.uniform();
  return {a, rng.uniform()};
}

scene::LightDesc sphereLight(float r, Vec3f c, Rgb power) {
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaShape = scene::LightDesc::AreaShape::Sphere;
  l.radius = r;
  l.placement.translate = c;
  l.power = power;
  return l;
}

scene::LightDesc diskLight(float r, Vec3f c, Rgb power) {
  scene::LightDesc l = sphereLight(r, c, power);
  l.areaShape = scene::LightDesc::AreaShape::Disk;  // local x-z plane, emits toward -y
  return l;
}

// Two triangles in the plane y = h, areas 1 and 3, facing down (-y).
scene::LightDesc meshLight(float h, Rgb power) {
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaShape = scene::LightDesc::AreaShape::Mesh;
  l.mesh.type = scene::ShapeDesc::Type::Mesh;
  l.mesh.vertices = {{0, h, 0}, {1, h, 0}, {0, h, 2}, {2, h, 0}, {2, h, 3}, {4, h, 0}};
  // (1,0,0) x (0,0,2) = (0,-2,0): counter-clockwise seen from below.
  l.mesh.indices = {0, 1, 2, 3, 5, 4};
  l.power = power;
  return l;
}

std::unique_ptr<Scene> lightsOnly(const std::vector<scene::LightDesc>& lights) {
  auto d = test::emptyScene(8, 8);
  d.lights = lights;
  return Scene::build(d);
}

// Irradiance on a surface at p with normal n by next-event estimation
// (stratified n x n samples), unoccluded, at time t (< 0: uniform over the shutter).
double irradiance(const Light& light, Vec3f p, Vec3f n, float t = 0.5f, int strata = 256) {
  double sum = 0;
  Rng rng(7, 0);
  for (int i = 0; i < strata; ++i)
    for (int j = 0; j < strata; ++j) {
      Vec2f u{(i + rng.uniform()) / strata, (j + rng.uniform()) / strata};
      float time = t < 0 ? rng.uniform() : t;
      LightSample ls;
      if (!sampleLight(light, p, time, u, ls)) continue;
      float c = dot(ls.wi, n);
      if (c > 0) sum += ls.li.g * c / ls.pdf;
    }
  return sum / (double(strata) * strata);
}

// Every sample's pdf equals the density areaLightPdf gives the same point
// (the MIS weight of a BSDF ray that hits it), and the radiance agrees.
void checkPdfConsistency(const Scene& s, const Light& light, Vec3f p, float time) {
  Rng rng(3, 0);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    LightSample ls;
    if (!sampleLight(light, p, time, u2(rng), ls)) continue;
    Hit h;
    REQUIRE(s.intersect(p, ls.wi, 1e30f, time, h));
    REQUIRE(h.isLight());
    CHECK(h.t == doctest::Approx(ls.distance).epsilon(1e-3));
    AreaLightFrame f = areaLightFrame(light, time);
    CHECK(areaLightPdf(light, f, p, h.p, h.n) == doctest::Approx(ls.pdf).epsilon(2e-3));
    CHECK(areaLightRadiance(light, f, h.n, -ls.wi).g == doctest::Approx(ls.li.g));
    ++checked;
  }
  CHECK(checked > 150);
}

}  // namespace

TEST_CASE("sphere light: irradiance on a plane against the closed form, pdfs as MIS asks for them") {
  const float r = 0.5f, P = 100.0f;
  auto s = lightsOnly({sphereLight(r, {0, 3, 0}, Rgb(P))});
  const Light& l = s->lights[0];
  float L = P / (4.0f * kPi * kPi * r * r);  // power = L pi A, A = 4 pi r^2
  CHECK(areaLightFrame(l, 0.5f).radiance.g == doctest::Approx(L));
  // Under the centre: E = pi L (r/d)^2.
  CHECK(irradiance(l, {0, 0, 0}, {0, 1, 0}) == doctest::Approx(kPi * L * r * r / 9.0f).epsilon(1e-3));
  // Off the axis, the sphere wholly above the horizon: E = pi L (r/d)^2 cos theta.
  Vec3f p{2, 0, 1};
  Vec3f d = Vec3f(0, 3, 0) - p;
  double cosT = 3.0 / length(d);
  CHECK(irradiance(l, p, {0, 1, 0}) == doctest::Approx(kPi * L * r * r / lengthSquared(d) * cosT).epsilon(1e-3));
  // A tilted receiver: the same law with its own cosine.
  Vec3f n = normalize(Vec3f{1, 1, 0});
  CHECK(irradiance(l, p, n) == doctest::Approx(kPi * L * r * r / lengthSquared(d) * dot(normalize(d), n)).epsilon(1e-3));
  checkPdfConsistency(*s, l, p, 0.5f);
  checkPdfConsistency(*s, l, {0, 2.49f, 0}, 0.5f);  // just outside: the cone is almost a hemisphere

  // A tiny sphere far away (veach-mis's smallest light is 0.05 m at ~10 m):
  // 1 - cos theta_max = 1.25e-7 is below float's spacing near 1.
  auto tiny = lightsOnly({sphereLight(0.01f, {0, 20, 0}, Rgb(P))});
  float Lt = P / (4.0f * kPi * kPi * 1e-4f);
  CHECK(irradiance(tiny->lights[0], {0, 0, 0}, {0, 1, 0}) == doctest::Approx(kPi * Lt * 1e-4 / 400.0).epsilon(1e-3));

  // Inside an inward-emitting sphere every direction sees L: E = pi L.
  scene::LightDesc in = sphereLight(2.0f, {0, 0, 0}, Rgb(P));
  in.reverseOrientation = true;
  auto si = lightsOnly({in});
  float Li = P / (4.0f * kPi * kPi * 4.0f);
  CHECK(irradiance(si->lights[0], {0.3f, -0.5f, 0.2f}, {0, 1, 0}) == doctest::Approx(kPi * Li).epsilon(2e-3));
  checkPdfConsistency(*si, si->lights[0], {0.3f, -0.5f, 0.2f}, 0.5f);
  // ... and from outside it sends nothing; an outward sphere nothing inward.
  CHECK(irradiance(si->lights[0], {0, 5, 0}, {0, -1, 0}, 0.5f, 16) == 0.0);
  auto so = lightsOnly({sphereLight(2.0f, {0, 0, 0}, Rgb(P))});
  CHECK(irradiance(so->lights[0], {0.3f, -0.5f, 0.2f}, {0, 1, 0}, 0.5f, 16) == 0.0);
}

TEST_CASE("disk light: irradiance on its axis, one side or two") {
  const float r = 0.8f, h = 1.5f, P = 50.0f;
  auto s = lightsOnly({diskLight(r, {0, h, 0}, Rgb(P))});
  const Light& l = s->lights[0];
  float L = P / (kPi * kPi * r * r);
  CHECK(irradiance(l, {0, 0, 0}, {0, 1, 0}) == doctest::Approx(kPi * L * r * r / (r * r + h * h)).epsilon(1e-3));
  CHECK(irradiance(l, {0, 2 * h, 0}, {0, -1, 0}, 0.5f, 16) == 0.0);  // above: its back
  checkPdfConsistency(*s, l, {0.3f, 0, -0.4f}, 0.5f);

  scene::LightDesc two = diskLight(r, {0, h, 0}, Rgb(P));
  two.twoSided = true;  // the same watts over two sides: half the radiance each
  auto s2 = lightsOnly({two});
  double below = irradiance(s2->lights[0], {0, 0, 0}, {0, 1, 0});
  double above = irradiance(s2->lights[0], {0, 2 * h, 0}, {0, -1, 0});
  CHECK(below == doctest::Approx(0.5 * kPi * L * r * r / (r * r + h * h)).epsilon(1e-3));
  CHECK(above == doctest::Approx(below).epsilon(1e-3));

  // Rotated by 90 degrees about z: it emits toward +x.
  scene::LightDesc side = diskLight(r, {h, 0, 0}, Rgb(P));
  side.placement.rotate = Quaternion::fromAxisAngle({0, 0, 1}, kPi / 2);
  auto s3 = lightsOnly({side});
  CHECK(irradiance(s3->lights[0], {2 * h, 0, 0}, {-1, 0, 0}) ==
        doctest::Approx(kPi * L * r * r / (r * r + h * h)).epsilon(1e-3));
}

TEST_CASE("mesh light: radiance power / (pi A), uniform by area, photons carry its power") {
  const float P = 40.0f;
  auto s = lightsOnly({meshLight(2.0f, Rgb(P))});
  const Light& l = s->lights[0];
  AreaLightFrame f = areaLightFrame(l, 0.5f);
  CHECK(f.area == doctest::Approx(4.0f));
  CHECK(f.radiance.g == doctest::Approx(P / (kPi * 4.0f)));
  checkPdfConsistency(*s, l, {1, 0, 0.5f}, 0.5f);

  // Photons: mean flux = emittedPower, origins 1/4 on the small triangle,
  // every direction downward (the ccw side seen from below).
  const int n = 40000;
  Rng rng(11, 0);
  double flux = 0;
  int small = 0, up = 0;
  for (int i = 0; i < n; ++i) {
    EmittedRay ray;
    REQUIRE(emitFromLight(l, rng.uniform(), s->bounds, u2(rng), u2(rng), ray));
    flux += ray.flux.g;
    CHECK(ray.origin.y == doctest::Approx(2.0f));
    small += ray.origin.x + 0.5f * ray.origin.z < 1.0f + 1e-5f;
    up += ray.direction.y > 0;
  }
  CHECK(flux / n == doctest::Approx(emittedPower(l, s->bounds).g));
  CHECK(emittedPower(l, s->bounds).g == doctest::Approx(P));
  double frac = double(small) / n, sigma = std::sqrt(0.25 * 0.75 / n);
  CHECK(std::fabs(frac - 0.25) < 4 * sigma);
  CHECK(up == 0);

  // Twosided: half the photons leave each side.
  scene::LightDesc two = meshLight(2.0f, Rgb(P));
  two.twoSided = true;
  auto s2 = lightsOnly({two});
  up = 0;
  for (int i = 0; i < n; ++i) {
    EmittedRay ray;
    REQUIRE(emitFromLight(s2->lights[0], 0.5f, s2->bounds, u2(rng), u2(rng), ray));
    up += ray.direction.y > 0;
  }
  CHECK(std::fabs(double(up) / n - 0.5) < 4 * std::sqrt(0.25 / n));
}

TEST_CASE("photon emission of spheres and disks: flux = power, from the surface, into the emitting side") {
  auto s = lightsOnly({sphereLight(0.5f, {0, 3, 0}, Rgb(10.0f)), diskLight(0.5f, {0, 1, 0}, Rgb(7.0f))});
  Rng rng(5, 0);
  for (const Light& l : s->lights) {
    double flux = 0;
    for (int i = 0; i < 2000; ++i) {
      EmittedRay ray;
      REQUIRE(emitFromLight(l, 0.5f, s->bounds, u2(rng), u2(rng), ray));
      flux += ray.flux.g;
      AreaLightFrame f = areaLightFrame(l, 0.5f);
      Vec3f n = areaLightNormal(l, f, ray.origin, 0);
      CHECK(dot(ray.direction, n) >= 0.0f);
      if (l.shape == Light::AreaShape::Sphere) CHECK(length(ray.origin - f.center) == doctest::Approx(0.5f));
      else CHECK(ray.origin.y == doctest::Approx(1.0f));
    }
    CHECK(flux / 2000 == doctest::Approx(l.power.g));
  }
}

TEST_CASE("moving sphere light: irradiance is the time average; Embree's sphere moves with it") {
  scene::LightDesc d = sphereLight(0.25f, {0, 0, 0}, Rgb(30.0f));
  d.motion = test::translation({-1, 2, 0}, {1, 2, 0});
  auto s = lightsOnly({d});
  const Light& l = s->lights[0];
  float L = 30.0f / (4.0f * kPi * kPi * 0.25f * 0.25f);
  // E(t) = pi L r^2 cos / d^2 with the centre at (-1 + 2t, 2, 0), receiver (0.5, 0, 0) facing up.
  double avg = 0;
  const int q = 20000;
  for (int i = 0; i < q; ++i) {
    double t = (i + 0.5) / q, x = -1 + 2 * t - 0.5;
    double d2 = x * x + 4;
    avg += kPi * L * 0.0625 * (2 / std::sqrt(d2)) / d2;
  }
  avg /= q;
  CHECK(irradiance(l, {0.5f, 0, 0}, {0, 1, 0}, -1.0f, 400) == doctest::Approx(avg).epsilon(3e-3));
  for (float t : {0.0f, 0.5f, 1.0f}) {
    Hit h;
    float x = -1 + 2 * t;
    REQUIRE(s->intersect({x, 0, 0}, {0, 1, 0}, 1e30f, t, h));
    CHECK(h.isLight());
    CHECK(h.t == doctest::Approx(1.75f));
    checkPdfConsistency(*s, l, {0.5f, 0, 0}, t);
  }
}

namespace {

// A white diffuse floor (albedo 0.5) under one light, seen from above at
// an angle that keeps the light out of view (and not in the way); max
// depth 1: each pixel is (rho / pi) E at its floor point.
scene::SceneDescription floorUnder(const scene::LightDesc& light) {
  auto d = test::emptyScene(12, 12);
  d.camera.position = {0, 5, -3};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = 10;
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(test::quad({20, 20}, {0, 0, 0}, 0));
  d.lights.push_back(light);
  return d;
}

double centreValue(const Film& f) {
  double sum = 0;
  for (int y = 5; y < 7; ++y)
    for (int x = 5; x < 7; ++x) sum += f.color[size_t(y * f.width + x)].g;
  return sum / 4;
}

}  // namespace

TEST_CASE("pathtrace (MIS of light and BSDF samples) and a photon method against the closed form, every shape") {
  struct Case {
    const char* name;
    scene::LightDesc light;
    double e;  // irradiance at the floor's centre
  };
  const float P = 60.0f;
  scene::LightDesc sph = sphereLight(0.4f, {0, 2, 0}, Rgb(P));
  scene::LightDesc dsk = diskLight(0.6f, {0, 1.5f, 0}, Rgb(P));
  scene::LightDesc msh = meshLight(2.0f, Rgb(P));  // not centred: the centre's E by quadrature below
  scene::LightDesc rect;
  rect.type = scene::LightDesc::Type::Area;
  rect.areaSize = {0.8f, 0.8f};
  rect.placement.translate = {0, 1.5f, 0};
  rect.power = Rgb(P);
  rect.twoSided = true;
  auto centreE = [](const scene::LightDesc& l) {
    auto s = lightsOnly({l});
    return irradiance(s->lights[0], {0, 0, 0}, {0, 1, 0});
  };
  float Ls = P / (4 * kPi * kPi * 0.16f), Ld = P / (kPi * kPi * 0.36f);
  // Moving from x = -1 to 1 at height 2 over the shutter: the time average
  // of pi L r^2 h / d^3, d^2 = x^2 + h^2.
  scene::LightDesc mov = sphereLight(0.4f, {0, 0, 0}, Rgb(P));
  mov.motion = test::translation({-1, 2, 0}, {1, 2, 0});
  double avg = 0;
  for (int i = 0; i < 10000; ++i) {
    double x = -1 + 2 * (i + 0.5) / 10000;
    avg += kPi * Ls * 0.16 * 2 / std::pow(x * x + 4, 1.5) / 10000;
  }
  Case cases[] = {{"sphere", sph, kPi * Ls * 0.16 / 4.0},
                  {"moving sphere", mov, avg},
                  {"disk", dsk, kPi * Ld * 0.36 / (0.36 + 2.25)},
                  {"mesh", msh, centreE(msh)},
                  {"twosided rectangle", rect, centreE(rect)}};
  for (const Case& c : cases) {
    CAPTURE(c.name);
    scene::SceneDescription d = floorUnder(c.light);
    // The floor seen is a 2 x 2 pixel patch a few cm wide: E varies < 0.5% over it.
    double expect = 0.5 / kPi * c.e;
    Film pt = test::renderOnce(d, test::smallRenderOptions(RenderMethod::PathTrace, 1024, 1, 1));
    CHECK(centreValue(pt) == doctest::Approx(expect).epsilon(0.015));
    RenderOptions o = test::smallRenderOptions(RenderMethod::Standard, 64, 1, 1);
    o.globalPhotons = 200000;
    o.causticPhotons = 0;
    Film ph = test::renderOnce(d, o);
    MESSAGE(std::string(c.name) << ": pathtrace / closed form " << centreValue(pt) / expect << ", standard " << centreValue(ph) / expect);
    CHECK(centreValue(ph) == doctest::Approx(expect).epsilon(0.03));
  }
}

TEST_CASE("pbrt import: AreaLightSource on sphere, disk and meshes; tdpm convert renders the same pixels") {
  const std::string text = R"(LookAt 0 5 0.01  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
WorldBegin
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-5 0 -5 5 0 -5 5 0 5 -5 0 5] "integer indices" [0 1 2 0 2 3]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Translate -1 2 0
  Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
  Translate 1 2 0
  Rotate 180 1 0 0
  Shape "disk" "float radius" 0.4
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Translate 3 1 0
  Rotate -90 1 0 0
  Shape "disk" "float radius" 0.2
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [3 3 3]
  ReverseOrientation
  Shape "trianglemesh" "point3 P" [0 1 1  1 1 1  0 1 2] "integer indices" [0 1 2]
AttributeEnd
)";
  pbrt::ImportResult r = pbrt::importPbrtText(text, "al.pbrt");
  REQUIRE(r.scene.lights.size() == 4);
  const scene::LightDesc& sp = r.scene.lights[0];
  CHECK(sp.areaShape == scene::LightDesc::AreaShape::Sphere);
  CHECK(sp.power.g == doctest::Approx(2 * kPi * 4 * kPi * 0.09f));  // L pi A
  const scene::LightDesc& dk = r.scene.lights[1];
  CHECK(dk.areaShape == scene::LightDesc::AreaShape::Disk);
  CHECK(dk.twoSided);
  CHECK(dk.power.g == doctest::Approx(2 * kPi * kPi * 0.16f));  // twosided: 2 L pi A
  const scene::LightDesc& ms = r.scene.lights[3];
  CHECK(ms.areaShape == scene::LightDesc::AreaShape::Mesh);
  CHECK(ms.reverseOrientation);
  CHECK(ms.power.g == doctest::Approx(3 * kPi * 0.5f));

  // pbrt's disk faces +z; Rotate -90 about x turns it to +y: it lights
  // what is above it. The triangle's pbrt normal (1,0,0) x (0,0,1) is -y;
  // ReverseOrientation: it emits upward.
  auto s = Scene::build(r.scene);
  for (int i : {2, 3}) {
    CAPTURE(i);
    const Light& l = s->lights[size_t(i)];
    Vec3f c = areaLightFrame(l, 0.5f).center;
    CHECK(irradiance(l, c + Vec3f(0, 1, 0), {0, -1, 0}, 0.5f, 32) > 0.0);
    CHECK(irradiance(l, c - Vec3f(0, 1, 0), {0, 1, 0}, 0.5f, 32) == 0.0);
  }

  std::string dir = test::makeTempDir();
  pbrt::SceneJson j = pbrt::sceneToJson(r.scene, dir + "/al.json");
  for (const auto& [path, body] : j.meshFiles) std::ofstream(path) << body;
  std::ofstream(dir + "/al.json") << j.json;
  scene::SceneDescription back = scene::loadScene(dir + "/al.json");
  REQUIRE(back.lights.size() == 4);
  CHECK(back.lights[1].twoSided);
  CHECK(back.lights[3].reverseOrientation);
  std::filesystem::remove_all(dir);
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Time}) {
    RenderOptions o = test::smallRenderOptions(m, 4, 3, 2);
    o.causticPhotons = 2000;
    o.globalPhotons = 2000;
    Film a = test::renderOnce(r.scene, o), b = test::renderOnce(back, o);
    CHECK(test::sameImage(a, b));
    CHECK(test::imageSum(a) > 0);
  }
}

TEST_CASE("area lights: bad input is a located error") {
  auto jsonError = [](const std::string& light) {
    std::string text = R"({"camera": {}, "materials": {}, "objects": [], "lights": [)" + light + "]}";
    try {
      scene::parseScene(text, "t.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(jsonError(R"({"type": "sphere", "radius": -1})").find("lights[0].radius") != std::string::npos);
  CHECK(jsonError(R"({"type": "disk", "radius": 0})").find("lights[0].radius") != std::string::npos);
  CHECK(jsonError(R"({"type": "sphere", "transform": {"scale": [1, 2, 1]}})").find("ellipsoid") != std::string::npos);
  CHECK(jsonError(R"({"type": "disk", "transform": {"scale": [1, 1, 3]}})").find("ellipse") != std::string::npos);
  CHECK(jsonError(R"({"type": "sphere", "two_sided": 1})").find("lights[0].two_sided: expected true or false") !=
        std::string::npos);
  CHECK(jsonError(R"({"type": "disk", "size": [1, 1]})").find("lights[0]") != std::string::npos);
  CHECK(jsonError(R"({"type": "mesh"})").find("file") != std::string::npos);
  // Rotating round lights are fine (the motion's blended steps shorten axes
  // a little: no shape change); a keyframe that stretches them is not.
  CHECK(jsonError(R"({"type": "disk", "motion": [{"time": 0}, {"time": 1, "rotate": {"axis": [0, 0, 1], "angle": 90}}]})") == "");
  CHECK(jsonError(R"({"type": "sphere", "motion": [{"time": 0}, {"time": 1, "rotate": {"axis": [1, 1, 0], "angle": 170}}]})") == "");
  CHECK(jsonError(R"({"type": "sphere", "motion": [{"time": 0}, {"time": 1, "scale": [1, 1, 2]}]})")
            .find("lights[0].motion: a sphere light must scale uniformly") != std::string::npos);
  // A mesh light of collinear triangles has no area.
  scene::MeshSource flat = [](const std::string&, std::vector<Vec3f>* v, std::vector<uint32_t>* i) {
    *v = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    *i = {0, 1, 2};
    return true;
  };
  std::string e;
  try {
    scene::parseScene(R"({"camera": {}, "materials": {}, "objects": [], "lights": [{"type": "mesh", "file": "flat.obj"}]})", "t.json", flat);
  } catch (const Error& x) {
    e = x.what();
  }
  CAPTURE(e);
  CHECK(e.find("lights[0].file: the light's area 0 m^2") != std::string::npos);

  auto pbrtError = [](const std::string& world) {
    try {
      pbrt::importPbrtText("Camera \"perspective\"\nWorldBegin\n" + world, "t.pbrt");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(pbrtError("AreaLightSource \"diffuse\"\nShape \"sphere\" \"float radius\" -1\n")
            .find("t.pbrt:4: Shape \"sphere\": radius must be positive") == 0);
  CHECK(pbrtError("AreaLightSource \"diffuse\"\nShape \"disk\" \"float innerradius\" 0.5\n").find("t.pbrt:4: Shape \"disk\": an annulus") == 0);
  CHECK(pbrtError("AreaLightSource \"diffuse\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 2 0 0] \"integer indices\" [0 1 2]\n")
            .find("zero area") != std::string::npos);
  CHECK(pbrtError("AreaLightSource \"diffuse\"\nScale 1 2 1\nShape \"sphere\"\n").find("ellipsoid") != std::string::npos);
}

TEST_CASE("pbrt import: a twosided mesh emitter's watts are 2 L pi A; a moving one keeps pbrt's side") {
  // A trapezoid (not a rectangle: a mesh light) of area 1.5 at y = 1,
  // and a triangle facing +y moving along x.
  std::string text = R"(Camera "perspective" "float shutteropen" 0 "float shutterclose" 1
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2] "bool twosided" true
  Shape "trianglemesh" "point3 P" [0 1 0  2 1 0  1.5 1 1  0.5 1 1] "integer indices" [0 1 2 0 2 3]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  ActiveTransform EndTime
  Translate 1 0 0
  ActiveTransform All
  Shape "trianglemesh" "point3 P" [0 3 0  1 3 0  0 3 1] "integer indices" [0 2 1]
AttributeEnd
)";
  pbrt::ImportResult r = pbrt::importPbrtText(text, "two.pbrt");
  REQUIRE(r.scene.lights.size() == 2);
  CHECK(r.scene.lights[0].areaShape == scene::LightDesc::AreaShape::Mesh);
  CHECK(r.scene.lights[0].power.g == doctest::Approx(2 * 2 * kPi * 1.5f));
  CHECK(!r.scene.lights[1].motion.empty());
  auto s = Scene::build(r.scene);
  // pbrt's normal (0,0,1) x (1,0,0) = +y, under the import's x mirror too.
  const Light& m = s->lights[1];
  for (float t : {0.0f, 1.0f}) {
    Vec3f c = areaLightFrame(m, t).center;
    CHECK(irradiance(m, c + Vec3f(0, 1, 0), {0, -1, 0}, t, 16) > 0.0);
    CHECK(irradiance(m, c - Vec3f(0, 1, 0), {0, 1, 0}, t, 16) == 0.0);
  }
}

TEST_CASE("a mesh light's triangles are part of the scene's fingerprint (resume refuses a changed one)") {
  auto d = test::emptyScene(8, 8);
  d.lights.push_back(meshLight(2.0f, Rgb(10.0f)));
  std::string a = sceneDigest(d);
  d.lights[0].mesh.vertices[1].x = 1.5f;
  CHECK(sceneDigest(d) != a);
  d.lights[0].mesh.vertices[1].x = 1.0f;
  CHECK(sceneDigest(d) == a);
  d.lights[0].twoSided = true;
  CHECK(sceneDigest(d) != a);
}

TEST_CASE("pbrt import: a mesh emitter with shading normals N faces them, as pbrt turns its triangles") {
  // Wound to face -y, with N = +y at every vertex: pbrt emits upward
  // (and ignores ReverseOrientation for such a mesh).
  for (const char* extra : {"", "ReverseOrientation\n"}) {
    for (const char* tris : {"[0 1 2]", "[0 1 2 0 2 3]"}) {  // one triangle: a mesh light; two: a rectangle
      CAPTURE(extra);
      CAPTURE(tris);
      std::string text = std::string("Camera \"perspective\"\nWorldBegin\nAreaLightSource \"diffuse\"\n") + extra +
                         "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 0 1 0 0 1] \"integer indices\" " + tris +
                         " \"normal N\" [0 1 0 0 1 0 0 1 0 0 1 0]\n";
      pbrt::ImportResult r = pbrt::importPbrtText(text, "n.pbrt");
      auto s = Scene::build(r.scene);
      const Light& l = s->lights[0];
      Vec3f c = areaLightFrame(l, 0.5f).center;
      if (l.shape == Light::AreaShape::Mesh) c = s->lights[0].mesh->centroid;
      CHECK(irradiance(l, c + Vec3f(0, 1, 0), {0, -1, 0}, 0.5f, 16) > 0.0);
      CHECK(irradiance(l, c - Vec3f(0, 1, 0), {0, 1, 0}, 0.5f, 16) == 0.0);
    }
  }
}

TEST_CASE("moving disk and mesh lights: Embree's geometry, the frame and the pdfs agree at every time") {
  scene::LightDesc disk = diskLight(0.5f, {0, 0, 0}, Rgb(10.0f));
  disk.motion = test::translation({-1, 2, 0}, {1, 2, 0});
  disk.motion.poses[1].rotate = Quaternion::fromAxisAngle({0, 0, 1}, 0.5f);  // tilts as it goes
  scene::LightDesc mesh = meshLight(0.0f, Rgb(10.0f));
  mesh.motion = test::translation({-1, 3, 0}, {1, 3, 0});
  mesh.motion.poses[1].scale = {2, 2, 2};  // grows: every area x 4 by the end
  auto sd = lightsOnly({disk}), sm = lightsOnly({mesh});
  for (float t : {0.0f, 0.3f, 1.0f}) {
    CAPTURE(t);
    checkPdfConsistency(*sd, sd->lights[0], {0.2f, 0, 0.1f}, t);
    checkPdfConsistency(*sm, sm->lights[0], {0.5f, 0, 0.5f}, t);
    Hit h;
    REQUIRE(sd->intersect({-1 + 2 * t, 0, 0}, {0, 1, 0}, 2.5f, t, h));  // the disk's centre is above
    CHECK(h.isLight());
  }
  const Light& m = sm->lights[0];
  CHECK(areaLightFrame(m, 0.0f).area == doctest::Approx(4.0f));
  CHECK(areaLightFrame(m, 1.0f).area == doctest::Approx(16.0f));
  // The watts stay the same: the radiance falls as the area grows.
  CHECK(areaLightFrame(m, 1.0f).radiance.g == doctest::Approx(10.0f / (kPi * 16.0f)));
}

TEST_CASE("caustic photons aimed at the glass (projection maps) keep the energy of plain emission, every shape") {
  scene::LightDesc two = diskLight(0.3f, {0, 3, 0}, Rgb(100.0f));
  two.twoSided = true;
  scene::LightDesc mesh = meshLight(3.0f, Rgb(100.0f));
  mesh.placement.translate = {-1, 0, -1};
  scene::LightDesc lights[] = {sphereLight(0.3f, {0, 3, 0}, Rgb(100.0f)), diskLight(0.3f, {0, 3, 0}, Rgb(100.0f)), two, mesh};
  for (const scene::LightDesc& l : lights) {
    auto d = test::emptyScene(8, 8);
    d.materials.push_back(test::diffuse(Rgb(0.5f)));
    scene::MaterialDesc glass;
    glass.type = scene::MaterialDesc::Type::Dielectric;
    d.materials.push_back(glass);
    d.objects.push_back(test::quad({20, 20}, {0, 0, 0}, 0));
    d.objects.push_back(test::sphere(0.4f, {0.3f, 1.0f, 0}, 1));
    d.lights = {l};
    auto s = Scene::build(d);
    photon::TraceSettings ts;
    ts.kind = photon::MapKind::Caustic;
    ts.storedWanted = 40000;
    ts.seed = 17;
    photon::TraceResult with = photon::tracePhotons(*s, ts, Progress{});
    ts.projection = false;
    photon::TraceResult without = photon::tracePhotons(*s, ts, Progress{});
    auto total = [](const photon::PhotonStore& st) {
      double e = 0;
      for (size_t i = 0; i < st.size(); ++i) e += st.energy(i).average();
      return e;
    };
    double a = total(with.store), b = total(without.store);
    INFO("shape " << int(l.areaShape) << (l.twoSided ? " twosided" : "") << ": with projection " << a << " J from "
                  << with.emitted << " paths, without " << b << " J from " << without.emitted);
    REQUIRE(b > 0);
    CHECK(a == doctest::Approx(b).epsilon(0.03));  // ~40k photons each: a few per mille of noise
    CHECK(with.emitted < without.emitted);
  }
}

TEST_CASE("mesh lights under a mirror emit from the object-space normal's side, still or moving") {
  // Faces -y in object space (meshLight); mirrored in x: still -y.
  for (bool moving : {false, true}) {
    CAPTURE(moving);
    scene::LightDesc l = meshLight(0.0f, Rgb(10.0f));
    l.placement.scale = {-1, 1, 1};
    l.placement.translate = {0, 2, 0};
    if (moving) l.motion = test::translation({0, 0, 0}, {0.1f, 0, 0});
    auto s = lightsOnly({l});
    const Light& m = s->lights[0];
    Vec3f c = areaLightFrame(m, 0.5f).center;
    CHECK(irradiance(m, c - Vec3f(0, 1, 0), {0, 1, 0}, 0.5f, 16) > 0.0);
    CHECK(irradiance(m, c + Vec3f(0, 1, 0), {0, -1, 0}, 0.5f, 16) == 0.0);
    checkPdfConsistency(*s, m, c - Vec3f(0, 1, 0), 0.5f);
  }
}
