// tests/test_scene_parse.cpp — scene/parse (and its helpers json_locate,
// mesh_obj): a scene using every feature round-trips into exactly the
// expected SceneDescription, and every kind of bad input is rejected with a
// message naming the file, the JSON path, the specific problem and, where
// checked, the line. Bad variants are built by editing a valid scene with
// nlohmann::json (header-only) so each test states only what it breaks.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "error_capture.h"
#include "core/error.h"
#include "scene/json_locate.h"
#include "scene/parse.h"

using namespace tdpm;
using namespace tdpm::scene;
using Json = nlohmann::json;

namespace {

const std::string kFile = "dir/t.json";
const std::string kData = std::string(TDPM_SOURCE_DIR) + "/tests/data";

// The message of the tdpm::Error thrown for `text`, or "(no error)".
std::string errorOf(const std::string& text, const std::string& file = kFile) {
  return test::errorMessageOf([&] { parseScene(text, file); });
}

std::string loadError(const std::string& path) {
  return test::errorMessageOf([&] { loadScene(path); });
}

// A small valid scene that the bad-input tests break one piece at a time.
Json baseScene() {
  return Json::parse(R"({
    "camera": {"position": [0, 1, 5], "target": [0, 0, 0], "shutter": [0, 1]},
    "materials": {"m": {"type": "diffuse"}, "glass": {"type": "dielectric"}},
    "objects": [{"shape": {"type": "sphere"}, "material": "m"}],
    "lights": [{"type": "point", "position": [0, 4, 0]}]
  })");
}

std::string mutated(const std::function<void(Json&)>& edit) {
  Json s = baseScene();
  edit(s);
  return s.dump(2);
}

// Checks "<file>:<line>: <path>: ...<problem>...". line 0: any line.
void checkError(const std::string& text, const std::string& path, const std::string& problem, int line = 0) {
  std::string msg = errorOf(text);
  CAPTURE(msg);
  std::string prefix = kFile + ":" + (line ? std::to_string(line) + ":" : "");
  CHECK(msg.rfind(prefix, 0) == 0);
  CHECK(msg.find(": " + path + ": ") != std::string::npos);
  CHECK(msg.find(problem) != std::string::npos);
}

void checkEdit(const std::function<void(Json&)>& edit, const std::string& path, const std::string& problem) {
  checkError(mutated(edit), path, problem);
}

bool near(float a, float b) { return std::fabs(a - b) <= 1e-6f * std::max(1.0f, std::fabs(b)); }
bool same(Vec3f a, Vec3f b) { return near(a.x, b.x) && near(a.y, b.y) && near(a.z, b.z); }
bool same(Rgb a, Rgb b) { return near(a.r, b.r) && near(a.g, b.g) && near(a.b, b.b); }
bool same(Quaternion a, Quaternion b) { return near(a.w, b.w) && near(a.x, b.x) && near(a.y, b.y) && near(a.z, b.z); }
Quaternion axisAngle(Vec3f axis, float degrees) { return Quaternion::fromAxisAngle(normalize(axis), degrees * kPi / 180); }

// Every key of the format at least once (mesh resolved against kData).
const char* kFullScene = R"({
  "camera": {"position": [0, 1, 5], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov": 40,
             "resolution": [320, 240], "shutter": [0.25, 1.5],
             "motion": [{"time": 0.25, "position": [-1, 1, 5]},
                        {"time": 1.5, "position": [1, 1, 5], "target": [1, 0.5, 0], "up": [0, 1, 0.1]}]},
  "materials": {
    "glass": {"type": "dielectric", "ior": 1.45, "tint": [1, 0.9, 0.8]},
    "floor": {"type": "diffuse", "color": [0.8, 0.7, 0.6]},
    "road": {"type": "diffuse", "texture": {"type": "checker", "colors": [[0.8, 0.8, 0.8], [0.2, 0.2, 0.2]], "scale": 0.5}},
    "flat": {"type": "diffuse", "texture": {"type": "constant", "color": 0.3}},
    "mirror": {"type": "mirror", "color": [0.95, 0.95, 0.95]},
    "steel": {"type": "metal", "color": 0.9, "roughness": 0.2},
    "red_plastic": {"type": "plastic", "color": [0.8, 0.1, 0.1], "ior": 1.6, "roughness": 0.1}
  },
  "objects": [
    {"name": "ball", "shape": {"type": "sphere", "radius": 0.5}, "material": "glass",
     "transform": {"translate": [0, 1, 0], "rotate": {"axis": [0, 2, 0], "angle": 30}, "scale": [1, 2, 3]},
     "motion": [{"time": 0.5, "translate": [-1, 0, 0]},
                {"time": 1, "translate": [1, 0, 0], "rotate": {"axis": [0, 0, 1], "angle": 90}, "scale": 2}]},
    {"shape": {"type": "quad", "size": [10, 20]}, "material": "floor"},
    {"shape": {"type": "box", "size": [1, 2, 3]}, "material": "road", "transform": {"scale": 0.5}},
    {"shape": {"type": "mesh", "file": "meshes/quad.obj"}, "material": "steel"},
    {"shape": {"type": "sphere"}}
  ],
  "lights": [
    {"type": "point", "position": [0, 4, 0], "power": [100, 90, 80]},
    {"type": "spot", "name": "laser", "position": [0, 4, 0], "target": [0, 0, 0], "cone_angle": 20, "falloff_start": 15, "power": 50},
    {"type": "spot", "position": [1, 1, 1], "direction": [2, 0, 0]},
    {"type": "directional", "direction": [0, -2, 0], "irradiance": [3, 3, 3]},
    {"type": "area", "size": [0.5, 0.25], "power": 40, "transform": {"translate": [0, 3, 0]},
     "motion": [{"time": 0.25}, {"time": 1.5, "translate": [0, 0, 1]}]}
  ],
  "background": [0.1, 0.2, 0.3],
  "render": {"method": "time", "spp": 64, "seed": 12345678901234, "max_depth": 8, "exposure": -1.5}
})";

}  // namespace

