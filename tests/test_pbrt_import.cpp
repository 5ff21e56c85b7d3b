// tests/test_pbrt_import.cpp — import/pbrt_*: pbrt-v3/v4 scenes map onto the
// same SceneDescription (and the same image) as the equivalent JSON scene,
// the handedness is pbrt's (a scene is not mirrored), ActiveTransform motion
// equals JSON keyframes, convert round-trips, and every unsupported or
// malformed input is an error naming file:line.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "error_capture.h"
#include "core/error.h"
#include "import/pbrt_import.h"
#include "import/pbrt_math.h"
#include "import/pbrt_tokenizer.h"
#include "import/ply_reader.h"
#include "cli_harness.h"
#include "scene/json_writer.h"
#include "render/renderer.h"
#include "scene/material.h"
#include "scene/parse.h"
#include "scene/scene.h"
#include "render_fixtures.h"

using namespace tdpm;

namespace {

const std::string kData = std::string(TDPM_SOURCE_DIR) + "/tests/data/pbrt";

scene::SceneDescription importText(const std::string& text, const std::string& file = "dir/t.pbrt") {
  return pbrt::importPbrtText(text, file).scene;
}

std::string errorOf(const std::string& text, const std::string& file = "dir/t.pbrt") {
  return test::errorMessageOf([&] { pbrt::importPbrtText(text, file); });
}

Film renderDesc(const scene::SceneDescription& d, const std::string& method = "pathtrace", int spp = 4) {
  RenderOptions o = test::smallRenderOptions(*parseRenderMethod(method), spp, 4, 7);
  o.causticPhotons = 2000;
  o.globalPhotons = 2000;
  return test::renderOnce(d, o);
}

using test::sameImage;
double sum(const Film& f) { return test::imageSum(f); }

// Writes the description as JSON (and OBJ meshes) into a temp dir and parses it back.
scene::SceneDescription roundTrip(const scene::SceneDescription& d, const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("tdpm_pbrt_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::string path = (dir / (name + ".json")).string();
  pbrt::writeSceneJson(d, path);
  scene::SceneDescription back = scene::loadScene(path);
  std::filesystem::remove_all(dir);
  return back;
}

}  // namespace

TEST_CASE("pbrt tokenizer: strings, numbers, comments and brackets carry their line") {
  auto t = pbrt::tokenize("Shape \"sphere\" # comment\n \"float radius\" [ 2.5 ]\n-1e2 true", "f.pbrt");
  REQUIRE(t.size() == 8);
  CHECK(t[0].kind == pbrt::Token::Kind::Word);
  CHECK(t[1].text == "sphere");
  CHECK(t[2].line == 2);
  CHECK(t[4].number == 2.5);
  CHECK(t[6].number == -100);
  CHECK(t[6].line == 3);
  CHECK(t[7].kind == pbrt::Token::Kind::Word);
  CHECK_THROWS_WITH_AS(pbrt::tokenize("Shape \"sph", "f.pbrt"), "f.pbrt:1: unterminated string", Error);
  CHECK_THROWS_WITH_AS(pbrt::tokenize("\n1e999", "f.pbrt"), "f.pbrt:2: number 1e999 is not finite as a 32-bit float", Error);
  CHECK_THROWS_WITH_AS(pbrt::tokenize("1.2.3", "f.pbrt"), "f.pbrt:1: malformed number '1.2.3'", Error);
}

namespace {

// The description as sorted JSON (materials by name), for comparisons.
nlohmann::json canonicalJson(const scene::SceneDescription& d) {
  return nlohmann::json::parse(pbrt::sceneToJson(d, "/x/s.json").json);
}

const char* kFeatureScene = R"(
Scale -1 1 1
LookAt 0 1 6  0 0.5 0  0 1 0
Camera "perspective" "float fov" 40 "float shutteropen" 0 "float shutterclose" 1
Film "rgb" "integer xresolution" 24 "integer yresolution" 16
Sampler "halton" "integer pixelsamples" 4
Integrator "volpath" "integer maxdepth" 4
WorldBegin
LightSource "infinite" "rgb L" [0.05 0.05 0.1]
LightSource "point" "rgb I" [2 2 2] "point3 from" [1 3 2]
LightSource "spot" "rgb I" [5 5 5] "point3 from" [0 4 0] "point3 to" [0.3 0 0] "float coneangle" 30 "float conedeltaangle" 10
LightSource "distant" "rgb L" [0.3 0.3 0.3] "point3 from" [1 1 1] "point3 to" [0 0 0]
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [0.7 0.2 0.2]
MakeNamedMaterial "gold" "string type" "conductor" "rgb eta" [0.2 0.4 1.4] "rgb k" [3.5 2.4 1.8] "float roughness" 0.1
Texture "grey" "spectrum" "constant" "rgb value" [0.4 0.4 0.4]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [3 3 3]
  Material "diffuse" "rgb reflectance" [0 0 0]
  Translate 0 2.5 0
  Rotate 90 1 0 0
  Shape "bilinearmesh" "point3 P" [-0.5 -0.5 0  0.5 -0.5 0  -0.5 0.5 0  0.5 0.5 0]
AttributeEnd
AttributeBegin
  NamedMaterial "red"
  Translate 0.8 0.5 0
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  NamedMaterial "gold"
  ActiveTransform StartTime
  Translate -1 0.5 -0.5
  ActiveTransform EndTime
  Translate -0.6 0.7 -0.5
  Rotate 60 0 1 1
  ActiveTransform All
  Shape "trianglemesh" "point3 P" [-0.4 -0.4 0  0.4 -0.4 0  0 0.4 0.2] "integer indices" [0 1 2]
AttributeEnd
AttributeBegin
  Material "coateddiffuse" "texture reflectance" "grey" "float roughness" 0.04
  Shape "trianglemesh" "point3 P" [-3 0 -3  3 0 -3  3 0 3  -3 0 3] "integer indices" [0 1 2 0 2 3]
AttributeEnd
AttributeBegin
  Material "dielectric" "float eta" 1.4
  Translate 0 0.3 1.5
  Scale 0.3 0.3 0.3
  Shape "sphere"
AttributeEnd
AttributeBegin
  Material "dielectric" "float eta" 1.3
  Translate -1.5 0 0.5
  Rotate -90 1 0 0
  ReverseOrientation
  Shape "cylinder" "float radius" 0.3 "float zmin" 0 "float zmax" 0.8 "float phimax" 300
  Shape "disk" "float radius" 0.3 "float height" 0.8
AttributeEnd
AttributeBegin
  NamedMaterial "red"
  ActiveTransform EndTime
  Translate 0.2 0 0
  ActiveTransform All
  Translate 1.6 0.01 1
  Scale 1 1 0.5
  Rotate -90 1 0 0
  Shape "disk" "float radius" 0.4 "float innerradius" 0.1
AttributeEnd
Shape "bilinearmesh" "point3 P" [1 0 -1  2 0 -1  1 1 -1  2 1.5 -0.5]
)";

}  // namespace

