// tests/test_shading_normals.cpp — bump and normal maps (scene/
// shading_normal.cpp, the shading frame of scene/bsdf.*): a linear bump
// ramp on a quad gives the analytic tilted normal and the rendered cosine
// under directional lights, a constant (0.5, 0.5, 1) normal map leaves the
// image bit for bit as without it (path tracer and photon method), a normal
// map tilting by a known angle gives its cosine, light from behind the
// geometric surface never leaks through a bumped one, the pbrt import of
// bumpmap / displacement / normalmap and its convert round trip (same
// pixels), and located errors for bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "error_capture.h"
#include "image/pfm.h"
#include "import/pbrt_import.h"
#include "normal_checks.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

RenderOptions options(RenderMethod m, int spp, int maxDepth, uint64_t seed) {
  return test::normalTestOptions(m, spp, maxDepth, seed);
}

// Camera straight down on a 2 x 2 quad (normal +y; u along +x over 2 m,
// v along -z), 16 x 16 pixels covering x, z in [-0.8, 0.8].
std::string quadScene(const std::string& textures, const std::string& material, const std::string& light) {
  return R"({"camera": {"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov": 30, "resolution": [16, 16]},
    "textures": )" + textures + R"(, "materials": {"m": )" + material + R"(},
    "objects": [{"shape": {"type": "quad", "size": [2, 2]}, "material": "m"}],
    "lights": [)" + light + "]}";
}

// A 2 x 1 float image 0 | 1: bilinear (clamped) it is 2 (u - 1/4) for u in
// [1/4, 3/4], a linear ramp of slope 2 in u.
std::string writeRamp(const std::string& dir) {
  image::ImageRgb img(2, 1);
  img.at(0, 0) = Rgb(0.0f);
  img.at(1, 0) = Rgb(1.0f);
  image::writePfm(dir + "/ramp.pfm", img);
  return R"({"ramp": {"type": "image", "file": "ramp.pfm", "float": true, "wrap": "clamp"}})";
}

// A 1 x 1 normal map holding the unit tangent-space normal t.
void writeNormalMap(const std::string& path, Vec3f t) {
  image::ImageRgb img(1, 1);
  img.at(0, 0) = Rgb(0.5f * (t.x + 1), 0.5f * (t.y + 1), 0.5f * (t.z + 1));
  image::writePfm(path, img);
}

// The mean of the centre columns 6..9 and rows 6..9 (u, v in [0.4, 0.6]).
Rgb centreMean(const Film& f) {
  Rgb s(0.0f);
  for (int y = 6; y < 10; ++y)
    for (int x = 6; x < 10; ++x) s += f.color[size_t(y) * size_t(f.width) + size_t(x)];
  return s * (1.0f / 16.0f);
}

const char* kDown = R"({"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]})";

}  // namespace