// ============================================================ valid scenes

TEST_CASE("scene parse: every feature round-trips into the description") {
  SceneDescription s = parseScene(kFullScene, kData + "/full.json");
  CHECK(s.sourcePath == kData + "/full.json");

  const CameraDesc& c = s.camera;
  CHECK(same(c.position, {0, 1, 5}));
  CHECK(same(c.target, {0, 0.5f, 0}));
  CHECK(same(c.up, {0, 1, 0}));
  CHECK(c.fovDegrees == 40.0f);
  CHECK(c.width == 320);
  CHECK(c.height == 240);
  CHECK(c.shutterOpen == 0.25f);
  CHECK(c.shutterClose == 1.5f);
  REQUIRE(c.motion.size() == 2);
  CHECK(c.motion[0].time == 0.25f);
  CHECK(same(c.motion[0].position, {-1, 1, 5}));
  CHECK(same(c.motion[0].target, c.target));  // defaults to the camera's own
  CHECK(same(c.motion[0].up, c.up));
  CHECK(c.motion[1].time == 1.5f);
  CHECK(same(c.motion[1].position, {1, 1, 5}));
  CHECK(same(c.motion[1].target, {1, 0.5f, 0}));
  CHECK(same(c.motion[1].up, {0, 1, 0.1f}));

  // Materials come in name order (a JSON object has no order).
  REQUIRE(s.materials.size() == 8);  // 7 + the implicit "default"
  auto mat = [&](const std::string& name) -> const MaterialDesc& {
    for (const auto& m : s.materials)
      if (m.name == name) return m;
    FAIL("no material " << name);
    return s.materials[0];
  };
  CHECK(mat("glass").type == MaterialDesc::Type::Dielectric);
  CHECK(mat("glass").ior == 1.45f);
  CHECK(same(mat("glass").specular, {1, 0.9f, 0.8f}));
  CHECK(mat("floor").type == MaterialDesc::Type::Diffuse);
  CHECK(mat("floor").albedo.kind == TextureDesc::Kind::Constant);
  CHECK(same(mat("floor").albedo.color, {0.8f, 0.7f, 0.6f}));
  CHECK(mat("road").albedo.kind == TextureDesc::Kind::Checker);
  CHECK(same(mat("road").albedo.color, Rgb(0.8f)));
  CHECK(same(mat("road").albedo.color2, Rgb(0.2f)));
  CHECK(mat("road").albedo.scale == 0.5f);
  CHECK(mat("flat").albedo.kind == TextureDesc::Kind::Constant);
  CHECK(same(mat("flat").albedo.color, Rgb(0.3f)));
  CHECK(mat("mirror").type == MaterialDesc::Type::Mirror);
  CHECK(same(mat("mirror").specular, Rgb(0.95f)));
  CHECK(mat("steel").type == MaterialDesc::Type::Metal);
  CHECK(same(mat("steel").specular, Rgb(0.9f)));
  CHECK(mat("steel").roughness == 0.2f);
  CHECK(mat("red_plastic").type == MaterialDesc::Type::Plastic);
  CHECK(same(mat("red_plastic").albedo.color, {0.8f, 0.1f, 0.1f}));
  CHECK(mat("red_plastic").ior == 1.6f);
  CHECK(mat("red_plastic").roughness == 0.1f);
  CHECK(mat("default").type == MaterialDesc::Type::Diffuse);
  CHECK(same(mat("default").albedo.color, Rgb(0.8f)));

  REQUIRE(s.objects.size() == 5);
  const ObjectDesc& ball = s.objects[0];
  CHECK(ball.name == "ball");
  CHECK(s.materials[ball.material].name == "glass");
  CHECK(ball.shape.type == ShapeDesc::Type::Sphere);
  CHECK(ball.shape.radius == 0.5f);
  CHECK(same(ball.placement.translate, {0, 1, 0}));
  CHECK(same(ball.placement.rotate, axisAngle({0, 1, 0}, 30)));
  CHECK(same(ball.placement.scale, {1, 2, 3}));
  REQUIRE(ball.motion.times.size() == 2);
  REQUIRE(ball.motion.poses.size() == 2);
  CHECK(ball.motion.times[0] == 0.5f);
  CHECK(ball.motion.times[1] == 1.0f);
  CHECK(same(ball.motion.poses[0].translate, {-1, 0, 0}));
  CHECK(same(ball.motion.poses[0].rotate, Quaternion{}));  // identity default
  CHECK(same(ball.motion.poses[0].scale, {1, 1, 1}));
  CHECK(same(ball.motion.poses[1].translate, {1, 0, 0}));
  CHECK(same(ball.motion.poses[1].rotate, axisAngle({0, 0, 1}, 90)));
  CHECK(same(ball.motion.poses[1].scale, {2, 2, 2}));

  CHECK(s.objects[1].name == "objects[1]");
  CHECK(s.objects[1].shape.type == ShapeDesc::Type::Quad);
  CHECK(s.objects[1].shape.size.x == 10.0f);
  CHECK(s.objects[1].shape.size.z == 20.0f);
  CHECK(s.objects[1].motion.empty());
  CHECK(s.objects[2].shape.type == ShapeDesc::Type::Box);
  CHECK(same(s.objects[2].shape.size, {1, 2, 3}));
  CHECK(same(s.objects[2].placement.scale, Vec3f(0.5f)));
  CHECK(s.materials[s.objects[2].material].name == "road");

  const ShapeDesc& mesh = s.objects[3].shape;
  CHECK(mesh.type == ShapeDesc::Type::Mesh);
  CHECK(mesh.meshFile == kData + "/meshes/quad.obj");
  REQUIRE(mesh.vertices.size() == 5);
  CHECK(same(mesh.vertices[0], {-0.5f, 0, -0.5f}));
  CHECK(same(mesh.vertices[4], {0, 1, 0}));
  // The square fan-triangulated, then the triangle with a relative index.
  CHECK(mesh.indices == std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 4});
  CHECK(s.materials[s.objects[4].material].name == "default");

  REQUIRE(s.lights.size() == 5);
  const LightDesc& point = s.lights[0];
  CHECK(point.type == LightDesc::Type::Point);
  CHECK(point.name == "lights[0]");
  CHECK(same(point.position, {0, 4, 0}));
  CHECK(same(point.power, {100, 90, 80}));
  const LightDesc& laser = s.lights[1];
  CHECK(laser.type == LightDesc::Type::Spot);
  CHECK(laser.name == "laser");
  CHECK(same(laser.direction, {0, -1, 0}));
  CHECK(laser.coneAngle == 20.0f);
  CHECK(laser.falloffStart == 15.0f);
  CHECK(same(laser.power, Rgb(50)));
  CHECK(same(s.lights[2].direction, {1, 0, 0}));  // normalised
  CHECK(s.lights[2].coneAngle == 30.0f);
  CHECK(near(s.lights[2].falloffStart, 25.0f));
  const LightDesc& sun = s.lights[3];
  CHECK(sun.type == LightDesc::Type::Directional);
  CHECK(same(sun.direction, {0, -1, 0}));
  CHECK(same(sun.power, Rgb(3)));
  const LightDesc& area = s.lights[4];
  CHECK(area.type == LightDesc::Type::Area);
  CHECK(area.areaSize.x == 0.5f);
  CHECK(area.areaSize.y == 0.25f);
  CHECK(same(area.power, Rgb(40)));
  CHECK(same(area.placement.translate, {0, 3, 0}));
  REQUIRE(area.motion.times.size() == 2);
  CHECK(same(area.motion.poses[0].translate, {0, 0, 0}));
  CHECK(same(area.motion.poses[1].translate, {0, 0, 1}));

  CHECK(same(s.background, {0.1f, 0.2f, 0.3f}));
  CHECK(s.render.method == "time");
  CHECK(s.render.spp == 64);
  CHECK(s.render.seed == 12345678901234ull);
  CHECK(s.render.maxDepth == 8);
  CHECK(s.render.exposure == -1.5f);
}

