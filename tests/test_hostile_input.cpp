// tests/test_hostile_input.cpp — regression tests for the scene-input items
// of issue 11: files that are not regular or too large, deep and wide JSON,
// render keys outside the flags' ranges, coordinates outside what the ray
// tracer handles, derived quantities that overflow (rotation axis, shutter,
// scale, kappa) and OBJ files that lie. Each refusal is checked by its
// message (file, line, JSON path, the limit); the resource cases are built
// at run time and checked by what fails and where, never by seconds.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "error_capture.h"
#include "cli_harness.h"
#include "core/error.h"
#include "image/exr.h"
#include "scene/json_locate.h"
#include "scene/limits.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;
using namespace tdpm::scene;
using Json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

const std::string kFile = "h.json";

std::string errorOf(const std::string& text, const std::string& file = kFile) {
  return test::errorMessageOf([&] { parseScene(text, file); });
}

std::string loadError(const std::string& path) {
  return test::errorMessageOf([&] { loadScene(path); });
}

Json baseScene() {
  return Json::parse(R"({
    "camera": {"position": [0, 1, 5], "target": [0, 0, 0], "shutter": [0, 1]},
    "objects": [{"shape": {"type": "sphere"}}],
    "lights": [{"type": "point", "position": [0, 4, 0]}]
  })");
}

std::string edited(const std::function<void(Json&)>& edit) {
  Json s = baseScene();
  edit(s);
  return s.dump(1);
}

// "<kFile>:<line>: <path>: <problem...>": checks path and problem.
void checkEdit(const std::function<void(Json&)>& edit, const std::string& path, const std::string& problem) {
  std::string msg = errorOf(edited(edit));
  CAPTURE(msg);
  CHECK(msg.rfind(kFile + ":", 0) == 0);
  CHECK(msg.find(": " + path + ": ") != std::string::npos);
  CHECK(msg.find(problem) != std::string::npos);
}

