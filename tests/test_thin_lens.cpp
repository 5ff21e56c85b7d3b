// tests/test_thin_lens.cpp — the thin-lens camera (camera.lens_radius,
// focal_distance): a small black sphere in front of a white sky, off the
// focal plane, renders as a disc of the thin-lens circle of confusion
// c = A |d - f| / d (A = 2 lens_radius, on the focal plane; in pixels
// divided by the focal plane's pixel size 2 f tan(fov/2) / height); the
// same sphere on the focal plane stays as sharp as through a pinhole; the
// lens moves with a moving camera; bad radii and distances are located
// errors; the pbrt import and `tdpm convert` carry the lens.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "import/pbrt_import.h"
#include "render/renderer.h"
#include "scene/camera.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "render_fixtures.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

constexpr int kRes = 64;
const float kTanHalf = 0.5f;  // fov = 2 atan(0.5): the focal plane at f is 2 f tan / 64 = f / 64 m per pixel

// Camera at the origin looking down -z; a black sphere of radius rho at
// depth d on the axis; white sky.
scene::SceneDescription sphereAtDepth(float d, float rho, float lensRadius, float focal) {
  auto s = test::emptyScene(kRes, kRes);
  s.background = Rgb(1.0f);
  s.camera.position = {0, 0, 0};
  s.camera.target = {0, 0, -1};
  s.camera.fovDegrees = 2.0f * std::atan(kTanHalf) * 180.0f / kPi;
  s.camera.lensRadius = lensRadius;
  s.camera.focalDistance = focal;
  s.materials.push_back(test::diffuse(Rgb(0.0f)));
  s.objects.push_back(test::sphere(rho, {0, 0, -d}, 0));
  return s;
}

Film renderPt(const scene::SceneDescription& d, int spp, SamplerKind sampler = SamplerKind::Sobol) {
  RenderOptions o = test::smallRenderOptions(RenderMethod::PathTrace, spp, 2, 11);
  o.sampler = sampler;
  return test::renderOnce(d, o);
}

// Moments of the occlusion 1 - I about the image centre, in pixels.
struct Blob {
  double mass = 0, varX = 0, varY = 0, meanX = 0, meanY = 0;
  int pixelsAboveHalf = 0;  // pixels darker than half the disc's plateau
};
Blob occlusion(const Film& f, double plateau) {
  Blob b;
  double sx = 0, sy = 0, sxx = 0, syy = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      double o = 1.0 - double(f.color[f.index(x, y)].g);
      double px = x + 0.5 - 0.5 * f.width, py = y + 0.5 - 0.5 * f.height;
      b.mass += o;
      sx += o * px;
      sy += o * py;
      sxx += o * px * px;
      syy += o * py * py;
      if (plateau > 0 && o > 0.5 * plateau) ++b.pixelsAboveHalf;
    }
  b.meanX = sx / b.mass;
  b.meanY = sy / b.mass;
  b.varX = sxx / b.mass - b.meanX * b.meanX;
  b.varY = syy / b.mass - b.meanY * b.meanY;
  return b;
}

// Thin-lens circle of confusion of a point at depth d, in pixels.
double predictedCoc(double d, double lensRadius, double focal) {
  double world = 2.0 * lensRadius * std::fabs(d - focal) / d;
  return world / (2.0 * focal * kTanHalf / kRes);
}

// The sphere's own image through the lens centre: a disc of this radius in pixels.
double sphereImageRadius(double d, double rho) { return rho / d * kRes / (2.0 * kTanHalf); }

// Diameter of the blur disc from the measured variance: a uniform disc of
// diameter c has variance c^2/16 per axis; the sphere's own disc (radius s)
// adds s^2/4 and the pixel box 1/12.
double measuredCoc(const Blob& b, double s) {
  double v = 0.5 * (b.varX + b.varY) - s * s / 4.0 - 1.0 / 12.0;
  return 4.0 * std::sqrt(std::max(0.0, v));
}

}  // namespace