TEST_CASE("scene parse: a minimal scene takes the documented defaults") {
  SceneDescription s = parseScene(R"({"camera": {}, "objects": []})", "min.json");
  const CameraDesc def;
  CHECK(same(s.camera.position, def.position));
  CHECK(same(s.camera.target, def.target));
  CHECK(s.camera.fovDegrees == def.fovDegrees);
  CHECK(s.camera.width == 640);
  CHECK(s.camera.height == 480);
  CHECK(s.camera.shutterOpen == 0.0f);
  CHECK(s.camera.shutterClose == 1.0f);
  CHECK(s.camera.motion.empty());
  CHECK(s.materials.empty());
  CHECK(s.objects.empty());
  CHECK(s.lights.empty());
  CHECK(same(s.background, Rgb(0)));
  // Unset render settings stay unset: the renderer's defaults apply.
  CHECK_FALSE(s.render.method.has_value());
  CHECK_FALSE(s.render.spp.has_value());
  CHECK_FALSE(s.render.seed.has_value());
  CHECK_FALSE(s.render.maxDepth.has_value());
  CHECK_FALSE(s.render.exposure.has_value());
  CHECK_FALSE(s.render.photons.has_value());
}

TEST_CASE("scene parse: accepted edge values") {
  // close == open (no blur), integral floats for integers, a file "default"
  // material used by objects that name none, a UTF-8 BOM.
  auto s = parseScene(mutated([](Json& j) {
                        j["camera"]["shutter"] = {0.5, 0.5};
                        j["camera"]["resolution"] = {64.0, 1e2};
                        j["render"] = {{"spp", 4.0}, {"seed", 0}};
                        j["materials"]["default"] = {{"type", "mirror"}};
                        j["objects"][0].erase("material");
                      }),
                      kFile);
  CHECK(s.camera.shutterOpen == 0.5f);
  CHECK(s.camera.shutterClose == 0.5f);
  CHECK(s.camera.width == 64);
  CHECK(s.camera.height == 100);
  CHECK(s.render.spp == 4);
  CHECK(s.render.seed == 0);
  CHECK(s.materials[s.objects[0].material].type == MaterialDesc::Type::Mirror);
  CHECK(parseScene("\xEF\xBB\xBF{\"camera\": {}, \"objects\": []}", kFile).objects.empty());
}

// ============================================================ text level

TEST_CASE("scene parse: empty, non-UTF-8, syntax errors, top level") {
  CHECK(errorOf("") == kFile + ":1: the file is empty (expected a JSON object)");
  CHECK(errorOf(" \n\t ") == kFile + ":1: the file is empty (expected a JSON object)");

  std::string bad = errorOf("{\n  \"camera\": \xff\xfe\n}");
  CHECK(bad.rfind(kFile + ":2:13: not valid UTF-8 text (byte 0xFF)", 0) == 0);

  std::string syntax = errorOf("{\n  \"camera\": {},\n  \"objects\": [1,]\n}");
  CAPTURE(syntax);
  CHECK(syntax.rfind(kFile + ":3:17: syntax error while parsing value", 0) == 0);
  CHECK(errorOf("{\"camera\": {}").rfind(kFile + ":1:14: syntax error", 0) == 0);

  checkError("[1]", "top level", "expected an object, got an array of 1 element", 1);
  checkError("42", "top level", "expected an object, got a number", 1);
}

