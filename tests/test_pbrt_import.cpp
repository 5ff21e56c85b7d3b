// tests/test_pbrt_import.cpp — import/pbrt_*: pbrt-v3/v4 scenes map onto the
// same SceneDescription (and the same image) as the equivalent JSON scene,
// the handedness is pbrt's (a scene is not mirrored), ActiveTransform motion
// equals JSON keyframes, convert round-trips, and every unsupported or
// malformed input is an error naming file:line.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "import/pbrt_import.h"
#include "import/pbrt_tokenizer.h"
#include "import/scene_json_writer.h"
#include "render/renderer.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

const std::string kData = std::string(TDPM_SOURCE_DIR) + "/tests/data/pbrt";

scene::SceneDescription importText(const std::string& text, const std::string& file = "dir/t.pbrt") {
  return pbrt::importPbrtText(text, file).scene;
}

std::string errorOf(const std::string& text, const std::string& file = "dir/t.pbrt") {
  try {
    pbrt::importPbrtText(text, file);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

Film renderDesc(const scene::SceneDescription& d, const std::string& method = "pathtrace", int spp = 4) {
  auto s = Scene::build(d);
  RenderOptions o;
  o.method = method;
  o.spp = spp;
  o.maxSpp = spp;
  o.maxDepth = 4;
  o.seed = 7;
  o.causticPhotons = 2000;
  o.globalPhotons = 2000;
  RenderStats st;
  return render(*s, o, Progress{}, st);
}

// Bit-identical images.
bool sameImage(const Film& a, const Film& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (size_t i = 0; i < a.color.size(); ++i)
    if (a.color[i].r != b.color[i].r || a.color[i].g != b.color[i].g || a.color[i].b != b.color[i].b) return false;
  return true;
}

double sum(const Film& f) {
  double s = 0;
  for (const Rgb& c : f.color) s += c.r + c.g + c.b;
  return s;
}

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

const char* kHeader = R"(
LookAt 0 1 6  0 0.5 0  0 1 0
Camera "perspective" "float fov" 40
Film "image" "integer xresolution" 24 "integer yresolution" 16
Sampler "halton" "integer pixelsamples" 4
Integrator "path" "integer maxdepth" 4
)";

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