struct TempDir {
  std::string path = test::makeTempDir();
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

// ============================================================ files (items 10, 11)

TEST_CASE("hostile input: scene files that are not regular or too large are refused before reading") {
  CHECK(loadError("/dev/zero") == "/dev/zero: cannot read scene file: it is not a regular file");
  TempDir dir;
  // A sparse file: refused by its size, so nothing of it is read.
  std::string big = dir.path + "/big.json";
  std::ofstream(big) << "{";
  fs::resize_file(big, uintmax_t(1) << 30);
  CHECK(loadError(big) == big + ": scene file is too large (1073741824 bytes; at most 16 MiB; put large meshes in OBJ files)");
  // One byte over the limit is refused, the limit itself is read (and then
  // fails on its content, not its size).
  std::string edge = dir.path + "/edge.json";
  std::ofstream(edge) << "{";
  fs::resize_file(edge, limits::kMaxSceneFileBytes + 1);
  CHECK(loadError(edge).find("scene file is too large") != std::string::npos);
  fs::resize_file(edge, limits::kMaxSceneFileBytes);
  CHECK(loadError(edge).find("too large") == std::string::npos);
}

// ============================================================ depth and width (items 7, 8)

TEST_CASE("hostile input: nesting deeper than the limit fails before nlohmann parses") {
  // 100,000 levels: before the fix this grew past 24 GB (nlohmann recursion
  // plus a path string per level); now the pre-scan stops at level 65.
  std::string deep = std::string(100000, '[') + std::string(100000, ']');
  CHECK(errorOf(deep) == kFile + ":1:65: arrays and objects are nested too deeply (at most 64 levels)");
  std::string objects;
  for (int i = 0; i < 70; ++i) objects += "{\"a\": ";
  CHECK(errorOf(objects + "1" + std::string(70, '}')).find(":1:" + std::to_string(6 * 64 + 1) + ": arrays and objects") !=
        std::string::npos);

  CHECK(firstTooDeep("[[[]]]", 3) == std::string::npos);
  CHECK(firstTooDeep("[[[[]]]]", 3) == 3);
  // Brackets inside strings (also after an escaped quote) do not count.
  CHECK(firstTooDeep("[\"[[[[\\\"[[[[\"]", 2) == std::string::npos);

  // Exactly the limit is parsed, and the located error is the real one.
  std::string ok = "{\"camera\": {}, \"objects\": [], \"x\": " + std::string(63, '[') + std::string(63, ']') + "}";
  CHECK(errorOf(ok) == kFile + ":1: x: unknown key \"x\"; allowed keys: animation, background, camera, exterior_medium, lights, materials, media, objects, render, textures");
}

TEST_CASE("hostile input: a 160k-key object and a long duplicate list are located correctly") {
  // Before the fix the locator searched each object's keys linearly per key
  // (28 s for this object); the message and line are what must not change.
  std::string text = "{\"camera\": {},\n\"objects\": [],\n";
  for (int i = 0; i < 160000; ++i) text += "\"k" + std::to_string(i) + "\": " + std::to_string(i) + ",\n";
  text += "\"camera\": {}}";
  // The duplicate at the very end is found and located.
  CHECK(errorOf(text) == kFile + ":160003: camera: duplicate key (each key may appear only once)");
  text.erase(text.rfind(",\n\"camera\""));
  text += "}";
  // nlohmann's objects are sorted: "k0" is the first unknown key, on line 3.
  CHECK(errorOf(text).rfind(kFile + ":3: k0: unknown key \"k0\"", 0) == 0);

  JsonLocator loc(text);
  CHECK(loc.line("k159999") == 160002);
  CHECK(loc.line("k159999.missing") == 160002);
  CHECK(loc.findNumber("159999") == "k159999");
  CHECK(loc.duplicates().empty());
}

TEST_CASE("hostile input: the locator follows long keys and deep paths by prefix") {
  // A 100 KB key above 10,000 elements: one path string per element would
  // be 1 GB; the locator keeps one.
  std::string key(100000, 'q');
  std::string text = "{\"" + key + "\": [\n";
  for (int i = 0; i < 10000; ++i) text += std::to_string(i) + (i + 1 < 10000 ? ",\n" : "\n");
  text += "]}";
  JsonLocator loc(text);
  CHECK(loc.line(key + "[0]") == 2);
  CHECK(loc.line(key + "[9999]") == 10001);
  CHECK(loc.line(key + "[10000]") == 1);  // missing: falls back to the array's line
  CHECK(loc.line(key.substr(1) + "[5]") == 1);
}

// ============================================================ render keys (item 9)

TEST_CASE("hostile input: scene render keys have the flags' ranges, named by JSON path") {
  checkEdit([](Json& j) { j["render"] = {{"k", 1e9}}; }, "render.k", "k 1000000000 is too large (at most 4096)");
  checkEdit([](Json& j) { j["render"] = {{"frames", 1e5}}; }, "render.frames", "frames 100000 is too large (at most 4096)");
  checkEdit([](Json& j) { j["render"] = {{"max_depth", 1e5}}; }, "render.max_depth",
            "max_depth 100000 is too large (at most 1024)");
  checkEdit([](Json& j) { j["render"] = {{"spp", 1 << 21}}; }, "render.spp", "spp 2097152 is too large (at most 1048576)");
  checkEdit([](Json& j) { j["render"] = {{"gather", 1025}}; }, "render.gather", "gather 1025 is too large (at most 1024)");
  checkEdit([](Json& j) { j["render"] = {{"exposure", 65}}; }, "render.exposure", "exposure must be in [-64, 64], got 65");
  checkEdit([](Json& j) { j["render"] = {{"photons", 3e9}}; }, "render.photons",
            "photons 3000000000 is too large (at most 2147483648)");
  checkEdit([](Json& j) { j["render"] = {{"max_radius", 1e-30}}; }, "render.max_radius",
            "max_radius must be in [1.1e-19, 1.8e+19], got 1e-30");

  // The command line refuses the same values with the same bounds.
  test::CommandResult k = test::runTdpm("render x.json --k 4097");
  CHECK(k.exitCode != 0);
  CHECK(k.output.find("not in range 1 to 4096") != std::string::npos);
  test::CommandResult frames = test::runTdpm("render x.json --frames 4097");
  CHECK(frames.output.find("not in range 1 to 4096") != std::string::npos);
  test::CommandResult depth = test::runTdpm("render x.json --max-depth 1025");
  CHECK(depth.output.find("not in range 1 to 1024") != std::string::npos);
  test::CommandResult radius = test::runTdpm("render x.json --max-radius 1e-30");
  CHECK(radius.exitCode != 0);
  CHECK(radius.output.find("--max-radius") != std::string::npos);
}

// ============================================================ kappa (item 6)

TEST_CASE("hostile input: kappa outside what the float 4D metric computes is refused") {
  limits::KappaRange r = limits::kappaRange(1.0);
  // One bin of a 1 s shutter is 1/256 s: kappa / 256^2 must be a normal float.
  CHECK(r.lo == doctest::Approx(1.17549435e-38 * 65536.0));
  CHECK(r.hi == doctest::Approx(3.40282347e+38 / 4));
  CHECK(float(r.lo / 65536.0) >= 1.17549435e-38f);
  checkEdit([](Json& j) { j["render"] = {{"kappa", 1e-38}}; }, "render.kappa",
            "kappa 1e-38 cannot be used with a shutter of 1 s: the 4D metric needs kappa in [7.704e-34, 8.507e+37] (float range)");
  CHECK(errorOf(edited([](Json& j) { j["render"] = {{"kappa", 1e-33}}; })) == "(no error)");
  // A zero-length shutter has no time to weigh.
  CHECK(errorOf(edited([](Json& j) {
          j["camera"]["shutter"] = {0.5, 0.5};
          j["render"] = {{"kappa", 1e-38}};
        })) == "(no error)");

  TempDir dir;
  std::string scene = dir.path + "/k.json";
  test::writeFile(scene, baseScene().dump());
  test::CommandResult res = test::runTdpm("render '" + scene + "' -o '" + dir.path + "/k.exr' --search 4d --kappa 1e-38 -q");
  CHECK(res.exitCode == 1);
  CHECK(res.output.find("--kappa: 1e-38 cannot be used with the 1 s shutter of " + scene +
                        ": the 4D metric needs kappa in [7.704e-34, 8.507e+37]") != std::string::npos);
  CHECK(!test::fileExists(dir.path + "/k.exr"));
}

// ============================================================ coordinates (item 1)

TEST_CASE("hostile input: coordinates beyond the ray tracer's range are refused where they are written") {
  const std::string range = "coordinates must be within +-1e+09 m";
  checkEdit([](Json& j) { j["objects"][0]["shape"] = {{"type", "quad"}, {"size", {1e10, 1e10}}}; },
            "objects[0].shape.size", "half size [5e+09, 0.5, 5e+09] is out of range: " + range);
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"translate", {0, 0, 1e20}}}; }, "objects[0].transform",
            "the object reaches [-1, -1, 1e+20] in world space (after its transform and motion); " + range);
  checkEdit([](Json& j) { j["lights"][0]["position"] = {0, 1e19, 0}; }, "lights[0].position",
            "position [0, 1e+19, 0] is out of range: " + range);
  checkEdit([](Json& j) { j["camera"]["position"] = {0, 0, 1e38}; }, "camera.position",
            "camera position [0, 0, 1e+38] is out of range: " + range);
  checkEdit([](Json& j) { j["objects"][0]["shape"]["radius"] = 1e38; }, "objects[0].shape.radius", range);
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"scale", 1e38}}; }, "objects[0].transform.scale",
            "scale [1e+38, 1e+38, 1e+38] is out of range: each factor's magnitude must be in [1e-12, 1e+12]");
  // A scale inside its range can still carry the object out of range.
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"scale", 1e10}}; }, "objects[0].transform",
            "the object reaches [-1e+10, -1e+10, -1e+10] in world space");
  // Motion: any keyframe, and the placement and motion combined.
  checkEdit(
      [](Json& j) {
        j["objects"][0]["transform"] = {{"translate", {6e8, 0, 0}}};
        j["objects"][0]["motion"] = Json::parse(R"([{"time": 0}, {"time": 1, "translate": [6e8, 0, 0]}])");
      },
      "objects[0].motion", "the object reaches [1.2e+09, 1, 1] in world space");
  checkEdit([](Json& j) { j["lights"][0]["motion"] = Json::parse(R"([{"time": 0}, {"time": 1, "translate": [0, 2e9, 0]}])"); },
            "lights[0].motion", "the light reaches [0, 2e+09, 0] in world space");
  checkEdit([](Json& j) { j["camera"]["motion"] = Json::parse(R"([{"time": 0}, {"time": 1, "target": [0, 0, -3e9]}])"); },
            "camera.motion[1].target", "camera target [0, 0, -3e+09] is out of range");
  checkEdit([](Json& j) { j["lights"][0] = Json::parse(R"({"type": "area", "size": [3e9, 1]})"); }, "lights[0]",
            "the light reaches [-1.5e+09, 0, -0.5] in world space");

  // The limit itself is accepted.
  CHECK(errorOf(edited([](Json& j) {
          j["objects"][0]["shape"] = {{"type", "quad"}, {"size", {2e9, 2e9}}};
          j["camera"]["position"] = {0, 1e9, 1e9};
        })) == "(no error)");
}