TEST_CASE("scene parse: numbers that are not finite") {
  // JSON has no NaN/Inf literals; overflowing ones are the way in.
  std::string text = "{\n  \"camera\": {\n    \"fov\": 1e999\n  },\n  \"objects\": []\n}";
  checkError(text, "camera.fov", "number 1e999 is not finite (it overflows)", 3);
  checkError(R"({"camera": {"position": [0, -1e999, 0]}, "objects": []})", "camera.position[1]",
             "number -1e999 is not finite");
  // Finite as a double, infinite as the float the description holds.
  checkError(R"({"camera": {"fov": 1e39}, "objects": []})", "camera.fov", "is not finite as a 32-bit float");
}

TEST_CASE("scene parse: duplicate keys are rejected with the repeat's line") {
  checkError("{\n \"camera\": {},\n \"objects\": [],\n \"camera\": {}\n}", "camera", "duplicate key", 4);
}

TEST_CASE("scene parse: loadScene file errors") {
  std::string missing = loadError(kData + "/no_such_scene.json");
  CHECK(missing == kData + "/no_such_scene.json: cannot read scene file (No such file or directory)");
  CHECK(loadError(kData) == kData + ": cannot read scene file: it is a directory");
  CHECK(loadError(kData + "/empty.json") == kData + "/empty.json:1: the file is empty (expected a JSON object)");
  CHECK(loadError(kData + "/not_utf8.json").rfind(kData + "/not_utf8.json:2:13: not valid UTF-8", 0) == 0);
}

// ============================================================ structure

TEST_CASE("scene parse: required keys, unknown keys, wrong types") {
  checkEdit([](Json& j) { j.erase("camera"); }, "top level", "missing required key \"camera\"");
  checkEdit([](Json& j) { j.erase("objects"); }, "top level", "missing required key \"objects\"");
  checkEdit([](Json& j) { j["objets"] = Json::array(); }, "objets",
            "unknown key \"objets\" (did you mean \"objects\"?); allowed keys: animation, background, camera, "
            "exterior_medium, lights, materials, media, objects, render");
  checkEdit([](Json& j) { j["camera"]["positon"] = {0, 0, 0}; }, "camera.positon",
            "unknown key \"positon\" (did you mean \"position\"?); allowed keys: focal_distance, fov, lens_radius, "
            "medium, motion, position, resolution, shutter, target, up");
  checkEdit([](Json& j) { j["objects"][0]["shape"]["colour"] = 1; }, "objects[0].shape.colour",
            "unknown key \"colour\"; allowed keys: radius, reverse_orientation, type");
  checkEdit([](Json& j) { j["camera"] = "front"; }, "camera", "expected an object, got a string");
  checkEdit([](Json& j) { j["objects"] = Json::object(); }, "objects", "expected an array of objects, got an object");
  checkEdit([](Json& j) { j["camera"]["position"] = "origin"; }, "camera.position",
            "expected an array of 3 numbers, got a string");
  checkEdit([](Json& j) { j["camera"]["position"] = {1, 2}; }, "camera.position",
            "expected an array of 3 numbers, got an array of 2 elements");
  checkEdit([](Json& j) { j["camera"]["position"] = {1, true, 2}; }, "camera.position[1]",
            "expected a number, got true");
  checkEdit([](Json& j) { j["camera"]["fov"] = nullptr; }, "camera.fov", "expected a number, got null");
  checkEdit([](Json& j) { j["objects"][0]["name"] = 7; }, "objects[0].name", "expected a string, got a number");
  checkEdit([](Json& j) { j["objects"][0]["name"] = ""; }, "objects[0].name", "name must not be empty");
}

TEST_CASE("scene parse: error lines point at the offending value") {
  const std::string text = R"({
  "camera": {"position": [0, 1, 5],
             "target": [0, 0, 0]},
  "objects": [
    {"shape": {"type": "sphere"}},
    {"shape": {"type": "sphere"},
     "motion": [
       {"time": 0},
       {"time": 1,
        "translate": "left"}
     ]}
  ]
})";
  checkError(text, "objects[1].motion[1].translate", "expected an array of 3 numbers, got a string", 10);
  // A missing key is reported at the line of its enclosing object.
  checkError("{\n \"camera\": {},\n \"objects\": [\n  {\n   \"material\": \"x\"}]}", "objects[0]",
             "missing required key \"shape\"", 4);
  checkError("{\n \"camera\": {\"up\": [0, 0, 0]},\n \"objects\": []}", "camera.up", "up must not be a zero vector", 2);
}

// ============================================================ camera

TEST_CASE("scene parse: camera values out of range") {
  checkEdit([](Json& j) { j["camera"]["fov"] = 0; }, "camera.fov", "fov must be in (0, 180) degrees, got 0");
  checkEdit([](Json& j) { j["camera"]["fov"] = 180; }, "camera.fov", "fov must be in (0, 180) degrees, got 180");
  checkEdit([](Json& j) { j["camera"]["resolution"] = {0, 480}; }, "camera.resolution",
            "resolution must be at least 1x1, got 0x480");
  checkEdit([](Json& j) { j["camera"]["resolution"] = {640, -2}; }, "camera.resolution",
            "resolution must be at least 1x1, got 640x-2");
  checkEdit([](Json& j) { j["camera"]["resolution"] = {70000, 480}; }, "camera.resolution",
            "resolution 70000x480 is too large (at most 65536 per side)");
  checkEdit([](Json& j) { j["camera"]["resolution"] = {640.5, 480}; }, "camera.resolution[0]",
            "expected an integer, got 640.5");
  checkEdit([](Json& j) { j["camera"]["resolution"] = {640, 480, 3}; }, "camera.resolution",
            "expected an array of 2 integers [width, height], got an array of 3 elements");
  checkEdit([](Json& j) { j["camera"]["shutter"] = {1, 0.5}; }, "camera.shutter",
            "shutter close (0.5) is before open (1)");
  checkEdit([](Json& j) { j["camera"]["target"] = {0, 1, 5}; }, "camera.target",
            "camera position and target are the same point [0, 1, 5]");
  checkEdit([](Json& j) { j["camera"]["up"] = {0, 2, 10}; }, "camera.up",
            "up [0, 2, 10] is parallel to the view direction");
  checkEdit([](Json& j) { j["camera"]["up"] = {0, 0, 0}; }, "camera.up", "up must not be a zero vector");
}

