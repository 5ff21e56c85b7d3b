// tests/test_textured_materials.cpp — the textured material parameters of
// issue 23's last texture gaps: a conductor's (and coated conductor's) eta
// and k, a coated conductor's reflectance, a mix's amount (per hit through
// Scene::materialAt), translucent's Kd / Ks / reflect. Each: a checkerboard
// whose two halves render exactly like the two constant scenes, the values
// per hit, the photon classification, the pbrt import, the convert round
// trip (same pixels) and located errors.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "texture_checks.h"
#include "error_capture.h"
#include "image/image.h"
#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

using test::texturedPlane;  // tests/texture_checks.h

// The material that the BSDF sees straight below (x, z), looking down.
Material shadedBelow(const Scene& s, float x, float z) {
  Hit h;
  REQUIRE(s.intersect({x, 3, z}, {0, -1, 0}, 100.0f, 0.0f, h));
  std::optional<Material> scratch;
  return s.shadedMaterial(s.materialAt(h, {0, 1, 0}), h, scratch);
}

using test::checkHalves;  // tests/texture_checks.h

using test::checkConvert;  // tests/texture_checks.h

const char* kCheckers = R"("eta": {"type": "checkerboard", "uscale": 2, "tex1": [0.2, 0.9, 1.1], "tex2": [1.5, 1.2, 0.5]},
    "k": {"type": "checkerboard", "uscale": 2, "tex1": [3.9, 2.4, 2.1], "tex2": [1.0, 2.0, 3.0]},
    "refl": {"type": "checkerboard", "uscale": 2, "tex1": [0.9, 0.5, 0.2], "tex2": [0.3, 0.6, 0.95]},
    "amt": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0.25, "tex2": 0.75},
    "kd": {"type": "checkerboard", "uscale": 2, "tex1": [0.7, 0.2, 0.1], "tex2": [0.1, 0.3, 0.8]})";

}  // namespace