TEST_CASE("pbrt convert: the written JSON parses back to the same description and renders identically") {
  for (bool mirrored : {false, true}) {
    std::string text = kFeatureScene;
    if (mirrored) text = text.substr(text.find("LookAt"));  // without Scale -1 1 1: the import mirrors the world
    CAPTURE(mirrored);
    scene::SceneDescription d = importText(text);
    scene::SceneDescription back = roundTrip(d, "feature");
    CHECK(canonicalJson(back) == canonicalJson(d));
    REQUIRE(back.objects.size() == d.objects.size());
    for (size_t i = 0; i < d.objects.size(); ++i) {
      CHECK(back.objects[i].shape.vertices.size() == d.objects[i].shape.vertices.size());
      for (size_t v = 0; v < d.objects[i].shape.vertices.size(); ++v) {
        CHECK(back.objects[i].shape.vertices[v].x == d.objects[i].shape.vertices[v].x);
        CHECK(back.objects[i].shape.vertices[v].y == d.objects[i].shape.vertices[v].y);
        CHECK(back.objects[i].shape.vertices[v].z == d.objects[i].shape.vertices[v].z);
      }
      CHECK(back.objects[i].shape.indices == d.objects[i].shape.indices);
    }
    Film a = renderDesc(d), b = renderDesc(back);
    CHECK(sum(a) > 0);
    CHECK(sameImage(a, b));
  }
}

namespace {

const char* kDefaultCameraScene = R"(
Camera "perspective" "float fov" 50
Film "image" "integer xresolution" 24 "integer yresolution" 16
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "point" "rgb I" [3 3 3] "point3 from" [1 2 1]
LightSource "infinite" "rgb L" [0.1 0.1 0.1]
AttributeBegin
  Material "matte" "rgb Kd" [0.7 0.2 0.2]
  Translate 0.8 0.3 4
  Shape "sphere" "float radius" 0.5
AttributeEnd
WorldEnd
)";

std::string num9(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// Brightness-weighted centroid (column, row) of an image.
Vec2f centroid(const Film& f) {
  double sx = 0, sy = 0, w = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      double l = f.color[f.index(x, y)].r;
      sx += l * (x + 0.5);
      sy += l * (y + 0.5);
      w += l;
    }
  return {float(sx / w), float(sy / w)};
}

const char* kSphereAtPlusX = R"(
Film "image" "integer xresolution" 32 "integer yresolution" 32
Sampler "random" "integer pixelsamples" 2
WorldBegin
LightSource "point" "rgb I" [20 20 20] "point3 from" [1 0 5]
AttributeBegin
  Translate 1 0.5 0
  Shape "sphere" "float radius" 0.4
AttributeEnd
)";

}  // namespace

TEST_CASE("pbrt camera and sphere: the same description and image as the equivalent JSON") {
  scene::SceneDescription d = importText(kDefaultCameraScene);
  // pbrt's default camera looks down +z with +x to the right: left-handed,
  // so the import mirrors x; the equivalent JSON is the scene with x negated.
  float power = 3.0f * float(4 * 3.14159265358979323846);
  std::string json = std::string(R"({
    "camera": {"position": [0, 0, 0], "target": [0, 0, 1], "up": [0, 1, 0], "fov": 50, "resolution": [24, 16]},
    "materials": {"m": {"type": "diffuse", "color": [0.7, 0.2, 0.2]}},
    "objects": [{"shape": {"type": "sphere", "radius": 0.5}, "material": "m", "transform": {"translate": [-0.8, 0.3, 4]}}],
    "lights": [{"type": "point", "position": [-1, 2, 1], "power": )") + num9(power) + R"(},
               {"type": "environment", "L": [0.1, 0.1, 0.1], "transform": {"scale": [-1, 1, 1]}}],
    "render": {"method": "pathtrace", "spp": 4, "max_depth": 5}})";
  scene::SceneDescription j = scene::parseScene(json, "equivalent.json");
  CHECK(d.camera.fovDegrees == 50.0f);
  CHECK(d.render.spp == 4);
  CHECK(d.render.maxDepth == 5);
  CHECK(*d.render.method == "pathtrace");
  REQUIRE(d.lights.size() == 2);
  CHECK(d.lights[0].power.r == j.lights[0].power.r);
  CHECK(d.lights[1].type == scene::LightDesc::Type::Environment);
  CHECK(d.lights[1].placement.scale.x == -1.0f);  // the import's mirror
  Film a = renderDesc(d), b = renderDesc(j);
  CHECK(sum(a) > 0);
  CHECK(sameImage(a, b));
}

TEST_CASE("pbrt handedness: a sphere on +x appears where pbrt's camera definition puts it") {
  // pbrt's LookAt: camera +x = normalize(cross(up, dir)) is the image's right
  // (raster x grows with camera x), +y is up. Looking down -z from +z with
  // up +y, cross(up, dir) = -x: world +x is on the image's LEFT. The
  // projection of the sphere's centre (1, 0.5, 0) from (0, 0, 5) with fov 40
  // on a square image: column (1 + x_cam / (z tan 20deg)) * 16 with
  // x_cam = -1, z = 5, and row (1 - 0.5 / (5 tan 20deg)) * 16.
  double t = std::tan(20.0 * 3.14159265358979323846 / 180.0);
  double col = (1 - 1 / (5 * t)) * 16, row = (1 - 0.5 / (5 * t)) * 16;
  std::string camera = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n";
  Vec2f c = centroid(renderDesc(importText(camera + kSphereAtPlusX)));
  CHECK(c.x == doctest::Approx(col).epsilon(0.08));
  CHECK(c.y == doctest::Approx(row).epsilon(0.08));
  CHECK(c.x < 16);  // left half
  // A scene that flips x before LookAt (common in exported scenes) has its
  // camera +x along world +x: the sphere is on the right.
  Vec2f m = centroid(renderDesc(importText("Scale -1 1 1\n" + camera + kSphereAtPlusX)));
  CHECK(m.x == doctest::Approx(32 - col).epsilon(0.08));
  CHECK(m.y == doctest::Approx(row).epsilon(0.08));
  // The default camera (identity: looking down +z, +x right).
  Vec2f d = centroid(renderDesc(importText("Translate 0 0 4\nCamera \"perspective\" \"float fov\" 40\n" + std::string(kSphereAtPlusX))));
  CHECK(d.x > 16);
}