TEST_CASE("scene parse: camera motion") {
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array({{{"time", 0}}}); }, "camera.motion",
            "motion needs at least 2 keyframes, got 1");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array(); }, "camera.motion",
            "motion needs at least 2 keyframes, got 0");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array({{{"time", 0.5}}, {{"time", 0.2}}}); },
            "camera.motion[1].time", "keyframe times must be strictly increasing: 0.2 does not come after 0.5");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array({{{"time", 0}}, {{"time", 2}}}); },
            "camera.motion[1].time", "time 2 is outside the shutter [0, 1]");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array({{{"time", 0}}, {{"at", 1}}}); },
            "camera.motion[1].at", "unknown key \"at\"");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::array({{{"time", 0}}, {{"position", {0, 0, 1}}}}); },
            "camera.motion[1]", "missing required key \"time\"");
  checkEdit(
      [](Json& j) {
        j["camera"]["motion"] = Json::array({{{"time", 0}}, {{"time", 1}, {"target", {0, 1, 5}}}});
      },
      "camera.motion[1].target", "camera position and target are the same point");
}

// ============================================================ materials

TEST_CASE("scene parse: materials") {
  checkEdit([](Json& j) { j["materials"]["m"].erase("type"); }, "materials.m", "missing required key \"type\"");
  checkEdit([](Json& j) { j["materials"]["m"]["type"] = "lambert"; }, "materials.m.type",
            "unknown material type \"lambert\"; expected one of diffuse, mirror, dielectric, metal, plastic");
  checkEdit([](Json& j) { j["materials"]["m"]["roughness"] = 0.5; }, "materials.m.roughness",
            "unknown key \"roughness\"; allowed keys: bump, color, normal_map, sigma, texture, type");
  checkEdit([](Json& j) { j["materials"]["glass"]["ior"] = 0.9; }, "materials.glass.ior",
            "ior must be at least 1, got 0.9");
  checkEdit([](Json& j) { j["materials"]["m"] = {{"type", "metal"}, {"roughness", 0}}; }, "materials.m.roughness",
            "roughness must be in (0, 1], got 0");
  checkEdit([](Json& j) { j["materials"]["m"] = {{"type", "plastic"}, {"roughness", 1.5}}; }, "materials.m.roughness",
            "roughness must be in (0, 1], got 1.5");
  checkEdit([](Json& j) { j["materials"]["m"]["color"] = {0.5, -0.1, 0.5}; }, "materials.m.color",
            "must be non-negative in every channel, got [0.5, -0.1, 0.5]");
  checkEdit([](Json& j) { j["materials"]["m"]["color"] = {0.5, 1.2, 0.5}; }, "materials.m.color",
            "reflectance must be at most 1 in every channel (energy conservation), got [0.5, 1.2, 0.5]");
  checkEdit([](Json& j) { j["materials"]["m"] = {{"type", "mirror"}, {"color", 1.01}}; }, "materials.m.color",
            "reflectance must be at most 1 in every channel");
  checkEdit([](Json& j) { j["materials"]["m"]["color"] = "red"; }, "materials.m.color",
            "expected a number or an array of 3 numbers [r, g, b], got a string");
  checkEdit(
      [](Json& j) {
        j["materials"]["m"]["texture"] = {{"type", "checker"}, {"colors", {{0.5, 0.5, 0.5}, {2, 0, 0}}}};
      },
      "materials.m.texture.colors[1]", "reflectance must be at most 1 in every channel");
  checkEdit([](Json& j) { j["materials"]["m"]["texture"] = {{"type", "checker"}, {"colors", {0.5}}}; },
            "materials.m.texture.colors", "expected an array of 2 colours, got an array of 1 element");
  checkEdit([](Json& j) { j["materials"]["m"]["texture"] = {{"type", "checker"}, {"scale", 0}}; },
            "materials.m.texture.scale", "checker scale (cell size) must be positive, got 0");
  checkEdit([](Json& j) { j["materials"]["m"]["texture"] = {{"type", "noise"}}; }, "materials.m.texture.type",
            "unknown texture type \"noise\"; expected one of constant, checker");
  checkEdit(
      [](Json& j) {
        j["materials"]["m"]["color"] = 0.5;
        j["materials"]["m"]["texture"] = {{"type", "constant"}};
      },
      "materials.m.texture", "give either \"color\" or \"texture\", not both");
  checkEdit([](Json& j) { j["materials"] = Json::array(); }, "materials", "expected an object, got an empty array");
  checkEdit([](Json& j) { j["materials"][""] = {{"type", "diffuse"}}; }, "materials.", "material names must not be empty");
}

TEST_CASE("scene parse: object material references") {
  checkEdit([](Json& j) { j["objects"][0]["material"] = "glas"; }, "objects[0].material",
            "unknown material \"glas\"; defined materials: glass, m");
  checkEdit(
      [](Json& j) {
        j.erase("materials");
        j["objects"][0]["material"] = "m";
      },
      "objects[0].material", "unknown material \"m\"; no materials are defined");
  checkEdit([](Json& j) { j["objects"][0]["material"] = 0; }, "objects[0].material",
            "expected a string (a material name), got a number");
}