TEST_CASE("bump ramp h = b u on a quad: the analytic tilted normal and the rendered cosine") {
  std::string dir = test::makeTempDir();
  std::string tex = writeRamp(dir);
  // d(u) = b x 2 (u - 1/4) (bump scale b); dp/du = (2, 0, 0), dp/dv =
  // (0, 0, -2), n = +y: dp/du' = (2, 2 b, 0), so the surface rises b per
  // metre of x and ns = dp/du' x dp/dv / |.| = (-b, 1, 0) / sqrt(1 + b^2).
  for (float b : {0.5f, 1.0f}) {
    std::string mat = R"({"type": "diffuse", "color": [0.5, 0.5, 0.5], "bump": {"texture": "ramp", "scale": )" +
                      std::to_string(b) + "}}";
    scene::SceneDescription d = scene::parseScene(quadScene(tex, mat, kDown), dir + "/s.json");
    auto s = Scene::build(d);
    Hit hit;
    REQUIRE(s->intersect({0.1f, 1, 0.2f}, {0, -1, 0}, 10, 0, hit));
    Vec3f ns = s->shadingNormal(s->materials[s->objects[hit.object].material], hit);
    float k = 1.0f / std::sqrt(1 + b * b);
    CHECK(ns.x == doctest::Approx(-b * k).epsilon(1e-3));
    CHECK(ns.y == doctest::Approx(k).epsilon(1e-3));
    CHECK(std::fabs(ns.z) < 1e-4f);
    // Seen from above under light straight down: albedo / pi x cos(tilt).
    RenderOptions o = options(RenderMethod::PathTrace, 4, 2, 5);
    Rgb L = centreMean(test::renderOnce(d, o));
    CHECK(L.g == doctest::Approx(0.5f / kPi * k).epsilon(2e-3));
    // Light from the -x side at 45 degrees: along the tilted normal when b = 1.
    std::string side = R"({"type": "directional", "direction": [1, -1, 0], "irradiance": [1, 1, 1]})";
    scene::SceneDescription d2 = scene::parseScene(quadScene(tex, mat, side), dir + "/s.json");
    Rgb L2 = centreMean(test::renderOnce(d2, o));
    float cosSide = (b + 1) / std::sqrt(2.0f) * k;  // dot((-b, 1, 0) k, (-1, 1, 0) / sqrt 2)
    CHECK(L2.g == doctest::Approx(0.5f / kPi * cosSide).epsilon(2e-3));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("a constant (0.5, 0.5, 1) normal map leaves the image bit for bit unchanged") {
  std::string dir = test::makeTempDir();
  writeNormalMap(dir + "/flat.pfm", {0, 0, 1});
  // A sphere and a box on a floor under a sphere light: indirect light,
  // curved and flat surfaces, both sides of the map's frame.
  auto text = [&](bool map) {
    std::string nm = map ? R"(, "normal_map": "flat.pfm")" : "";
    return R"({"camera": {"position": [0, 2, 4], "target": [0, 0.5, 0], "fov": 40, "resolution": [16, 12]},
      "materials": {"floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6])" + nm + R"(},
                    "ball": {"type": "plastic", "color": [0.7, 0.3, 0.2], "roughness": 0.3)" + nm + R"(}},
      "objects": [{"shape": {"type": "quad", "size": [6, 6]}, "material": "floor"},
                  {"shape": {"type": "sphere", "radius": 0.5}, "material": "ball", "transform": {"translate": [0, 0.5, 0]}},
                  {"shape": {"type": "box", "size": [0.5, 0.5, 0.5]}, "material": "floor", "transform": {"translate": [1, 0.25, 0]}}],
      "lights": [{"type": "sphere", "radius": 0.3, "power": [200, 200, 200], "transform": {"translate": [0, 3, 1]}}]})";
  };
  scene::SceneDescription plain = scene::parseScene(text(false), dir + "/a.json");
  scene::SceneDescription mapped = scene::parseScene(text(true), dir + "/b.json");
  REQUIRE(mapped.materials[0].normalMap);
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Time}) {
    RenderOptions o = options(m, 4, 4, 9);
    Film a = test::renderOnce(plain, o), b = test::renderOnce(mapped, o);
    CHECK(test::imageSum(a) > 0);
    CHECK(test::sameImage(a, b));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("a normal map tilting by 30 degrees: the analytic normal and cosine") {
  std::string dir = test::makeTempDir();
  const float th = 30.0f * kPi / 180.0f;
  writeNormalMap(dir + "/tilt.pfm", {std::sin(th), 0, std::cos(th)});
  std::string mat = R"({"type": "diffuse", "color": [0.5, 0.5, 0.5], "normal_map": "tilt.pfm"})";
  scene::SceneDescription d = scene::parseScene(quadScene("{}", mat, kDown), dir + "/s.json");
  auto s = Scene::build(d);
  Hit hit;
  REQUIRE(s->intersect({0.1f, 1, 0.2f}, {0, -1, 0}, 10, 0, hit));
  // Frame x = dp/du = +x, z = n = +y: ns = sin x + cos y.
  Vec3f ns = s->shadingNormal(s->materials[0], hit);
  CHECK(ns.x == doctest::Approx(std::sin(th)).epsilon(1e-5));
  CHECK(ns.y == doctest::Approx(std::cos(th)).epsilon(1e-5));
  CHECK(std::fabs(ns.z) < 1e-5f);
  Rgb L = centreMean(test::renderOnce(d, options(RenderMethod::PathTrace, 4, 2, 5)));
  CHECK(L.g == doctest::Approx(0.5f / kPi * std::cos(th)).epsilon(2e-3));
  // The photon method sees the same cosine (its direct light is the path tracer's).
  Rgb P = centreMean(test::renderOnce(d, options(RenderMethod::Time, 4, 2, 5)));
  CHECK(P.g == doctest::Approx(0.5f / kPi * std::cos(th)).epsilon(2e-3));
  std::filesystem::remove_all(dir);
}

TEST_CASE("no light leaks through a bumped surface: light from below the geometric surface stays out") {
  std::string dir = test::makeTempDir();
  std::string tex = writeRamp(dir);
  // ns = (-1, 1, 0) / sqrt 2; the light comes from below (toward the light:
  // (-1, -0.3, 0)), inside the shading hemisphere but behind the quad.
  std::string mat = R"({"type": "diffuse", "color": [0.5, 0.5, 0.5], "bump": {"texture": "ramp", "scale": 1}})";
  std::string below = R"({"type": "directional", "direction": [1, 0.3, 0], "irradiance": [1, 1, 1]})";
  scene::SceneDescription d = scene::parseScene(quadScene(tex, mat, below), dir + "/s.json");
  auto s = Scene::build(d);
  Hit hit;
  REQUIRE(s->intersect({0, 1, 0}, {0, -1, 0}, 10, 0, hit));
  Vec3f wi = normalize(Vec3f(-1, -0.3f, 0));
  test::checkLightFromBelowStaysOut(d, *s, hit, wi);
  std::filesystem::remove_all(dir);
}

TEST_CASE("pbrt bumpmap / displacement / normalmap: imported, written by convert, the JSON renders the same pixels") {
  std::string dir = test::makeTempDir();
  image::ImageRgb img(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.at(x, y) = Rgb(0.1f * float(x * x + y));
  image::writePfm(dir + "/h.pfm", img);
  writeNormalMap(dir + "/n.pfm", normalize(Vec3f(0.3f, -0.2f, 1)));
  for (int v : {3, 4}) {
    std::string bump = v == 3 ? R"("texture bumpmap" "h")" : R"("texture displacement" "h")";
    std::string text = R"(LookAt 0 3 0  0 0 0  0 0 -1
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 12 "integer yresolution" 12
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "distant" "rgb L" [2 2 2] "point3 from" [0.3 1 0.2] "point3 to" [0 0 0]
Texture "h" "float" "imagemap" "string filename" "h.pfm" "float scale" 0.05
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5] )" + bump + R"(
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0 1  -1 0 1] "integer indices" [0 2 1 0 3 2]
  "point2 uv" [0 0  1 0  1 1  0 1]
AttributeBegin
Material "conductor" "float roughness" 0.2 "string normalmap" "n.pfm"
Translate 0 0.5 0
Shape "sphere" "float radius" 0.3
AttributeEnd
)";
    test::writeFile(dir + "/s.pbrt", text);
    pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
    scene::SceneDescription& d = r.scene;
    REQUIRE(d.objects.size() == 2);
    CHECK(d.materials[d.objects[0].material].bumpTexture == 0);
    CHECK(d.materials[d.objects[1].material].normalMap);
    std::filesystem::create_directories(dir + "/out");
    std::string json = dir + "/out/s.json";
    pbrt::writeSceneJson(d, json);
    std::ifstream in(json);
    std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(written.find("\"bump\": \"h\"") != std::string::npos);
    CHECK(written.find("\"normal_map\": \"../n.pfm\"") != std::string::npos);
    scene::SceneDescription back = scene::loadScene(json);
    CHECK(nlohmann::json::parse(pbrt::sceneToJson(back, "/x/s.json").json) ==
          nlohmann::json::parse(pbrt::sceneToJson(d, "/x/s.json").json));
    RenderOptions o = options(RenderMethod::PathTrace, 4, 4, 11);
    Film a = test::renderOnce(d, o), b = test::renderOnce(back, o);
    CHECK(test::sameImage(a, b));
    // And the bump changes the picture (the map is not silently dropped).
    scene::SceneDescription flat = d;
    for (auto& m : flat.materials) {
      m.bumpTexture = -1;
      m.normalMap.reset();
      m.normalMapFile.clear();
    }
    CHECK_FALSE(test::sameImage(a, test::renderOnce(flat, o)));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("bump and normal map bad input: located errors") {
  std::string dir = test::makeTempDir();
  std::string tex = writeRamp(dir);
  auto err = [&](const std::string& mat, const std::string& textures) {
    return test::errorMessageOf([&] { scene::parseScene(quadScene(textures, mat, kDown), dir + "/s.json"); });
  };
  auto has = [](const std::string& s, const std::string& part) {
    INFO(s);
    CHECK(s.find(part) != std::string::npos);
  };
  has(err(R"({"type": "diffuse", "bump": "nope"})", tex), "unknown texture \"nope\"");
  has(err(R"({"type": "diffuse", "normal_map": "missing.png"})", "{}"), "materials.m.normal_map");
  has(err(R"({"type": "diffuse", "bump": {"texture": "ramp", "scale": "x"}})", tex), "materials.m.bump.scale");
  has(err(R"({"type": "mix", "materials": ["a", "b"], "bump": "ramp"})", tex), "bump");
  std::string colour = R"({"c": {"type": "constant", "color": [1, 0, 0]}})";
  has(err(R"({"type": "diffuse", "bump": "c"})", colour), "float");
  // pbrt: a missing normal map names the file and the statement's place.
  test::writeFile(dir + "/bad.pbrt", "WorldBegin\nMaterial \"diffuse\" \"string normalmap\" \"gone.png\"\n"
                                     "Shape \"sphere\"\n");
  std::string e = test::errorMessageOf([&] { pbrt::importPbrtFile(dir + "/bad.pbrt"); });
  has(e, "bad.pbrt:2");
  has(e, "gone.png");
  // pbrt-v3's mix with a spectrum amount: mapped now (per channel, tests/test_textured_params.cpp),
  // the two materials swapped (pbrt-v3's amount weights the first); a bad name is still located.
  test::writeFile(dir + "/mix.pbrt", "WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\"\n"
                                     "MakeNamedMaterial \"a\" \"string type\" \"matte\"\n"
                                     "MakeNamedMaterial \"b\" \"string type\" \"mirror\"\n"
                                     "Material \"mix\" \"string materials\" [\"a\" \"b\"] "
                                     "\"texture amount\" \"c\"\nShape \"sphere\"\n");
  scene::SceneDescription mixed = pbrt::importPbrtFile(dir + "/mix.pbrt").scene;
  const scene::MaterialDesc& m = mixed.materials.back();
  CHECK(m.amountPerChannel);
  CHECK(mixed.materials.at(m.mix[0]).type == scene::MaterialDesc::Type::Mirror);
  test::writeFile(dir + "/mix2.pbrt", "WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"matte\"\n"
                                      "MakeNamedMaterial \"b\" \"string type\" \"mirror\"\n"
                                      "Material \"mix\" \"string materials\" [\"a\" \"b\"] "
                                      "\"texture amount\" \"c\"\nShape \"sphere\"\n");
  std::string em = test::errorMessageOf([&] { pbrt::importPbrtFile(dir + "/mix2.pbrt"); });
  has(em, "mix2.pbrt:4");
  has(em, "no texture named \"c\"");
  std::filesystem::remove_all(dir);
}