TEST_CASE("pbrt motion: ActiveTransform poses become keyframes equal to the JSON ones") {
  std::string pbrtScene = R"(
Camera "perspective" "float fov" 50
Film "image" "integer xresolution" 24 "integer yresolution" 16
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "point" "rgb I" [3 3 3] "point3 from" [0 2 1]
AttributeBegin
  ActiveTransform StartTime
  Translate -1 0 4
  ActiveTransform EndTime
  Translate 1 0 4
  Rotate 90 0 0 1
  ActiveTransform All
  Shape "trianglemesh" "point3 P" [-0.4 -0.4 0  0.4 -0.4 0  0 0.4 0.2] "integer indices" [0 1 2]
AttributeEnd
)";
  scene::SceneDescription d = importText(pbrtScene, kData + "/motion.pbrt");
  REQUIRE(d.objects.size() == 1);
  const scene::MotionDesc& m = d.objects[0].motion;
  REQUIRE(m.times.size() == 2);
  CHECK(m.times[0] == 0.0f);
  CHECK(m.times[1] == 1.0f);
  // pbrt interpolates T linearly and R by slerp: at t = 0.5 the triangle is
  // Translate(0, 0, 4) Rotate(45 deg about z); the import mirrors x.
  std::vector<MotionKey> keys;
  for (size_t i = 0; i < 2; ++i) keys.push_back({m.times[i], m.poses[i].translate, m.poses[i].rotate, m.poses[i].scale});
  Affine3f mid = Motion::poseAt(MotionKey{}, keys, 0.5f);
  double c = std::cos(3.14159265358979323846 / 4), s = std::sin(3.14159265358979323846 / 4);
  for (Vec3f v : d.objects[0].shape.vertices) {
    Vec3f expect{float(-(c * v.x - s * v.y)), float(s * v.x + c * v.y), v.z + 4};
    Vec3f got = mid.point(v);
    CHECK(got.x == doctest::Approx(expect.x).epsilon(1e-5));
    CHECK(got.y == doctest::Approx(expect.y).epsilon(1e-5));
    CHECK(got.z == doctest::Approx(expect.z).epsilon(1e-5));
  }
  std::string json = R"({
    "camera": {"position": [0, 0, 0], "target": [0, 0, 1], "up": [0, 1, 0], "fov": 50, "resolution": [24, 16]},
    "materials": {"m": {"type": "diffuse", "color": 0.5}},
    "objects": [{"shape": {"type": "mesh", "file": "motion_tri.obj"}, "material": "m",
                 "motion": [{"time": 0, "translate": [1, 0, 4], "scale": [-1, 1, 1]},
                            {"time": 1, "translate": [-1, 0, 4], "rotate": {"axis": [0, 0, 1], "angle": -90},
                             "scale": [-1, 1, 1]}]}],
    "lights": [{"type": "point", "position": [0, 2, 1], "power": )" + num9(3.0f * float(4 * 3.14159265358979323846)) + R"(}],
    "render": {"method": "pathtrace", "spp": 4, "max_depth": 5}})";
  scene::SceneDescription j = scene::parseScene(json, kData + "/motion.json");
  Film a = renderDesc(d), b = renderDesc(j);
  CHECK(sum(a) > 0);
  CHECK(sameImage(a, b));
}

TEST_CASE("pbrt motion: TransformTimes and the shutter clip the keyframes; a static scene has none") {
  std::string head = R"(
TransformTimes 0 1
Camera "perspective" "float shutteropen" 0.25 "float shutterclose" 0.75
WorldBegin
ActiveTransform EndTime
Translate 2 0 0
ActiveTransform All
)";
  scene::SceneDescription d = importText(head + "Shape \"sphere\"\n");
  REQUIRE(d.objects[0].motion.times.size() == 2);
  CHECK(d.objects[0].motion.times[0] == 0.25f);
  CHECK(d.objects[0].motion.times[1] == 0.75f);
  CHECK(d.objects[0].motion.poses[0].translate.x == doctest::Approx(-0.5f));  // mirrored x
  CHECK(d.objects[0].motion.poses[1].translate.x == doctest::Approx(-1.5f));
  CHECK(d.camera.shutterOpen == 0.25f);
  // Motion entirely after the shutter: the start pose holds (pbrt's rule).
  scene::SceneDescription late = importText("TransformTimes 2 3\n" + head.substr(head.find("Camera")) + "Shape \"sphere\"\n");
  CHECK(late.objects[0].motion.empty());
  CHECK(late.objects[0].placement.translate.x == 0.0f);
  // A camera that translates during the shutter: two camera keyframes.
  scene::SceneDescription cam = importText(R"(
ActiveTransform StartTime
Translate 0 0 0
ActiveTransform EndTime
Translate -1 0 0
ActiveTransform All
Camera "perspective"
WorldBegin
Shape "sphere"
)");
  REQUIRE(cam.camera.motion.size() == 2);
  CHECK(cam.camera.motion[1].position.x == doctest::Approx(-1.0f));  // camera at pbrt +1, mirrored
}

TEST_CASE("pbrt lights: intensities, radiances, v4 scale/power and the infinite light map exactly") {
  const double pi = 3.14159265358979323846;
  scene::SceneDescription d = importText(R"(
Scale -1 1 1
Camera "perspective"
WorldBegin
LightSource "point" "rgb I" [1 2 3] "point3 from" [0 1 0] "float scale" 2
LightSource "point" "rgb I" [1 1 1] "float power" 100
LightSource "spot" "rgb I" [4 4 4] "point3 from" [0 3 0] "point3 to" [0 0 0] "float coneangle" 30 "float conedeltaangle" 0
LightSource "distant" "rgb L" [0.5 0.5 0.5] "point3 from" [0 1 0] "point3 to" [0 0 0]
LightSource "infinite" "rgb L" [0.2 0.3 0.4]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Translate 0 2 0
  Rotate 90 1 0 0
  Shape "trianglemesh" "point3 P" [-1 -0.5 0  1 -0.5 0  1 0.5 0  -1 0.5 0] "integer indices" [0 1 2 0 2 3]
AttributeEnd
)");
  REQUIRE(d.lights.size() == 6);
  CHECK(d.lights[0].power.g == doctest::Approx(2 * 2 * 4 * pi));  // I * scale * 4 pi
  CHECK(d.lights[0].position.y == 1.0f);
  CHECK(d.lights[1].power.r == doctest::Approx(100.0));  // v4 power: the total, whatever I is
  const auto& spot = d.lights[2];
  CHECK(spot.direction.y == doctest::Approx(-1.0f));
  CHECK(spot.falloffStart == 30.0f);
  CHECK(spot.power.r == doctest::Approx(4 * 2 * pi * (1 - std::cos(pi / 6))));  // hard-edged cone
  CHECK(d.lights[3].type == scene::LightDesc::Type::Directional);
  CHECK(d.lights[3].direction.y == doctest::Approx(-1.0f));  // travels from "from" to "to"
  CHECK(d.lights[3].power.r == 0.5f);
  CHECK(d.lights[4].type == scene::LightDesc::Type::Environment);  // pbrt's infinite light
  CHECK(d.lights[4].radiance.b == 0.4f);
  CHECK(d.lights[4].mapFile.empty());
  const auto& area = d.lights[5];
  CHECK(area.type == scene::LightDesc::Type::Area);
  CHECK(area.areaSize.x == doctest::Approx(2.0f));
  CHECK(area.areaSize.y == doctest::Approx(1.0f));
  CHECK(area.power.r == doctest::Approx(2 * pi * 2));  // L pi A
  // Rotate 90 about x turns the quad's +z normal to -y: it emits downward,
  // i.e. tdpm's local -y must stay world -y.
  Affine3f pl = area.placement.matrix();
  Vec3f emit = pl.vector({0, -1, 0});
  CHECK(emit.y == doctest::Approx(-1.0f));
}