// ============================================================ shapes

TEST_CASE("scene parse: shapes") {
  checkEdit([](Json& j) { j["objects"][0].erase("shape"); }, "objects[0]", "missing required key \"shape\"");
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"radius", 1}}; }, "objects[0].shape",
            "missing required key \"type\"");
  checkEdit([](Json& j) { j["objects"][0]["shape"]["type"] = "torus"; }, "objects[0].shape.type",
            "unknown shape type \"torus\"; expected one of sphere, quad, box, mesh, disk, cylinder");
  checkEdit([](Json& j) { j["objects"][0]["shape"]["radius"] = -1; }, "objects[0].shape.radius",
            "radius must be positive, got -1");
  checkEdit([](Json& j) { j["objects"][0]["shape"]["radius"] = 0; }, "objects[0].shape.radius",
            "radius must be positive, got 0");
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"type", "quad"}, {"size", {10, 0}}}; }, "objects[0].shape.size",
            "size must be positive in every dimension, got [10, 0]");
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"type", "quad"}, {"size", {1, 2, 3}}}; },
            "objects[0].shape.size", "expected an array of 2 numbers, got an array of 3 elements");
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"type", "box"}, {"size", {1, -2, 1}}}; },
            "objects[0].shape.size", "size must be positive in every dimension, got [1, -2, 1]");
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"type", "mesh"}}; }, "objects[0].shape",
            "missing required key \"file\"");
}

TEST_CASE("scene parse: transforms and object motion") {
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"scale", {1, 0, 1}}}; }, "objects[0].transform.scale",
            "scale must not have a zero component, got [1, 0, 1]");
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"scale", 0}}; }, "objects[0].transform.scale",
            "scale must not have a zero component");
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"rotate", {{"axis", {0, 0, 0}}, {"angle", 10}}}}; },
            "objects[0].transform.rotate.axis", "rotation axis must not be a zero vector");
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"rotate", {{"axis", {0, 1, 0}}}}}; },
            "objects[0].transform.rotate", "missing required key \"angle\"");
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"move", {0, 1, 0}}}; }, "objects[0].transform.move",
            "unknown key \"move\"; allowed keys: rotate, scale, translate");
  checkEdit([](Json& j) { j["objects"][0]["motion"] = Json::array({{{"time", 0}}}); }, "objects[0].motion",
            "motion needs at least 2 keyframes, got 1");
  checkEdit([](Json& j) { j["objects"][0]["motion"] = Json::array({{{"time", 0.5}}, {{"time", 0.5}}}); },
            "objects[0].motion[1].time", "keyframe times must be strictly increasing: 0.5 does not come after 0.5");
  checkEdit([](Json& j) { j["objects"][0]["motion"] = Json::array({{{"time", -0.1}}, {{"time", 0.5}}}); },
            "objects[0].motion[0].time", "time -0.1 is outside the shutter [0, 1]");
  checkEdit(
      [](Json& j) {
        j["objects"][0]["motion"] = Json::array({{{"time", 0}}, {{"time", 1}, {"scale", {1, 1, 0}}}});
      },
      "objects[0].motion[1].scale", "scale must not have a zero component");
  checkEdit([](Json& j) { j["objects"][0]["motion"] = {{"time", 0}}; }, "objects[0].motion",
            "expected an array of keyframes, got an object");
}

// ============================================================ meshes

TEST_CASE("scene parse: meshes load relative to the scene file") {
  SceneDescription s = loadScene(kData + "/mesh_scene.json");
  REQUIRE(s.objects.size() == 1);
  CHECK(s.objects[0].shape.meshFile == kData + "/meshes/quad.obj");
  CHECK(s.objects[0].shape.vertices.size() == 5);
  CHECK(s.objects[0].shape.indices.size() == 9);
  CHECK(same(s.materials[s.objects[0].material].albedo.color, Rgb(0.7f)));

  // An absolute path is used as is.
  Json j = baseScene();
  j["objects"][0]["shape"] = {{"type", "mesh"}, {"file", kData + "/meshes/quad.obj"}};
  CHECK(parseScene(j.dump(), "elsewhere/x.json").objects[0].shape.meshFile == kData + "/meshes/quad.obj");
}

TEST_CASE("scene parse: mesh errors name the mesh file and the JSON path") {
  std::string missing = loadError(kData + "/missing_mesh_scene.json");
  CHECK(missing == kData + "/missing_mesh_scene.json:6: objects[1].shape.file: mesh \"" + kData +
                       "/meshes/does_not_exist.obj\" does not exist");

  auto meshError = [](const std::string& obj) {
    Json j = baseScene();
    j["objects"][0]["shape"] = {{"type", "mesh"}, {"file", "meshes/" + obj}};
    return errorOf(j.dump(), kData + "/inline.json");
  };
  std::string prefix = kData + "/inline.json:1: objects[0].shape.file: mesh \"" + kData + "/meshes/";
  CHECK(meshError("bad_index.obj") == prefix + "bad_index.obj\", line 6: face 2 uses vertex 9 but the file has 3 vertices");
  CHECK(meshError("no_faces.obj") == prefix + "no_faces.obj\" has no triangles");
  CHECK(meshError("nonfinite.obj") == prefix + "nonfinite.obj\", line 3: number 1e999 is not finite as a 32-bit float");
  CHECK(meshError("two_corners.obj") == prefix + "two_corners.obj\", line 5: a face needs at least 3 vertices, got 2");
  CHECK(meshError("") == prefix + "\" is not a regular file");
  checkEdit([](Json& s) { s["objects"][0]["shape"] = {{"type", "mesh"}, {"file", ""}}; }, "objects[0].shape.file",
            "mesh file name must not be empty");
}

// ============================================================ lights