TEST_CASE("textured conductor eta and k: each half renders as the constant conductor; values per hit") {
  std::string dir = test::makeTempDir();
  auto conductor = [&](const std::string& eta, const std::string& k) {
    return scene::parseScene(texturedPlane(kCheckers, R"("m": {"type": "conductor", "roughness": 0.3, "eta": )" + eta +
                                                  R"(, "k": )" + k + "}"),
                             dir + "/s.json");
  };
  scene::SceneDescription t = conductor("\"eta\"", "\"k\"");
  REQUIRE(t.materials[0].etaTexture >= 0);
  REQUIRE(t.materials[0].kTexture >= 0);
  auto s = Scene::build(t);
  Material left = shadedBelow(*s, -0.5f, 0.1f), right = shadedBelow(*s, 0.5f, 0.1f);
  CHECK(left.eta.r == 0.2f);
  CHECK(left.eta.b == 1.1f);
  CHECK(left.k.g == 2.4f);
  CHECK(right.eta.g == 1.2f);
  CHECK(right.k.b == 3.0f);
  CHECK(s->materials[0].isGlossy() == false);  // classification from the roughness alone (0.3)
  checkHalves(t, conductor("[0.2, 0.9, 1.1]", "[3.9, 2.4, 2.1]"), conductor("[1.5, 1.2, 0.5]", "[1.0, 2.0, 3.0]"));
  // One of the two textured alone.
  checkHalves(conductor("[0.2, 0.9, 1.1]", "\"k\""), conductor("[0.2, 0.9, 1.1]", "[3.9, 2.4, 2.1]"),
              conductor("[0.2, 0.9, 1.1]", "[1.0, 2.0, 3.0]"));
  // A texture value of 0 for eta (a division by zero in the Fresnel term): kept at 1e-3.
  scene::SceneDescription zero = scene::parseScene(
      texturedPlane(R"("z": {"type": "constant", "value": [0, 0.5, 0.5]}, "c": {"type": "checkerboard", "tex1": "z", "tex2": [1, 1, 1]})",
            R"("m": {"type": "conductor", "eta": "c", "k": [1, 1, 1]})"),
      dir + "/z.json");
  CHECK(shadedBelow(*Scene::build(zero), -0.5f, 0.1f).eta.r == 1e-3f);
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured coated conductor: reflectance and eta per hit relative to the coating; each half as the constant one") {
  std::string dir = test::makeTempDir();
  auto coated = [&](const std::string& ior) {
    return scene::parseScene(texturedPlane(kCheckers, R"("m": {"type": "coatedconductor", "roughness": 0.2, "ior": 1.5, )" + ior + "}"),
                             dir + "/s.json");
  };
  scene::SceneDescription t = coated(R"("color": "refl")");
  auto s = Scene::build(t);
  Material left = shadedBelow(*s, -0.5f, 0.1f);
  CHECK(left.eta.r == doctest::Approx(1 / 1.5f).epsilon(1e-6));
  CHECK(left.k.r == doctest::Approx(2 * std::sqrt(0.9f) / std::sqrt(0.1f) / 1.5f).epsilon(1e-5));
  checkHalves(t, coated(R"("color": [0.9, 0.5, 0.2])"), coated(R"("color": [0.3, 0.6, 0.95])"));
  scene::SceneDescription e = coated(R"("eta": "eta", "k": [3, 2, 1])");
  CHECK(shadedBelow(*Scene::build(e), 0.5f, 0.1f).eta.g == doctest::Approx(1.2f / 1.5f).epsilon(1e-6));
  checkHalves(e, coated(R"("eta": [0.2, 0.9, 1.1], "k": [3, 2, 1])"), coated(R"("eta": [1.5, 1.2, 0.5], "k": [3, 2, 1])"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured mix amount: the choice per hit follows the texture there; each half renders as the constant mix") {
  std::string dir = test::makeTempDir();
  const std::string parts = R"("red": {"type": "diffuse", "color": [0.8, 0.1, 0.1]}, "blue": {"type": "diffuse", "color": [0.1, 0.2, 0.8]}, )";
  auto mix = [&](const std::string& amount, const std::string& textures = "") {
    return scene::parseScene(texturedPlane(std::string(kCheckers) + textures, parts + R"("m": {"type": "mix", "materials": ["red", "blue"], "amount": )" +
                                                             amount + "}"),
                             dir + "/s.json");
  };
  scene::SceneDescription t = mix("\"amt\"");
  auto s = Scene::build(t);
  const Material& m = s->materials[s->objects[0].material];
  REQUIRE(m.amountTexture >= 0);
  // The fraction of hits that choose "blue" (the second) is the texture's value at the hit.
  for (float x : {-0.5f, 0.5f}) {
    Hit h;
    REQUIRE(s->intersect({x, 3, 0.1f}, {0, -1, 0}, 100.0f, 0.0f, h));
    const int n = 20000;
    int blue = 0;
    for (int i = 0; i < n; ++i) {
      float a = 0.001f * float(i);
      const Material& c = s->materialAt(h, normalize(Vec3f{std::cos(a), 2.0f, std::sin(a)}));
      blue += c.albedo.a.b > 0.5f;
    }
    double want = x < 0 ? 0.25 : 0.75, sd = std::sqrt(want * (1 - want) / n);
    CHECK(std::fabs(double(blue) / n - want) < 4 * sd);
  }
  checkHalves(t, mix("0.25"), mix("0.75"));
  // Amounts 0 and 1 on the two halves: exactly one component each, as pbrt-v4.
  const std::string ends = R"(, "ends": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0, "tex2": 1})";
  checkHalves(mix("\"ends\"", ends), mix("0"), mix("1"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured mix amount: photon classification from the components, whatever the amount's range") {
  std::string dir = test::makeTempDir();
  auto build = [&](const std::string& b) {
    return Scene::build(scene::parseScene(
        texturedPlane(kCheckers, R"("d": {"type": "diffuse"}, "b": )" + b + R"(, "m": {"type": "mix", "materials": ["d", "b"], "amount": "amt"})"),
        dir + "/s.json"));
  };
  {  // A mirror component: a caustic target of both maps.
    auto s = build(R"({"type": "mirror"})");
    const Material& m = s->materials[s->objects[0].material];
    CHECK(m.causticTarget(false));
    CHECK(m.causticTarget(true));
  }
  {  // A sharp conductor: a glossy caustic target only.
    auto s = build(R"({"type": "conductor", "eta": [0.2, 0.9, 1.1], "k": "k", "roughness": 0.1})");
    const Material& m = s->materials[s->objects[0].material];
    CHECK(!m.causticTarget(false));
    CHECK(m.causticTarget(true));
  }
  {  // Two diffuse components: no target.
    auto s = build(R"({"type": "diffuse", "color": [0.1, 0.1, 0.1]})");
    CHECK(!s->materials[s->objects[0].material].causticTarget(true));
  }
  std::filesystem::remove_all(dir);
}

namespace {

// The plane's textures and named materials (tests/texture_checks.h pbrtPlane).
const std::string kPbrtDefs =
    "Texture \"kd\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [0.7 0.2 0.1] \"rgb tex2\" [0.1 0.3 0.8]\n"
    "Texture \"refl\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [0.9 0.5 0.2] \"rgb tex2\" [0.3 0.6 0.95]\n"
    "Texture \"e\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [0.2 0.9 1.1] \"rgb tex2\" [1.5 1.2 0.5]\n"
    "Texture \"amt\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0.25 \"float tex2\" 0.75\n"
    "MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0.1 0.1]\n"
    "MakeNamedMaterial \"blue\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.8]\n";

std::string pbrtPlane(const std::string& body) { return test::pbrtPlane(kPbrtDefs, body); }
using test::importText;
void checkPbrtHalves(const std::string& textured, const std::string& tex1, const std::string& tex2) {
  test::checkPbrtHalves(kPbrtDefs, textured, tex1, tex2);
}

}  // namespace

TEST_CASE("pbrt: textured conductor eta / k, coatedconductor reflectance, mix amount, translucent Kd / Ks / reflect") {
  // conductor (pbrt-v4) and metal (pbrt-v3): eta and k SpectrumTextures.
  checkPbrtHalves(R"(Material "conductor" "texture eta" "e" "rgb k" [3 2 1] "float roughness" 0.1)",
                  R"(Material "conductor" "rgb eta" [0.2 0.9 1.1] "rgb k" [3 2 1] "float roughness" 0.1)",
                  R"(Material "conductor" "rgb eta" [1.5 1.2 0.5] "rgb k" [3 2 1] "float roughness" 0.1)");
  checkPbrtHalves(R"(Material "metal" "rgb eta" [0.2 0.9 1.1] "texture k" "e" "float roughness" 0.05)",
                  R"(Material "metal" "rgb eta" [0.2 0.9 1.1] "rgb k" [0.2 0.9 1.1] "float roughness" 0.05)",
                  R"(Material "metal" "rgb eta" [0.2 0.9 1.1] "rgb k" [1.5 1.2 0.5] "float roughness" 0.05)");
  checkPbrtHalves(R"(Material "coatedconductor" "texture reflectance" "refl" "float interface.roughness" 0.1)",
                  R"(Material "coatedconductor" "rgb reflectance" [0.9 0.5 0.2] "float interface.roughness" 0.1)",
                  R"(Material "coatedconductor" "rgb reflectance" [0.3 0.6 0.95] "float interface.roughness" 0.1)");
  checkPbrtHalves(R"(Material "coatedconductor" "texture conductor.eta" "e" "rgb conductor.k" [3 2 1])",
                  R"(Material "coatedconductor" "rgb conductor.eta" [0.2 0.9 1.1] "rgb conductor.k" [3 2 1])",
                  R"(Material "coatedconductor" "rgb conductor.eta" [1.5 1.2 0.5] "rgb conductor.k" [3 2 1])");
  checkPbrtHalves(R"(Material "mix" "string materials" ["red" "blue"] "texture amount" "amt")",
                  R"(Material "mix" "string materials" ["red" "blue"] "float amount" 0.25)",
                  R"(Material "mix" "string materials" ["red" "blue"] "float amount" 0.75)");
  // translucent: Kd x reflect and Ks x reflect, each textured or not.
  checkPbrtHalves(R"(Material "translucent" "texture Kd" "kd" "rgb Ks" [0.5 0.5 0.5] "rgb reflect" [0.8 0.7 0.6])",
                  R"(Material "translucent" "rgb Kd" [0.7 0.2 0.1] "rgb Ks" [0.5 0.5 0.5] "rgb reflect" [0.8 0.7 0.6])",
                  R"(Material "translucent" "rgb Kd" [0.1 0.3 0.8] "rgb Ks" [0.5 0.5 0.5] "rgb reflect" [0.8 0.7 0.6])");
  checkPbrtHalves(R"(Material "translucent" "rgb Kd" [0.5 0.5 0.5] "texture Ks" "kd" "float roughness" 0.05)",
                  R"(Material "translucent" "rgb Kd" [0.5 0.5 0.5] "rgb Ks" [0.7 0.2 0.1] "float roughness" 0.05)",
                  R"(Material "translucent" "rgb Kd" [0.5 0.5 0.5] "rgb Ks" [0.1 0.3 0.8] "float roughness" 0.05)");
  checkPbrtHalves(R"(Material "translucent" "rgb Kd" [0.6 0.6 0.6] "texture reflect" "refl" "texture transmit" "kd")",
                  R"(Material "translucent" "rgb Kd" [0.6 0.6 0.6] "rgb reflect" [0.9 0.5 0.2])",
                  R"(Material "translucent" "rgb Kd" [0.6 0.6 0.6] "rgb reflect" [0.3 0.6 0.95])");
}

TEST_CASE("convert: textured eta, k, coated reflectance, mix amount, translucent lobes, v3 RGB scales: the JSON renders the same pixels") {
  std::string dir = test::makeTempDir();
  std::string text = pbrtPlane(R"(Material "conductor" "texture eta" "e" "texture k" "refl" "float roughness" 0.1)") +
                     R"(AttributeBegin
Translate 0 0.2 0
Material "coatedconductor" "texture reflectance" "refl" "texture conductor.roughness" "amt"
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Translate 0.5 0.2 0.5
Material "mix" "string materials" ["red" "blue"] "texture amount" "amt"
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Translate -0.5 0.2 -0.5
Material "translucent" "texture Kd" "kd" "texture Ks" "refl" "texture reflect" "refl"
Shape "sphere" "float radius" 0.3
AttributeEnd
Texture "v3a" "spectrum" "scale" "texture tex1" "kd" "rgb tex2" [0.5 1 0.8]
Texture "v3b" "spectrum" "scale" "texture tex1" "kd" "texture tex2" "refl"
AttributeBegin
Translate 0.5 0.2 -0.5
Material "matte" "texture Kd" "v3a"
Shape "sphere" "float radius" 0.2
AttributeEnd
AttributeBegin
Translate -0.5 0.2 0.5
Material "matte" "texture Kd" "v3b"
Shape "sphere" "float radius" 0.2
AttributeEnd
)";
  test::writeFile(dir + "/s.pbrt", text);
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  std::string written = checkConvert(r.scene, dir + "/s.json");
  CHECK(contains(written, "\"eta\": \"e\""));
  CHECK(contains(written, "\"k\": \"refl\""));
  CHECK(contains(written, "\"amount\": \"amt\""));
  CHECK(contains(written, "\"color\": \"refl\""));  // the coated conductor's reflectance
  CHECK(contains(written, "x reflect\""));          // translucent's lobes: scale textures
  // pbrt-v3's scale of two spectrum inputs keeps its RGB (it was written as
  // one float: v3a rendered other pixels, v3b's JSON did not load).
  CHECK(contains(written, "\"scale\": \"refl\""));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured eta, k, amount: bad input gets located errors") {
  std::string dir = test::makeTempDir();
  auto json = [&](const std::string& material) {
    return test::errorMessageOf([&] { scene::parseScene(texturedPlane(kCheckers, R"("m": )" + material), dir + "/s.json"); });
  };
  CHECK(contains(json(R"({"type": "conductor", "eta": "amt", "k": [1, 1, 1]})"),
                 "materials.m.eta: texture \"amt\" is a float texture, but a spectrum (RGB) one is expected here"));
  CHECK(contains(json(R"({"type": "coatedconductor", "eta": [1, 1, 1], "k": "nope"})"), "materials.m.k: unknown texture \"nope\""));
  CHECK(contains(json(R"({"type": "mix", "materials": ["m", "m"], "amount": "nope"})"), "materials.m.amount: unknown texture \"nope\""));
  auto pbrtError = [&](const std::string& body) {
    return test::errorMessageOf([&] { importText(pbrtPlane(body)); });
  };
  CHECK(contains(pbrtError(R"(Material "conductor" "texture eta" "amt")"),
                 "texture \"amt\" is a float texture, but a conductor's eta needs a spectrum one"));
  CHECK(contains(pbrtError(R"(Material "coatedconductor" "texture conductor.k" "amt")"),
                 "texture \"amt\" is a float texture, but a conductor's k needs a spectrum one"));
  CHECK(contains(pbrtError(R"(Material "mix" "string materials" ["red" "blue"] "texture amount" "nope")"),
                 "no texture named \"nope\" has been defined"));
  CHECK(contains(pbrtError(R"(Material "translucent" "texture reflect" "amt")"),
                 "texture \"amt\" is a float texture, but a reflectance needs a spectrum one"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("parseScene with an ImageSource: texture images and environment maps lent by the caller, not read from files") {
  const std::string text = R"({"camera": {"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "resolution": [4, 4]},
    "textures": {"t": {"type": "image", "file": "not-there.pfm", "encoding": "linear"}},
    "materials": {"m": {"type": "diffuse", "texture": "t"}},
    "objects": [], "lights": [{"type": "environment", "filename": "no-map.exr"}]})";
  auto lent = std::make_shared<const image::ImageRgb>(2, 1);
  std::vector<std::string> asked;
  scene::ImageSource images = [&](const std::string& file, const std::string& key) {
    asked.push_back(file + " " + key);
    return lent;
  };
  scene::MeshSource meshes = [](const std::string&, std::vector<Vec3f>*, std::vector<uint32_t>*) { return false; };
  scene::SceneDescription d = scene::parseScene(text, "dir/s.json", meshes, images);
  REQUIRE(asked.size() == 2);
  CHECK(asked[0] == "dir/not-there.pfm linear");
  CHECK(asked[1] == "dir/no-map.exr environment latlong");
  CHECK(d.textures[0].image == lent);
  CHECK(d.lights[0].map == lent);
  // Without one, the same text reads the files: a located error for the missing one.
  CHECK(contains(test::errorMessageOf([&] { scene::parseScene(text, "dir/s.json"); }), "not-there.pfm"));
}

TEST_CASE("textured ior (rough dielectric, uber; pbrt-v3 glass and uber eta): each half as the constant ior; range checked") {
  std::string dir = test::makeTempDir();
  const std::string iors = R"(, "ior": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 1.2, "tex2": 2.0},
    "low": {"type": "checkerboard", "float": true, "tex1": 0.9, "tex2": 1.5})";
  auto material = [&](const std::string& m) {
    return scene::parseScene(texturedPlane(std::string(kCheckers) + iors, R"("m": )" + m), dir + "/s.json");
  };
  scene::SceneDescription t = material(R"({"type": "dielectric", "roughness": 0.3, "ior": "ior"})");
  auto s = Scene::build(t);
  CHECK(shadedBelow(*s, -0.5f, 0.1f).ior == 1.2f);
  CHECK(shadedBelow(*s, 0.5f, 0.1f).ior == 2.0f);
  checkHalves(t, material(R"({"type": "dielectric", "roughness": 0.3, "ior": 1.2})"),
              material(R"({"type": "dielectric", "roughness": 0.3, "ior": 2.0})"));
  checkHalves(material(R"({"type": "uber", "specular": [0.8, 0.8, 0.8], "roughness": 0.1, "ior": "ior"})"),
              material(R"({"type": "uber", "specular": [0.8, 0.8, 0.8], "roughness": 0.1, "ior": 1.2})"),
              material(R"({"type": "uber", "specular": [0.8, 0.8, 0.8], "roughness": 0.1, "ior": 2.0})"));
  // Values below 1: refused when built; a textured ior elsewhere: refused when read.
  scene::SceneDescription low = material(R"({"type": "dielectric", "ior": "low"})");
  CHECK(contains(test::errorMessageOf([&] { Scene::build(low); }), "material \"m\": its ior texture's values [0.9"));
  CHECK(contains(test::errorMessageOf([&] { material(R"({"type": "plastic", "ior": "ior"})"); }),
                 "materials.m.ior: a textured ior is supported on dielectric and uber only"));
  // pbrt-v3: glass eta and uber index as FloatTextures.
  const std::string tex = "Texture \"i\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 1.2 \"float tex2\" 2\n";
  checkPbrtHalves(tex + R"(Material "glass" "texture eta" "i" "float roughness" 0.1)",
                  R"(Material "glass" "float eta" 1.2 "float roughness" 0.1)", R"(Material "glass" "float eta" 2 "float roughness" 0.1)");
  checkPbrtHalves(tex + R"(Material "uber" "texture index" "i")", R"(Material "uber" "float index" 1.2)",
                  R"(Material "uber" "float index" 2)");
  test::writeFile(dir + "/g.pbrt", pbrtPlane(tex + R"(Material "glass" "texture eta" "i" "float roughness" 0.1)"));
  CHECK(contains(checkConvert(pbrt::importPbrtFile(dir + "/g.pbrt").scene, dir + "/g.json"), "\"ior\": \"i\""));
  std::filesystem::remove_all(dir);
}