TEST_CASE("pbrt area lights emit on the side of pbrt's surface normal") {
  auto floorLight = [&](const std::string& rotate) {
    return sum(renderDesc(importText(R"(
LookAt 0 0.3 6  0 0 0  0 1 0
Camera "perspective" "float fov" 8
Film "image" "integer xresolution" 16 "integer yresolution" 16
Sampler "random" "integer pixelsamples" 2
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [5 5 5]
  Translate 0 1 0
  )" + rotate + R"(
  Shape "bilinearmesh" "point3 P" [-0.5 -0.5 0  0.5 -0.5 0  -0.5 0.5 0  0.5 0.5 0]
AttributeEnd
Shape "trianglemesh" "point3 P" [-3 0 -3  3 0 -3  3 0 3  -3 0 3] "integer indices" [0 1 2 0 2 3]
)")));
  };
  // The camera sees only the floor (the light is above the field of view).
  double down = floorLight("Rotate 90 1 0 0"), up = floorLight("Rotate -90 1 0 0");
  CHECK(down > 20 * up);
}

TEST_CASE("pbrt materials map onto tdpm's, approximations as documented") {
  using T = scene::MaterialDesc::Type;
  auto material = [&](const std::string& m) {
    scene::SceneDescription d = importText("WorldBegin\n" + m + "\nShape \"sphere\"\n");
    REQUIRE(d.objects.size() == 1);
    return d.materials[d.objects[0].material];
  };
  CHECK(material("").albedo.color.r == 0.5f);  // pbrt's default material
  CHECK(material("Material \"matte\" \"color Kd\" [0.1 0.2 0.3]").albedo.color.b == 0.3f);
  CHECK(material("Material \"diffuse\" \"float reflectance\" 0.25").albedo.color.g == 0.25f);
  auto mirror = material("Material \"mirror\"");
  CHECK(mirror.type == T::Mirror);
  CHECK(mirror.specular.r == 0.9f);
  auto glass = material("Material \"glass\" \"float eta\" 1.33 \"rgb Kr\" [0.9 0.9 0.9] \"rgb Kt\" [0.9 0.9 0.9]");
  CHECK(glass.type == T::Dielectric);
  CHECK(glass.ior == 1.33f);
  CHECK(glass.specular.r == 0.9f);
  // Conductor: its complex IOR as given (scene/bsdf_pbrt.cpp's Fresnel).
  auto metal = material("Material \"conductor\" \"rgb eta\" [0.2 0.2 0.2] \"rgb k\" [3 3 3] \"float roughness\" 0.09");
  CHECK(metal.type == T::Conductor);
  CHECK(metal.eta.r == 0.2f);
  CHECK(metal.k.g == 3.0f);
  CHECK(metal.roughness == doctest::Approx(0.3));  // v4: alpha = sqrt(roughness)
  auto v3metal = material("Material \"metal\" \"rgb eta\" [0.2 0.2 0.2] \"rgb k\" [3 3 3] \"float roughness\" 0.3 \"bool remaproughness\" \"false\"");
  CHECK(v3metal.roughness == doctest::Approx(0.3));
  auto smooth = material("Material \"conductor\" \"rgb reflectance\" [0.8 0.8 0.8]");
  CHECK(smooth.type == T::Conductor);
  CHECK(smooth.roughness == 0.0f);  // smooth: delta (scene/build.cpp)
  CHECK(smooth.k.r == doctest::Approx(2 * std::sqrt(0.8) / std::sqrt(0.2)));  // eta = 1: normal Fresnel 0.8
  auto plastic = material("Material \"plastic\" \"rgb Kd\" [0.3 0.3 0.3] \"float roughness\" 0.01 \"bool remaproughness\" false");
  CHECK(plastic.type == T::Uber);  // pbrt-v3's plastic is Lambert + GGX with dielectric Fresnel, as uber
  CHECK(plastic.specular.g == 0.25f);
  CHECK(plastic.roughness == doctest::Approx(0.01));
  auto coated = material("Material \"coateddiffuse\" \"rgb reflectance\" [0.3 0.6 0.3] \"float eta\" 1.6");
  CHECK(coated.type == T::CoatedDiffuse);
  CHECK(coated.ior == 1.6f);
  auto rough = material("Material \"dielectric\" \"float roughness\" 0.04");
  CHECK(rough.type == T::RoughDielectric);
  CHECK(rough.roughness == doctest::Approx(0.2));
  auto uber = material("Material \"uber\" \"rgb Kd\" [0.64 0.64 0.64] \"rgb Ks\" [0.1 0.1 0.1] \"float index\" 1 \"float roughness\" 0.0104");
  CHECK(uber.type == T::Uber);
  CHECK(uber.ior == 1.0f);
  CHECK(uber.specular.r == 0.1f);
  auto uberGlass = material("Material \"uber\" \"rgb Kd\" [0 0 0] \"rgb Ks\" [0 0 0] \"rgb Kr\" [1 1 1] \"rgb Kt\" [1 1 1] \"float eta\" 1.4");
  CHECK(uberGlass.type == T::Dielectric);
  CHECK(uberGlass.ior == 1.4f);
  CHECK(material("Material \"substrate\"").type == T::Substrate);
  auto cc = material("Material \"coatedconductor\" \"float conductor.roughness\" 0.04 \"float interface.roughness\" 0");
  CHECK(cc.type == T::CoatedConductor);
  CHECK(cc.baseRoughness == doctest::Approx(0.2));
  auto mix = importText("WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n"
                        "MakeNamedMaterial \"b\" \"string type\" \"conductor\"\n"
                        "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0.3\nShape \"sphere\"\n");
  REQUIRE(mix.objects.size() == 1);
  const auto& mm = mix.materials[mix.objects[0].material];
  CHECK(mm.type == T::Mix);
  CHECK(mm.amount == 0.3f);
  CHECK(mix.materials[mm.mix[0]].type == T::Diffuse);
  CHECK(mix.materials[mm.mix[1]].type == T::Conductor);
  CHECK(coated.albedo.color.g == 0.6f);
  CHECK(material("Texture \"t\" \"float\" \"constant\" \"float value\" 0.7\nMaterial \"diffuse\" \"texture reflectance\" \"t\"")
            .albedo.color.r == 0.7f);
  // "" and interface have no surface: the shape is not in the scene.
  CHECK(importText("WorldBegin\nMaterial \"interface\"\nShape \"sphere\"\n").objects.empty());
  CHECK(importText("WorldBegin\nMakeNamedMaterial \"air\" \"string type\" \"\"\nNamedMaterial \"air\"\nShape \"sphere\"\n")
            .objects.empty());
}

TEST_CASE("pbrt statements: Include/Import relative to the including file, instancing, named coordinate systems, attributes") {
  scene::SceneDescription inc = pbrt::importPbrtFile(kData + "/include_main.pbrt").scene;
  CHECK(inc.lights.size() == 2);  // one from parts/lights.pbrt, one from parts/more_lights.pbrt it imports
  CHECK(inc.objects.size() == 1);
  scene::SceneDescription d = importText(R"(
Scale -1 1 1
Camera "perspective"
Film "image" "integer xresolution" 8 "integer yresolution" 4 "string filename" "out/picture.png"
Sampler "stratified" "integer xsamples" 3 "integer ysamples" 2
Integrator "sppm" "integer numiterations" 10 "integer photonsperiteration" 1000 "float radius" 0.25 "integer maxdepth" 7
WorldBegin
ObjectBegin "pair"
  Translate 1 0 0
  Shape "sphere" "float radius" 0.25
  Translate -2 0 0
  Shape "sphere" "float radius" 0.25
ObjectEnd
AttributeBegin
  Translate 0 0 5
  CoordinateSystem "five"
  ObjectInstance "pair"
AttributeEnd
TransformBegin
  CoordSysTransform "five"
  Translate 0 1 0
  ObjectInstance "pair"
TransformEnd
ObjectInstance "pair"
)");
  REQUIRE(d.objects.size() == 6);
  CHECK(d.objects[0].placement.translate.x == 1.0f);
  CHECK(d.objects[0].placement.translate.z == 5.0f);
  CHECK(d.objects[1].placement.translate.x == -1.0f);
  CHECK(d.objects[2].placement.translate.y == 1.0f);
  CHECK(d.objects[2].placement.translate.z == 5.0f);
  CHECK(d.objects[4].placement.translate.z == 0.0f);  // the attribute block restored the CTM
  CHECK(d.render.spp == 6);
  CHECK(*d.render.method == "time");
  CHECK(*d.render.photons == 10000);
  CHECK(*d.render.maxRadius == 0.25f);
  CHECK(*d.render.maxDepth == 7);
  CHECK(d.camera.width == 8);
  CHECK(d.camera.fovDegrees == 90.0f);  // pbrt's default; landscape: the vertical one
  CHECK(*pbrt::importPbrtText("Film \"image\" \"string filename\" \"a.png\"\nWorldBegin\n", "x.pbrt").filmFilename == "a.png");
  // Portrait: pbrt's fov spans the shorter (horizontal) axis.
  scene::SceneDescription portrait =
      importText("Camera \"perspective\" \"float fov\" 60\nFilm \"image\" \"integer xresolution\" 10 \"integer yresolution\" 20\nWorldBegin\n");
  CHECK(portrait.camera.fovDegrees == doctest::Approx(2 * std::atan(std::tan(3.14159265358979323846 / 6) * 2) * 180 / 3.14159265358979323846));
}

TEST_CASE("pbrt v3 and v4 spellings of one scene render identically") {
  std::string v3 = R"(
LookAt 0 1 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "image" "integer xresolution" [ 20 ] "integer yresolution" [ 12 ]
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "point" "color I" [ 4 4 4 ] "point from" [ 0 3 2 ]
Material "matte" "color Kd" [ 0.6 0.5 0.4 ]
Shape "trianglemesh" "point P" [ -2 -1 -2  2 -1 -2  2 -1 2  -2 -1 2 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "sphere" "float radius" 0.7
WorldEnd
)";
  std::string v4 = R"(
LookAt 0 1 5  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 20 "integer yresolution" 12
Sampler "zsobol" "integer pixelsamples" 4
WorldBegin
LightSource "point" "rgb I" [ 4 4 4 ] "point3 from" [ 0 3 2 ]
Material "diffuse" "rgb reflectance" [ 0.6 0.5 0.4 ]
Shape "bilinearmesh" "point3 P" [ -2 -1 -2  2 -1 -2  -2 -1 2  2 -1 2 ]
Shape "sphere" "float radius" 0.7
)";
  Film a = renderDesc(importText(v3)), b = renderDesc(importText(v4));
  CHECK(sum(a) > 0);
  // The bilinear patch is the same square as two triangles but split along
  // the other diagonal order: compare statistically, not bit for bit.
  CHECK(std::fabs(sum(a) - sum(b)) < 1e-3 * sum(a));
  // v4's film scales by exposure time x ISO / 100.
  scene::SceneDescription half = importText("Camera \"perspective\" \"float shutterclose\" 0.5\nFilm \"rgb\" \"float iso\" 200\nWorldBegin\n"
                                            "LightSource \"point\" \"rgb I\" [1 1 1]\n");
  CHECK(half.lights[0].power.r == doctest::Approx(4 * 3.14159265358979323846));
}

TEST_CASE("pbrt errors name file:line and the statement or parameter") {
  struct Case {
    std::string text, expected;
  };
  const Case cases[] = {
      {"WorldBegin\nShape \"hyperboloid\"\n", "dir/t.pbrt:2: Shape \"hyperboloid\" is not supported (sphere, disk, cylinder,"},
      {"WorldBegin\n\nShape \"sphere\" \"float zmax\" 0.5\n", "dir/t.pbrt:3: Shape \"sphere\": partial spheres"},
      {"WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float bogus\" 2\n",
       "dir/t.pbrt:2: Shape \"sphere\": parameter \"float bogus\": not supported"},
      {"WorldBegin\nShape \"sphere\" \"integer radius\" 1\n", "dir/t.pbrt:2: Shape \"sphere\": parameter \"integer radius\": expected type float"},
      {"Camera \"perspective\" \"float lensradius\" -0.1\nWorldBegin\n", "dir/t.pbrt:1: Camera \"perspective\": parameter \"float lensradius\": lensradius must be in [0, "},
      {"Camera \"perspective\" \"float focaldistance\" 0\nWorldBegin\n", "dir/t.pbrt:1: Camera \"perspective\": parameter \"float focaldistance\": focaldistance must be in (0, "},
      {"Camera \"orthographic\"\nWorldBegin\n", "dir/t.pbrt:1: Camera \"orthographic\" is not supported"},
      {"WorldBegin\nMaterial \"measured\" \"string filename\" \"x.bsdf\"\n", "dir/t.pbrt:2: measured: measured BSDFs"},
      {"WorldBegin\nMaterial \"hair\"\n", "dir/t.pbrt:2: material type \"hair\" is not supported"},
      {"WorldBegin\nMaterial \"uber\" \"rgb Kr\" [1 1 1]\n", "dir/t.pbrt:2: uber: uber with specular lobes (Kr, Kt) beside Kd or Ks"},
      {"WorldBegin\nMaterial \"mix\" \"string materials\" [\"p\" \"q\"]\n", "dir/t.pbrt:2: Material \"mix\": parameter \"string materials\": no material named \"p\""},
      {"Integrator \"whitted\"\nWorldBegin\n", "dir/t.pbrt:1: Integrator \"whitted\" is not supported"},
      {"WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-CuZn-eta\"\n", "dir/t.pbrt:2: Material \"conductor\": parameter \"spectrum eta\": named spectrum \"metal-CuZn-eta\" is not available"},
      {"WorldBegin\nMaterial \"matte\" \"spectrum Kd\" [700 0.5 400 0.5]\n", "dir/t.pbrt:2: Material \"matte\": parameter \"spectrum Kd\": wavelengths must increase"},
      {"WorldBegin\nMaterial \"glass\" \"rgb Kr\" [1 1 1] \"rgb Kt\" [0.5 0.5 0.5]\n", "dir/t.pbrt:2: glass: Kr and Kt differ"},
      {"WorldBegin\nLightSource \"goniometric\"\n", "dir/t.pbrt:2: LightSource \"goniometric\" is not supported"},
      {"WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\"\n", "dir/t.pbrt:2: LightSource \"infinite\": dir/sky.exr: "},
      {"WorldBegin\nLightSource \"infinite\" \"float power\" 3\n", "dir/t.pbrt:2: LightSource \"infinite\": \"power\" is not supported"},
      {"WorldBegin\nAreaLightSource \"diffuse\" \"string filename\" \"e.png\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"integer indices\" [0 1 2 0 2 3]\n",
       "dir/t.pbrt:2: AreaLightSource: an image emitter (filename) is not supported"},
      {"WorldBegin\nAreaLightSource \"diffuse\"\nShape \"sphere\" \"float zmax\" 0.5\n", "dir/t.pbrt:3: Shape \"sphere\": partial spheres"},
      {"WorldBegin\nAreaLightSource \"diffuse\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 2 0 0]\n",
       "dir/t.pbrt:3: AreaLightSource (dir/t.pbrt:2) on Shape \"trianglemesh\": the emitter has zero area"},
      {"WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]\n",
       "dir/t.pbrt:2: Shape \"trianglemesh\": parameter \"integer indices\": index 3 is out of range"},
      {"WorldBegin\nShape \"disk\" \"float radius\" -1\n", "dir/t.pbrt:2: Shape \"disk\": radius must be positive, got -1"},
      {"WorldBegin\nShape \"disk\" \"float innerradius\" 2\n", "dir/t.pbrt:2: Shape \"disk\": innerradius 2 must be below radius 1"},
      {"WorldBegin\nShape \"cylinder\" \"float zmin\" 1 \"float zmax\" 0\n", "dir/t.pbrt:2: Shape \"cylinder\": zmin 1 must be below zmax 0"},
      {"WorldBegin\nShape \"cylinder\" \"float radius\" 0\n", "dir/t.pbrt:2: Shape \"cylinder\": radius must be positive, got 0"},
      {"WorldBegin\nShape \"cylinder\" \"float phimax\" -5\n", "dir/t.pbrt:2: Shape \"cylinder\": phimax must be positive"},
      {"WorldBegin\nAreaLightSource \"diffuse\"\nShape \"cylinder\"\n", "dir/t.pbrt:3: Shape \"cylinder\" with an AreaLightSource is not supported"},
      {"ReverseOrientation\nWorldBegin\n", "dir/t.pbrt:1: ReverseOrientation is only allowed after WorldBegin"},
      {"WorldBegin\nScale 2 1 1\nShape \"sphere\"\n", "dir/t.pbrt:3: Shape \"sphere\" under a non-uniform scale"},
      {"WorldBegin\nAreaLightSource \"diffuse\"\nShape \"disk\" \"float innerradius\" 0.5\n", "dir/t.pbrt:3: Shape \"disk\": an annulus"},
      {"WorldBegin\nMakeNamedMedium \"fog\"\n", "dir/t.pbrt:2: MakeNamedMedium \"fog\": missing parameter \"string type\""},
      {"WorldBegin\nAttributeBegin\n", "dir/t.pbrt:2: AttributeBegin without a matching End"},
      {"WorldBegin\nAttributeEnd\n", "dir/t.pbrt:2: AttributeEnd without a matching AttributeBegin"},
      {"WorldBegin\nNamedMaterial \"x\"\n", "dir/t.pbrt:2: NamedMaterial: no material named \"x\""},
      {"WorldBegin\nObjectInstance \"x\"\n", "dir/t.pbrt:2: ObjectInstance: no object named \"x\""},
      {"WorldBegin\nTranslate 1 2\n", "dir/t.pbrt:2: Translate: expected a number before the end of the file"},
      {"WorldBegin\nShape \"sphere\" \"float radius\" [ 1\n", "dir/t.pbrt:2: Shape \"sphere\": parameter \"float radius\": missing ']'"},
      {"Shape \"sphere\"\n", "dir/t.pbrt:1: Shape is only allowed after WorldBegin"},
      {"WorldBegin\nCamera \"perspective\"\n", "dir/t.pbrt:2: Camera is only allowed before WorldBegin"},
      {"Camera \"perspective\"\n", "dir/t.pbrt: no WorldBegin"},
      {"WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3\n", "dir/t.pbrt:2: Texture \"c\": a 3D checkerboard"},
      {"WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" \"c\"\nTexture \"c\" \"spectrum\" \"checkerboard\"\n",
       "dir/t.pbrt:2: Material \"diffuse\": parameter \"texture reflectance\": no texture named \"c\" has been defined"},
      {"WorldBegin\nTexture \"f\" \"float\" \"checkerboard\"\nMaterial \"diffuse\" \"texture reflectance\" \"f\"\n",
       "dir/t.pbrt:3: Material \"diffuse\": parameter \"texture reflectance\": texture \"f\" is a float texture, but a reflectance needs a spectrum one"},
      {"WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\"\nMaterial \"uber\" \"texture Kr\" \"c\"\n",
       "dir/t.pbrt:3: Material \"uber\": parameter \"texture Kr\": a spectrum texture that varies is supported only on"},
      {"LookAt 0 0 0  0 0 0  0 1 0\n", "dir/t.pbrt:1: LookAt: eye and look-at point coincide"},
      {"Camera \"perspective\" \"float fov\" 180\nWorldBegin\n", "dir/t.pbrt:1: Camera: fov must be in (0, 180)"},
      {"Film \"image\" \"float cropwindow\" [0 0.5 0 1]\nWorldBegin\n", "dir/t.pbrt:1: Film \"image\": parameter \"float cropwindow\": a crop window"},
      {"ActiveTransform EndTime\nRotate 30 0 1 0\nActiveTransform All\nCamera \"perspective\"\nWorldBegin\n",
       "dir/t.pbrt:4: Camera: a camera that rotates during the shutter"},
      {"WorldBegin\nActiveTransform EndTime\nScale 1 2 1\nRotate 30 0 0 1\nActiveTransform All\nShape \"sphere\"\n",
       "dir/t.pbrt:6: Shape \"sphere\": its EndTime transform has shear"},
      {"WorldBegin\nShape \"sphere\" \"float radius\" 1e999\n", "dir/t.pbrt:2: number 1e999 is not finite"},
      {"WorldBegin\n{\n", "dir/t.pbrt:2: unexpected character '{'"},
      // found by fuzz_pbrt: a string where a number belongs
      {"WorldBegin\nLightSource \"spot\" \"float conedeltaangle\" \"x\"\n",
       "dir/t.pbrt:2: LightSource \"spot\": parameter \"float conedeltaangle\": expected numbers, got \"x\""},
      {"WorldBegin\nShape \"plymesh\" \"string filename\" 3\n", "expected a quoted string, got a number"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.text);
    std::string e = errorOf(c.text);
    CHECK_MESSAGE(e.find(c.expected) != std::string::npos, e);
  }
  std::string cycle = kData + "/include_cycle.pbrt";
  try {
    pbrt::importPbrtFile(cycle);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("nested more than 32 deep") != std::string::npos);
    CHECK(std::string(e.what()).find("cycle_a.pbrt:2: Include") != std::string::npos);
  }
  try {
    pbrt::importPbrtFile(kData + "/include_missing.pbrt");
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("include_missing.pbrt:3: Include: ") != std::string::npos);
    CHECK(std::string(e.what()).find("parts/nope.pbrt: cannot read scene file") != std::string::npos);
  }
}