TEST_CASE("scene parse: lights") {
  auto light = [](Json l) { return [l](Json& j) { j["lights"] = Json::array({l}); }; };
  checkEdit(light({{"type", "laser"}}), "lights[0].type",
            "unknown light type \"laser\"; expected one of point, spot, directional, area");
  checkEdit(light({{"position", {0, 1, 0}}}), "lights[0]", "missing required key \"type\"");
  checkEdit(light({{"type", "point"}, {"power", {10, -1, 10}}}), "lights[0].power",
            "must be non-negative in every channel, got [10, -1, 10]");
  checkEdit(light({{"type", "point"}, {"direction", {0, -1, 0}}}), "lights[0].direction",
            "unknown key \"direction\"; allowed keys: medium, motion, name, position, power, transform, type");
  checkEdit(light({{"type", "spot"}, {"target", {0, 0, 0}}, {"direction", {0, -1, 0}}}), "lights[0].direction",
            "give either \"target\" or \"direction\", not both");
  checkEdit(light({{"type", "spot"}, {"position", {1, 2, 3}}, {"target", {1, 2, 3}}}), "lights[0].target",
            "spot target equals its position [1, 2, 3]");
  checkEdit(light({{"type", "spot"}, {"direction", {0, 0, 0}}}), "lights[0].direction",
            "direction must not be a zero vector");
  checkEdit(light({{"type", "spot"}, {"cone_angle", 0}}), "lights[0].cone_angle",
            "cone_angle must be in (0, 90] degrees, got 0");
  checkEdit(light({{"type", "spot"}, {"cone_angle", 95}}), "lights[0].cone_angle",
            "cone_angle must be in (0, 90] degrees, got 95");
  checkEdit(light({{"type", "spot"}, {"cone_angle", 20}, {"falloff_start", 25}}), "lights[0].falloff_start",
            "falloff_start must be in [0, cone_angle = 20] degrees, got 25");
  checkEdit(light({{"type", "spot"}, {"falloff_start", -1}}), "lights[0].falloff_start",
            "falloff_start must be in [0, cone_angle = 30] degrees, got -1");
  checkEdit(light({{"type", "directional"}, {"direction", {0, 0, 0}}}), "lights[0].direction",
            "direction must not be a zero vector");
  checkEdit(light({{"type", "directional"}, {"power", 5}}), "lights[0].power",
            "a directional light takes \"irradiance\" (W/m^2), not \"power\"");
  checkEdit(light({{"type", "directional"}, {"irradiance", -3}}), "lights[0].irradiance",
            "must be non-negative in every channel");
  checkEdit(light({{"type", "area"}, {"size", {0, 1}}}), "lights[0].size",
            "size must be positive in every dimension, got [0, 1]");
  checkEdit(light({{"type", "area"}, {"motion", Json::array({Json{{"time", 0}}})}}), "lights[0].motion",
            "motion needs at least 2 keyframes, got 1");
  checkEdit(light({{"type", "point"}, {"motion", Json::array({Json{{"time", 0}}, Json{{"time", 3}}})}}),
            "lights[0].motion[1].time",
            "time 3 is outside the shutter [0, 1]");
  checkEdit([](Json& j) { j["lights"] = {{"type", "point"}}; }, "lights", "expected an array of lights, got an object");

  // The spot's default falloff follows its cone.
  Json j = baseScene();
  j["lights"] = Json::array({{{"type", "spot"}, {"cone_angle", 12}}});
  CHECK(near(parseScene(j.dump(), kFile).lights[0].falloffStart, 10.0f));
}

// ============================================================ render, background