TEST_CASE("thin lens: a point off the focal plane is a disc of diameter A |d - f| / d") {
  const float f = 4.0f;
  struct Case { float d, r; SamplerKind sampler; };
  // Predicted diameters: 24, 12 and 12 px.
  for (Case k : {Case{2.0f, 0.75f, SamplerKind::Sobol}, Case{8.0f, 0.75f, SamplerKind::Sobol},
                 Case{2.0f, 0.375f, SamplerKind::Random}}) {
    const float r = k.r;
    CAPTURE(k.d);
    CAPTURE(std::string(samplerName(k.sampler)));
    const float rho = 3.0f * k.d / kRes;  // its image through the lens centre: a disc of radius 3 px
    Film img = renderPt(sphereAtDepth(k.d, rho, r, f), 256, k.sampler);
    double c = predictedCoc(k.d, r, f);
    double s = sphereImageRadius(k.d, rho);
    // The disc's plateau: the sphere's image area spread over the disc.
    double plateau = (kPi * s * s) / (kPi * c * c / 4.0);
    Blob b = occlusion(img, plateau);
    // Mass is the sphere's image area (conserved by the blur).
    CHECK(b.mass == doctest::Approx(kPi * s * s).epsilon(0.05));
    CHECK(std::fabs(b.meanX) < 0.3);
    CHECK(std::fabs(b.meanY) < 0.3);
    CHECK(measuredCoc(b, s) == doctest::Approx(c).epsilon(0.03));
    // And as an area: the pixels darker than half the plateau fill the disc.
    // Measured (seed 11): d 2, r 0.75: 24.23 px, 438 px^2 for 452; d 8: 11.97 px, 105 for 113; random d 2: 12.14 px, 107 for 113.
    CHECK(double(b.pixelsAboveHalf) == doctest::Approx(kPi * c * c / 4.0).epsilon(0.1));
  }
}

TEST_CASE("thin lens: a point on the focal plane is as sharp as through a pinhole") {
  const float rho = 0.1f, d = 4.0f;
  Film pin = renderPt(sphereAtDepth(d, rho, 0.0f, d), 64);
  Film lens = renderPt(sphereAtDepth(d, rho, 0.5f, d), 64);
  Blob a = occlusion(pin, 0), b = occlusion(lens, 0);
  double s = sphereImageRadius(d, rho);  // 1.6 px
  CHECK(a.mass == doctest::Approx(kPi * s * s).epsilon(0.03));
  CHECK(b.mass == doctest::Approx(a.mass).epsilon(0.03));
  CHECK(std::sqrt(0.5 * (b.varX + b.varY)) == doctest::Approx(std::sqrt(0.5 * (a.varX + a.varY))).epsilon(0.05));
  // Out of focus by 25% the same lens spreads it over 2 * 0.5 * 1 / 5 / (5/64) ~ 2.6 px... measurably wider.
  Film off = renderPt(sphereAtDepth(5.0f, rho, 0.5f, d), 64);
  Blob c = occlusion(off, 0);
  CHECK(c.varX > a.varX + 0.2);
}

TEST_CASE("thin lens: a pinhole camera's rays are unchanged by the lens sample") {
  scene::CameraDesc cd;
  cd.width = 32;
  cd.height = 24;
  Camera cam(cd);
  Vec3f o0, d0, o1, d1;
  cam.generateRay({3.5f, 7.25f}, 0.3f, o0, d0);
  cam.generateRay({3.5f, 7.25f}, 0.3f, {0.9f, 0.1f}, o1, d1);
  CHECK(o0.x == o1.x);
  CHECK(o0.z == o1.z);
  CHECK(d0.x == d1.x);
  CHECK(d0.y == d1.y);
  CHECK(d0.z == d1.z);
}

TEST_CASE("thin lens: the lens moves with a moving camera and focuses on its focal plane") {
  scene::CameraDesc cd;
  cd.width = 40;
  cd.height = 30;
  cd.lensRadius = 0.2f;
  cd.focalDistance = 3.0f;
  cd.motion = {{0.0f, {0, 0, 5}, {0, 0, 0}, {0, 1, 0}}, {1.0f, {4, 1, 5}, {4, 1, 0}, {0, 1, 0}}};
  Camera cam(cd);
  for (float t : {0.0f, 0.25f, 0.8f}) {
    Vec3f pos = lerp(Vec3f{0, 0, 5}, Vec3f{4, 1, 5}, t);
    Vec3f po, pd;
    cam.generateRay({11.0f, 20.5f}, t, po, pd);  // pinhole ray: through the lens centre
    Vec3f focus = po + pd * (3.0f / -pd.z);      // its point on the focal plane z = 5 - 3
    for (Vec2f u : {Vec2f{0.1f, 0.9f}, Vec2f{0.5f, 0.5f}, Vec2f{0.99f, 0.02f}}) {
      Vec3f o, d;
      cam.generateRay({11.0f, 20.5f}, t, u, o, d);
      CAPTURE(t);
      CHECK(o.z == doctest::Approx(5.0f));  // on the lens plane (forward is -z)
      CHECK(length(o - pos) <= 0.2f + 1e-5f);
      Vec3f hit = o + d * ((o.z - 2.0f) / -d.z);
      CHECK(length(hit - focus) < 1e-4f);
    }
  }
}