TEST_CASE("pbrt PixelFilter: box and Gaussian map onto render.filter, each version's names and defaults") {
  struct Case {
    std::string text;
    std::optional<std::string> filter;
    std::optional<float> radius;
    size_t notes;
  };
  const std::string world = "WorldBegin\n";
  const std::vector<Case> cases = {
      // No PixelFilter: tdpm's default, unless the film is pbrt-v4's (its default Gaussian 1.5).
      {world, std::nullopt, std::nullopt, 0},
      {"Film \"image\"\n" + world, std::nullopt, std::nullopt, 0},
      {"Film \"rgb\"\n" + world, "gaussian", 1.5f, 0},
      // Box: v3 xwidth, v4 xradius, default 0.5.
      {"PixelFilter \"box\"\n" + world, "box", 0.5f, 0},
      {"PixelFilter \"box\" \"float xwidth\" 1 \"float ywidth\" 1\n" + world, "box", 1.0f, 0},
      {"PixelFilter \"box\" \"float xradius\" 0.75 \"float yradius\" 0.75\n" + world, "box", 0.75f, 0},
      // Gaussian: v3 (width 2, alpha 2 = sigma 0.5) and v4 (radius 1.5, sigma 0.5).
      {"PixelFilter \"gaussian\"\n" + world, "gaussian", 1.5f, 0},
      {"Film \"image\"\nPixelFilter \"gaussian\"\n" + world, "gaussian", 2.0f, 0},
      {"PixelFilter \"gaussian\" \"float alpha\" 2\n" + world, "gaussian", 2.0f, 0},
      {"PixelFilter \"gaussian\" \"float xradius\" 1 \"float yradius\" 1 \"float sigma\" 0.5\n" + world, "gaussian", 1.0f, 0},
      // Approximations, each a note: another sigma; unequal radii (the larger).
      {"PixelFilter \"gaussian\" \"float sigma\" 0.8\n" + world, "gaussian", 1.5f, 1},
      {"PixelFilter \"box\" \"float xradius\" 0.5 \"float yradius\" 1\n" + world, "box", 1.0f, 1},
      // Unsupported kinds: tdpm's box, with a note.
      {"PixelFilter \"triangle\" \"float xradius\" 2\n" + world, std::nullopt, std::nullopt, 1},
  };
  for (const Case& c : cases) {
    INFO(c.text);
    pbrt::ImportResult r = pbrt::importPbrtText(c.text, "f.pbrt");
    CHECK(r.scene.render.filter == c.filter);
    CHECK(r.scene.render.filterRadius == c.radius);
    CHECK(r.notes.size() == c.notes);
  }
  // Errors name the place: a radius outside tdpm's range, both spellings at once.
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"PixelFilter \"box\" \"float xradius\" 40\nWorldBegin\n", "f.pbrt:1: PixelFilter \"box\": radius 40 is outside"},
           {"PixelFilter \"gaussian\" \"float xwidth\" 2 \"float xradius\" 2\nWorldBegin\n", "f.pbrt:1"},
           {"PixelFilter \"gaussian\" \"float bogus\" 2\nWorldBegin\n", "bogus"}}) {
    INFO(text);
    std::string message;
    try {
      pbrt::importPbrtText(text, "f.pbrt");
    } catch (const Error& e) {
      message = e.what();
    }
    CHECK(message.find(expected) != std::string::npos);
  }
  // The filter survives `tdpm convert`'s JSON (render.filter, filter_radius).
  scene::SceneDescription d = pbrt::importPbrtText("PixelFilter \"gaussian\" \"float xradius\" 1.25 \"float yradius\" 1.25\nWorldBegin\n", "f.pbrt").scene;
  nlohmann::json j = nlohmann::json::parse(pbrt::sceneToJson(d, "/tmp/f.json").json);
  CHECK(j["render"]["filter"] == "gaussian");
  CHECK(j["render"]["filter_radius"].get<double>() == 1.25);
}