TEST_CASE("scene parse: render settings and background") {
  checkEdit([](Json& j) { j["render"] = {{"method", "photon"}}; }, "render.method",
            "unknown render method \"photon\"; expected one of pathtrace, static, accumulation, standard, time");
  checkEdit([](Json& j) { j["render"] = {{"spp", 0}}; }, "render.spp", "spp must be at least 1, got 0");
  checkEdit([](Json& j) { j["render"] = {{"spp", 1e10}}; }, "render.spp", "spp 10000000000 is too large");
  checkEdit([](Json& j) { j["render"] = {{"max_depth", 0}}; }, "render.max_depth", "max_depth must be at least 1, got 0");
  checkEdit([](Json& j) { j["render"] = {{"seed", -1}}; }, "render.seed", "seed must be a non-negative integer, got -1");
  checkEdit([](Json& j) { j["render"] = {{"seed", 1.5}}; }, "render.seed", "seed must be a non-negative integer, got 1.5");
  checkEdit([](Json& j) { j["render"] = {{"seed", "42"}}; }, "render.seed",
            "seed must be a non-negative integer, got a string");
  checkEdit([](Json& j) { j["render"] = {{"exposure", "+1"}}; }, "render.exposure", "expected a number, got a string");
  checkEdit([](Json& j) { j["render"] = {{"threads", 4}}; }, "render.threads",
            "unknown key \"threads\"; allowed keys: contrast, direct_only, exposure, filter, filter_radius, fraction, frames, "
            "gather, global_photons, k, kappa, kernel_space, kernel_time, max_depth, max_dt, max_radius, max_spp, method, "
            "passes, photons, photons_per_pixel, progressive, sampler, search, seed, spp, time_limit");
  checkEdit([](Json& j) { j["render"] = {{"sampler", "halton"}}; }, "render.sampler", "halton");
  checkEdit([](Json& j) { j["render"] = {{"filter", "mitchell"}}; }, "render.filter",
            "unknown filter \"mitchell\"; expected one of box, gaussian");
  checkEdit([](Json& j) { j["render"] = {{"filter_radius", 0}}; }, "render.filter_radius",
            "filter_radius must be in [0.01, 16], got 0");
  {
    Json j = baseScene();
    j["render"] = {{"filter", "gaussian"}, {"filter_radius", 2}};
    auto d = parseScene(j.dump(), kFile);
    CHECK(d.render.filter == std::string("gaussian"));
    CHECK(*d.render.filterRadius == 2.0f);
  }
  checkEdit([](Json& j) { j["render"] = {{"progressive", 1}}; }, "render.progressive", "expected true or false");
  checkEdit([](Json& j) { j["render"] = {{"passes", 0}}; }, "render.passes", "passes");
  checkEdit([](Json& j) { j["render"] = {{"time_limit", -1}}; }, "render.time_limit", "time_limit");
  checkEdit([](Json& j) { j["render"] = {{"fraction", 0}}; }, "render.fraction", "fraction must be in [1e-06, 1], got 0");
  checkEdit([](Json& j) { j["render"] = {{"fraction", 1.5}}; }, "render.fraction", "fraction must be in [1e-06, 1], got 1.5");
  checkEdit([](Json& j) { j["render"] = {{"photons", -1}}; }, "render.photons", "photons must be at least 0, got -1");
  checkEdit([](Json& j) { j["render"] = {{"global_photons", 1e12}}; }, "render.global_photons", "is too large");
  checkEdit([](Json& j) { j["render"] = {{"search", "5d"}}; }, "render.search", "unknown search \"5d\"");
  checkEdit([](Json& j) { j["render"] = {{"kernel_space", "box"}}; }, "render.kernel_space", "unknown space kernel \"box\"");
  checkEdit([](Json& j) { j["render"] = {{"kernel_time", "cone"}}; }, "render.kernel_time", "unknown time kernel \"cone\"");
  checkEdit([](Json& j) { j["render"] = {{"kappa", 0}}; }, "render.kappa", "kappa must be positive, got 0");
  checkEdit([](Json& j) { j["render"] = {{"max_radius", -1}}; }, "render.max_radius", "max_radius must be positive");
  checkEdit([](Json& j) { j["render"] = {{"max_dt", 0}}; }, "render.max_dt", "max_dt must be positive");
  checkEdit([](Json& j) { j["render"] = {{"gather", -2}}; }, "render.gather", "gather must be at least 0, got -2");
  checkEdit([](Json& j) { j["render"] = {{"frames", 0}}; }, "render.frames", "frames must be at least 1, got 0");
  checkEdit([](Json& j) { j["render"] = {{"max_spp", 0}}; }, "render.max_spp", "max_spp must be at least 1, got 0");
  checkEdit([](Json& j) { j["render"] = {{"contrast", -0.1}}; }, "render.contrast", "contrast must be positive");
  checkEdit([](Json& j) { j["background"] = {0, -1, 0}; }, "background",
            "must be non-negative in every channel, got [0, -1, 0]");
}

// ============================================================ end to end

TEST_CASE("scene parse: tdpm render rejects a bad scene, exits 1 and writes no image") {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("tdpm_test_scene_parse_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path scene = dir / "bad.json", out = dir / "out.exr", err = dir / "stderr.txt";
  std::ofstream(scene) << "{\n \"camera\": {},\n \"objects\": [\n  {\"shape\": {\"type\": \"sphere\", \"radius\": -1}}]\n}\n";
  std::string cmd = std::string("\"") + TDPM_BINARY + "\" render \"" + scene.string() + "\" -o \"" + out.string() +
                    "\" 2> \"" + err.string() + "\"";
  int status = std::system(cmd.c_str());
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  std::stringstream message;
  message << std::ifstream(err).rdbuf();
  CAPTURE(message.str());
  CHECK(message.str().find(scene.string() + ":4: objects[0].shape.radius: radius must be positive, got -1") !=
        std::string::npos);
  CHECK(!fs::exists(out));
  CHECK(!fs::exists(dir / "out.png"));
  fs::remove_all(dir);
}

// ============================================================ locator

TEST_CASE("json locator: paths, lines, escapes, duplicates, numbers") {
  std::string text = "{\n \"a\": [1,\n  {\"b\\u00e9\": 2}],\n \"c.d\": {\"e\": 1e999},\n \"a\": 3\n}";
  JsonLocator loc(text);
  CHECK(loc.line("") == 1);
  CHECK(loc.line("a[0]") == 2);
  CHECK(loc.line("a[1]") == 3);
  CHECK(loc.line("a[1].b\xC3\xA9") == 3);  // \u00e9 decoded to UTF-8, as nlohmann does
  CHECK(loc.line("c.d.e") == 4);
  CHECK(loc.line("c.d.missing") == 4);  // falls back to the enclosing object
  CHECK(loc.line("a") == 5);            // the later duplicate wins, as in nlohmann
  REQUIRE(loc.duplicates().size() == 1);
  CHECK(loc.duplicates()[0].path == "a");
  CHECK(loc.duplicates()[0].line == 5);
  CHECK(loc.findNumber("1e999") == "c.d.e");
  CHECK(loc.findNumber("1e99") == "");

  CHECK(parentPath("objects[2].motion[1].translate") == "objects[2].motion[1]");
  CHECK(parentPath("objects[2].motion[1]") == "objects[2].motion");
  CHECK(parentPath("objects") == "");
  CHECK(positionOf("ab\ncd", 4).line == 2);
  CHECK(positionOf("ab\ncd", 4).column == 2);
  CHECK(firstInvalidUtf8("ok \xC3\xA9") == std::string::npos);
  CHECK(firstInvalidUtf8("ok \xC3(") == 3);
  CHECK(firstInvalidUtf8("\xED\xA0\x80") == 0);  // a UTF-16 surrogate is not UTF-8

  // Truncated or garbage text must not crash the best-effort scan.
  JsonLocator broken("{\"a\": [1, {\"b\": ");
  CHECK(broken.line("a[1]") == 1);
}