TEST_CASE("thin lens: JSON keys, defaults, located errors, and the writer's round trip") {
  auto parse = [](const std::string& camera) {
    return scene::parseScene("{\"camera\": {" + camera + "}, \"objects\": []}", "lens.json");
  };
  auto d = parse("\"position\": [0, 0, 5], \"target\": [0, 0, 1], \"lens_radius\": 0.1");
  CHECK(d.camera.lensRadius == doctest::Approx(0.1f));
  CHECK(d.camera.focalDistance == doctest::Approx(4.0f));  // default: position to target
  d = parse("\"lens_radius\": 0.1, \"focal_distance\": 2.5");
  CHECK(d.camera.focalDistance == doctest::Approx(2.5f));
  CHECK(parse("").camera.lensRadius == 0.0f);

  auto errorOf = [&](const std::string& camera) {
    try {
      parse(camera);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(errorOf("\n\"lens_radius\": -0.1").find("lens.json:2: camera.lens_radius: lens_radius must be >= 0") == 0);
  CHECK(errorOf("\"focal_distance\": 0").find("camera.focal_distance: focal_distance must be > 0") != std::string::npos);
  CHECK(errorOf("\"focal_distance\": -3").find("camera.focal_distance") != std::string::npos);

  d = parse("\"lens_radius\": 0.125, \"focal_distance\": 2.5");
  pbrt::SceneJson j = pbrt::sceneToJson(d, "out.json");
  auto back = scene::parseScene(j.json, "out.json");
  CHECK(back.camera.lensRadius == 0.125f);
  CHECK(back.camera.focalDistance == 2.5f);
}

TEST_CASE("thin lens: pbrt lensradius / focaldistance / focusdistance, scaled by the camera transform") {
  auto cam = [](const std::string& camera) {
    return pbrt::importPbrtText("Scale 2 2 2\nCamera \"perspective\" " + camera + "\nWorldBegin\n", "lens.pbrt").scene.camera;
  };
  scene::CameraDesc c = cam("\"float lensradius\" 0.1 \"float focaldistance\" 3");
  // Scale 2 is world-to-camera: the camera-to-world transform halves lengths.
  CHECK(c.lensRadius == doctest::Approx(0.05f));
  CHECK(c.focalDistance == doctest::Approx(1.5f));
  c = cam("\"float lensradius\" 0.1 \"float focusdistance\" 3");
  CHECK(c.focalDistance == doctest::Approx(1.5f));
  c = cam("\"float lensradius\" 0.1");
  CHECK(c.focalDistance == doctest::Approx(5e5f));  // pbrt's default 1e6
  CHECK(cam("").lensRadius == 0.0f);
  std::string e;
  try {
    cam("\"float focaldistance\" 3 \"float focusdistance\" 3");
  } catch (const Error& x) {
    e = x.what();
  }
  CHECK(e.find("lens.pbrt:2: Camera \"perspective\": parameter \"float focusdistance\": both") == 0);
}

TEST_CASE("thin lens: tdpm convert writes the lens and the reduced spectra; the JSON renders the same pixels") {
  const char* text = R"(LookAt 0 1 5  0 0 0  0 1 0
Camera "perspective" "float fov" 40 "float lensradius" 0.2 "float focaldistance" 3
Film "rgb" "integer xresolution" 24 "integer yresolution" 16
WorldBegin
LightSource "point" "blackbody I" [3200] "point3 from" [0 3 2]
Material "diffuse" "spectrum reflectance" [360 0.2 500 0.7 830 0.3]
AttributeBegin
Translate 0 -101 0
Shape "sphere" "float radius" 100
AttributeEnd
Material "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.3
Shape "sphere" "float radius" 0.7
)";
  scene::SceneDescription d = pbrt::importPbrtText(text, "lens.pbrt").scene;
  CHECK(d.camera.lensRadius == doctest::Approx(0.2f));
  pbrt::SceneJson j = pbrt::sceneToJson(d, "lens.json");
  scene::SceneDescription back = scene::parseScene(j.json, "lens.json");
  CHECK(back.camera.lensRadius == d.camera.lensRadius);
  CHECK(back.camera.focalDistance == d.camera.focalDistance);
  Film a = renderPt(d, 8), b = renderPt(back, 8);
  double sum = 0;
  bool same = a.color.size() == b.color.size();
  for (size_t i = 0; same && i < a.color.size(); ++i) {
    same = a.color[i].r == b.color[i].r && a.color[i].g == b.color[i].g && a.color[i].b == b.color[i].b;
    sum += a.color[i].g;
  }
  CHECK(same);
  CHECK(sum > 0);
}