TEST_CASE("hostile input: the worst triangle inside the range keeps finite face normals") {
  // The limit's derivation: edge components <= 2e9, |cross| components
  // <= 8e18, squared length <= 1.92e38 < FLT_MAX. A triangle spanning the
  // whole range in every axis must build with finite unit normals.
  TempDir dir;
  test::writeFile(dir.path + "/t.obj", "v -1e9 -1e9 -1e9\nv 1e9 -1e9 1e9\nv -1e9 1e9 1e9\nv 1e9 1e9 -1e9\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
  Json j = baseScene();
  j["objects"][0]["shape"] = {{"type", "mesh"}, {"file", "t.obj"}};
  auto scene = Scene::build(parseScene(j.dump(), dir.path + "/s.json"));
  REQUIRE(scene->objects[0].worldNormals.size() == 3);
  for (Vec3f n : scene->objects[0].worldNormals) {
    CHECK(isFinite(n));
    CHECK(length(n) == doctest::Approx(1.0f).epsilon(1e-5));
  }
}

TEST_CASE("hostile input: a scene scaled to the coordinate limit renders the same image as at unit scale") {
  // Measured for scene/limits.h: floor, sphere, point light and camera scaled
  // by s (power by s^2) give the same image up to s = 2e8 (coordinates to
  // 1e9); from s = 5e8 Embree aborted before the limit existed.
  auto sceneAt = [](double s) {
    Json j;
    j["camera"] = {{"position", {0, 3 * s, 4.6 * s}}, {"target", {0, s, 0}}, {"fov", 40}, {"resolution", {16, 12}}};
    j["objects"] = Json::array({{{"shape", {{"type", "quad"}, {"size", {10 * s, 10 * s}}}}},
                                {{"shape", {{"type", "sphere"}, {"radius", 0.5 * s}}}, {"transform", {{"translate", {0, s, 0}}}}}});
    j["lights"] = Json::array({{{"type", "point"}, {"position", {0, 4 * s, 0}}, {"power", 100 * s * s}}});
    j["render"] = {{"spp", 2}, {"seed", 1}, {"photons", 2000}, {"global_photons", 2000}};
    return j.dump();
  };
  TempDir dir;
  for (const char* method : {"pathtrace", "time"}) {
    double mean[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
      std::string scene = dir.path + "/s" + std::to_string(i) + ".json", out = dir.path + "/s" + std::to_string(i) + ".exr";
      test::writeFile(scene, sceneAt(i == 0 ? 1.0 : 2e8));
      test::CommandResult r = test::runTdpm("render '" + scene + "' -o '" + out + "' -m " + method + " --threads 1 -q");
      CAPTURE(r.output);
      REQUIRE(r.exitCode == 0);
      image::ExrFile exr = image::readExr(out);
      for (const Rgb& p : exr.color.pixels) {
        REQUIRE(isFinite(p));
        mean[i] += p.r;
      }
      mean[i] /= double(exr.color.pixelCount());
    }
    CAPTURE(method);
    CHECK(mean[0] > 0.01);
    CHECK(mean[1] == doctest::Approx(mean[0]).epsilon(1e-3));
  }
}

// ============================================================ derived quantities (item 3)

TEST_CASE("hostile input: derived quantities are validated as the renderer computes them") {
  // A tiny axis normalises (in double) to the same rotation as [1, 1, 0].
  SceneDescription tiny = parseScene(
      edited([](Json& j) { j["objects"][0]["transform"] = Json::parse(R"({"rotate": {"axis": [1e-40, 1e-40, 0], "angle": 30}})"); }),
      kFile);
  Quaternion q = tiny.objects[0].placement.rotate;
  Quaternion want = Quaternion::fromAxisAngle(normalize(Vec3f{1, 1, 0}), 30 * kPi / 180);
  CHECK(q.w == doctest::Approx(want.w));
  CHECK(q.x == doctest::Approx(want.x));
  CHECK(q.y == doctest::Approx(want.y));
  CHECK(q.z == doctest::Approx(0.0));

  checkEdit([](Json& j) { j["camera"]["shutter"] = {-3e38, 3e38}; }, "camera.shutter",
            "shutter [-3e+38, 3e+38] is too long: its duration overflows a 32-bit float");
  checkEdit(
      [](Json& j) { j["objects"][0]["motion"] = Json::parse(R"([{"time": 0, "scale": 1}, {"time": 1, "scale": [1, -1, 1]}])"); },
      "objects[0].motion[1].scale", "has a sign opposite to the previous keyframe's [1, 1, 1]");
  checkEdit([](Json& j) { j["objects"][0]["transform"] = {{"scale", 1e-13}}; }, "objects[0].transform.scale",
            "each factor's magnitude must be in [1e-12, 1e+12]");
  checkEdit(
      [](Json& j) {
        j["camera"]["position"] = {0, 0, 0};
        j["camera"]["target"] = {1e-30, 0, 0};
      },
      "camera.target", "camera target [1e-30, 0, 0] is too close to the position [0, 0, 0] to give a view direction in float");
  checkEdit([](Json& j) { j["camera"]["up"] = {1e-30, 0, 0}; }, "camera.up", "is too small to give a camera frame in float");
  checkEdit([](Json& j) { j["lights"][0] = Json::parse(R"({"type": "area", "size": [1e-20, 1e-20]})"); }, "lights[0].size",
            "is too small for float arithmetic");
  checkEdit(
      [](Json& j) {
        j["objects"][0]["motion"] = Json::parse(R"([{"time": 0}, {"time": 1e-30, "rotate": {"axis": [0, 1, 0], "angle": 90}}])");
      },
      "objects[0].motion[1].time", "keyframes must be at least 1e-06 of the shutter apart");
  checkEdit(
      [](Json& j) {
        j["materials"] = Json::parse(R"({"c": {"type": "diffuse", "texture": {"type": "checker", "scale": 1e-40}}})");
        j["objects"][0]["material"] = "c";
      },
      "materials.c.texture.scale", "checker scale 9.99995e-41 is too small (1 / scale overflows)");
}

// ============================================================ OBJ files that lie (item 5)

TEST_CASE("hostile input: OBJ lines that do not say what they mean fail with the mesh file and line") {
  TempDir dir;
  auto meshError = [&](const std::string& body) {
    test::writeFile(dir.path + "/m.obj", "# test mesh\nv 0 0 0\nv 1 0 0\nv 0 1 0\n" + body);
    Json j = baseScene();
    j["objects"][0]["shape"] = {{"type", "mesh"}, {"file", "m.obj"}};
    return errorOf(j.dump(), dir.path + "/s.json");
  };
  const std::string prefix = dir.path + "/s.json:1: objects[0].shape.file: mesh \"" + dir.path + "/m.obj\", line 5: ";
  CHECK(meshError("v nan nan nan\nf 1 2 3\n") == prefix + "\"nan\" is not a decimal number");
  CHECK(meshError("v inf 0 0\nf 1 2 3\n") == prefix + "\"inf\" is not a decimal number");
  CHECK(meshError("v abc 0 0\nf 1 2 3\n") == prefix + "\"abc\" is not a decimal number");
  CHECK(meshError("v 0x10 0 0\nf 1 2 3\n") == prefix + "\"0x10\" is not a decimal number");
  CHECK(meshError("v 1 2\nf 1 2 3\n") == prefix + "\"v\" needs 3 to 7 numbers, got 2");
  CHECK(meshError("v 1e39 0 0\nf 1 2 3\n") == prefix + "number 1e39 is not finite as a 32-bit float");
  CHECK(meshError("v 1e30 0 0\nf 1 2 3\n") ==
        prefix + "coordinate 1e30 is out of range: coordinates must be within +-1e+09 m, the range the ray tracer handles "
                 "(docs/scene-format.md)");
  CHECK(meshError("f 1.5 2 3\n") == prefix + "face corner \"1.5\": \"1.5\" is not an integer index");
  CHECK(meshError("f 1 2 99999999999999999999\n") == prefix + "face corner \"99999999999999999999\": index 99999999999999999999 is too large");
  CHECK(meshError("f 0 1 2\n") == prefix + "face corner \"0\": OBJ indices start at 1, got 0");
  CHECK(meshError("f 1/x 2 3\n") == prefix + "face corner \"1/x\": \"x\" is not an integer index");
  CHECK(meshError("vn 0 1\nf 1 2 3\n") == prefix + "\"vn\" needs 3 numbers, got 2");
  CHECK(meshError("f 1 2 4\n") == "" + dir.path + "/s.json:1: objects[0].shape.file: mesh \"" + dir.path +
                                      "/m.obj\", line 5: face 1 uses vertex 4 but the file has 3 vertices");

  // The forms real OBJ writers use still load: w, texture/normal indices,
  // relative indices, comments, CRLF line ends.
  CHECK(meshError("vt 0.5 0.5\nvn 0 0 1\nv 1 1 0 1.0 # w\r\nf 1/1/1 2//1 -1\r\nf 1/1 2/1 3/1\n") == "(no error)");
}