TEST_CASE("pbrt import notes: quality-only statements and ignored mesh attributes are one line each") {
  pbrt::ImportResult r = pbrt::importPbrtText(R"(
PixelFilter "mitchell" "float B" 0.3
Accelerator "bvh"
ColorSpace "srgb"
WorldBegin
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "normal N" [0 0 1 0 0 1 0 0 1] "point2 uv" [0 0 1 0 0 1]
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "normal N" [0 0 1 0 0 1 0 0 1]
)", "n.pbrt");
  int filters = 0, normals = 0;
  for (const auto& n : r.notes) {
    filters += n.find("n.pbrt:2: PixelFilter") == 0;
    normals += n.find("\"N\" ignored") != std::string::npos;
  }
  CHECK(filters == 1);
  CHECK(normals == 0);  // N is used now (tests/test_vertex_normals.cpp): no note
  CHECK(r.notes.size() == 3);
  for (const auto& o : r.scene.objects) CHECK(o.shape.normals.size() == 3);
}

namespace {

// A PLY file in one of the binary encodings: the test's square + triangle.
std::string binaryPly(bool little, const std::string& extraHeader = "", int64_t faceCount = 2) {
  std::string h = std::string("ply\nformat ") + (little ? "binary_little_endian" : "binary_big_endian") +
                  " 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n" + extraHeader +
                  "element face " + std::to_string(faceCount) + "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) {
    std::string b(static_cast<const char*>(p), n);
    uint16_t one = 1;
    bool hostLittle = *reinterpret_cast<const unsigned char*>(&one) == 1;
    if (hostLittle != little) std::reverse(b.begin(), b.end());
    h += b;
  };
  const float v[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 2, 0}};
  for (const auto& p : v)
    for (float c : p) put(&c, 4);
  const std::vector<std::vector<int32_t>> faces = {{0, 1, 2, 3}, {3, 2, 4}};
  for (const auto& f : faces) {
    unsigned char n = static_cast<unsigned char>(f.size());
    h += char(n);
    for (int32_t i : f) put(&i, 4);
  }
  return h;
}

}  // namespace

TEST_CASE("pbrt plymesh: ASCII and binary (both endians) read to the same triangles") {
  scene::SceneDescription d = pbrt::importPbrtFile(kData + "/plymesh.pbrt").scene;
  REQUIRE(d.objects.size() == 1);
  const auto& s = d.objects[0].shape;
  REQUIRE(s.vertices.size() == 5);
  CHECK(s.indices.size() == 9);  // the quad as two triangles, then the triangle
  CHECK(s.vertices[4].y == 2.0f);
  CHECK(s.vertices[1].x == -1.0f);  // mirrored world
  for (bool little : {true, false}) {
    CAPTURE(little);
    pbrt::PlyMesh m = pbrt::parsePly(binaryPly(little), "b.ply");
    REQUIRE(m.vertices.size() == 5);
    CHECK(m.vertices[4].x == 0.5f);
    CHECK(m.vertices[4].y == 2.0f);
    CHECK(m.quads == std::vector<uint32_t>{0, 1, 2, 3});
    CHECK(m.triangles == std::vector<uint32_t>{3, 2, 4});
  }
}

TEST_CASE("pbrt plymesh: hostile files are refused with a reason, never a crash or a huge allocation") {
  auto err = [](const std::string& bytes) {
    try {
      pbrt::parsePly(bytes, "h.ply");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  std::string good = binaryPly(true);
  CHECK(err(good) == "(no error)");
  CHECK(err("plx\n") .find("h.ply: not a PLY file") == 0);
  CHECK(err(good.substr(0, good.size() - 3)).find("truncated") != std::string::npos);
  CHECK(err(binaryPly(true, "", 4000000000LL)).find("more than the file can hold") != std::string::npos);
  std::string badIndex = good;
  badIndex[badIndex.size() - 4] = 9;  // last triangle index -> 9 (little endian low byte)
  CHECK(err(badIndex).find("uses vertex 9") != std::string::npos);
  std::string nan = good;
  size_t body = nan.find("end_header\n") + 11;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan[body], &q, 4);
  CHECK(err(nan).find("vertex 0 is not finite") != std::string::npos);
  CHECK(err("ply\nformat ascii 2.0\nend_header\n").find("unsupported PLY version") != std::string::npos);
  CHECK(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 x\n")
            .find("'x' is not a number") != std::string::npos);
  CHECK(err("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nend_header\n1 2\n").find("is a list") != std::string::npos);
  CHECK(err("ply\nformat ascii 1.0\nbogus\nend_header\n").find("unknown header line 'bogus'") != std::string::npos);
  std::string pentagon = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 2 0\n5 0 1 2 3 4\n";
  CHECK(err(pentagon).find("has 5 corners") != std::string::npos);
  // A missing PLY file: the Shape statement's line and the file name.
  std::string e = errorOf("WorldBegin\n\nShape \"plymesh\" \"string filename\" \"nope.ply\"\n", kData + "/x.pbrt");
  CHECK(e.find("x.pbrt:3: Shape \"plymesh\": ") != std::string::npos);
  CHECK(e.find("nope.ply: cannot read PLY file") != std::string::npos);
}

TEST_CASE("cli: render chooses the pbrt import by extension and names the output after the Film") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/scene.pbrt", "LookAt 0 0 5  0 0 0  0 1 0\n" + std::string(kSphereAtPlusX));
  // Film "filename" without -o: the film's name, as .exr, in the working directory.
  test::writeFile(dir + "/named.pbrt", "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"pic.png\"\n"
                                       "Sampler \"random\" \"integer pixelsamples\" 1\nWorldBegin\nShape \"sphere\"\n");
  auto r = test::runTdpm("render '" + dir + "/scene.pbrt' -o '" + dir + "/a.exr' --threads 2 -q");
  INFO(r.output);
  CHECK(r.exitCode == 0);
  CHECK(test::fileExists(dir + "/a.exr"));
  auto n = test::runTdpm("render '" + dir + "/named.pbrt' --threads 2 -q && mv pic.exr pic.png '" + dir + "/'");
  INFO(n.output);
  CHECK(n.exitCode == 0);
  CHECK(test::fileExists(dir + "/pic.exr"));
  // A located error, exit 1, nothing written.
  test::writeFile(dir + "/bad.pbrt", "WorldBegin\n\nShape \"hyperboloid\"\n");
  auto b = test::runTdpm("render '" + dir + "/bad.pbrt' -o '" + dir + "/bad.exr' -q");
  CHECK(b.exitCode == 1);
  CHECK(b.output.find("bad.pbrt:3: Shape \"hyperboloid\" is not supported") != std::string::npos);
  CHECK(!test::fileExists(dir + "/bad.exr"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("cli: convert writes JSON (+ OBJ) that renders to the same image as the pbrt file") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/f.pbrt", kFeatureScene);
  auto h = test::runTdpm("convert --help");
  CHECK(h.exitCode == 0);
  CHECK(h.output.find("--output") != std::string::npos);
  auto c = test::runTdpm("convert '" + dir + "/f.pbrt' -o '" + dir + "/f.json' -q");
  INFO(c.output);
  REQUIRE(c.exitCode == 0);
  CHECK(test::fileExists(dir + "/f.mesh0.obj"));
  std::string common = " --threads 2 -q --seed 3 --spp 2";
  REQUIRE(test::runTdpm("render '" + dir + "/f.pbrt' -o '" + dir + "/p.exr'" + common).exitCode == 0);
  REQUIRE(test::runTdpm("render '" + dir + "/f.json' -o '" + dir + "/j.exr'" + common).exitCode == 0);
  auto cmp = test::runTdpm("compare '" + dir + "/p.exr' '" + dir + "/j.exr' --json");
  INFO(cmp.output);
  auto metrics = nlohmann::json::parse(cmp.output);
  CHECK(metrics["max_abs_error"]["overall"] == 0.0);
  CHECK(metrics["mean_test"]["overall"].get<double>() > 0);
  // Errors: not pbrt, output not .json, a bad scene (nothing written).
  CHECK(test::runTdpm("convert '" + dir + "/f.json' -o '" + dir + "/x.json'").exitCode == 1);
  CHECK(test::runTdpm("convert '" + dir + "/f.pbrt' -o '" + dir + "/x.txt'").exitCode == 1);
  CHECK(test::runTdpm("convert '" + dir + "/f.pbrt'").exitCode == 2);
  test::writeFile(dir + "/bad.pbrt", "WorldBegin\nShape \"hyperboloid\"\n");
  auto b = test::runTdpm("convert '" + dir + "/bad.pbrt' -o '" + dir + "/bad.json'");
  CHECK(b.exitCode == 1);
  CHECK(!test::fileExists(dir + "/bad.json"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("pbrt checkerboard 2D on a flat (u, v) mesh equals pbrt's parity rule") {
  // pbrt: tex1 where floor(uscale u + udelta) + floor(vscale v + vdelta) is
  // even. The patch spans 4 x 2 units with uscale 8, vscale 4: square cells
  // of 0.5; rotated and translated so nothing is axis-aligned.
  const double su = 8, sv = 4, du = 0.25, dv = 0.5;
  std::string text = R"(
WorldBegin
Texture "checks" "spectrum" "checkerboard" "float uscale" 8 "float vscale" 4 "float udelta" 0.25 "float vdelta" 0.5
  "rgb tex1" [0.9 0.1 0.1] "rgb tex2" [0.1 0.1 0.9]
Material "diffuse" "texture reflectance" "checks"
Translate 0.3 -1 2
Rotate 30 1 1 0
Shape "bilinearmesh" "point3 P" [0 0 0  4 0 0  0 0 2  4 0 2]
)";
  scene::SceneDescription d = importText(text);
  REQUIRE(d.objects.size() == 1);
  REQUIRE(d.materials[d.objects[0].material].albedoTexture >= 0);
  auto built = Scene::build(d);
  // The surface point at (u, v) in pbrt's world, mirrored as the import
  // does; a ray down the normal finds it and shades it with the texture.
  pbrt::Mat M = pbrt::mirrorX() * pbrt::Mat::translate(0.3, -1, 2) * pbrt::Mat::rotate(30, 1, 1, 0);
  Vec3f n = normalize(M.vector({0, 1, 0}));
  int checked = 0;
  for (double u = 0.013; u < 1; u += 0.0371)
    for (double v = 0.021; v < 1; v += 0.0433) {
      double a = su * u + du, b = sv * v + dv;
      if (std::fabs(a - std::round(a)) < 0.02 || std::fabs(b - std::round(b)) < 0.02) continue;  // cell edges
      Vec3f p = M.point({float(4 * u), 0, float(2 * v)});
      bool even = (int64_t(std::floor(a)) + int64_t(std::floor(b))) % 2 == 0;
      Hit h;
      REQUIRE(built->intersect(p + n, n * -1.0f, 10.0f, 0.0f, h));
      Rgb got = built->albedoAt(built->materials[built->objects[h.object].material], h);
      CHECK(got.r == doctest::Approx(even ? 0.9f : 0.1f));
      ++checked;
    }
  CHECK(checked > 300);
  // And it survives convert: same description and image.
  std::string lit = "LookAt 2 3 6  2 0 1  0 1 0\nCamera \"perspective\"\nFilm \"image\" \"integer xresolution\" 16 \"integer yresolution\" 12\n"
                    "Sampler \"random\" \"integer pixelsamples\" 2\n" + text + "LightSource \"distant\" \"rgb L\" [2 2 2] \"point3 from\" [0 1 0] \"point3 to\" [0 0 0]\n";
  scene::SceneDescription full = importText(lit);
  scene::SceneDescription back = roundTrip(full, "checker");
  CHECK(canonicalJson(back) == canonicalJson(full));
  CHECK(sameImage(renderDesc(full), renderDesc(back)));
}
