// tests/test_textured_params.cpp — the last three textured material
// parameters of issue 23: matte's Oren-Nayar sigma (pbrt-v3), a coating's
// thickness (pbrt-v4 coateddiffuse / coatedconductor) and pbrt-v3's
// per-channel (RGB) mix amount. Each: a constant texture renders bit for
// bit as the constant parameter; a two-value checkerboard renders each half
// exactly as the constant scene of that value; the pbrt import and the
// convert round trip; located errors. The per-channel mix also: its
// expectation per channel against the two materials alone, path traced
// and with photons (a statistical bound, fixed seeds).
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
#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/bsdf.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

using test::texturedPlane;  // tests/texture_checks.h

const char* kTextures = R"("sig": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0, "tex2": 25},
    "sig20": {"type": "constant", "float": true, "value": 20},
    "thick": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0.01, "tex2": 0.6},
    "thick03": {"type": "constant", "float": true, "value": 0.3},
    "amt": {"type": "checkerboard", "uscale": 2, "tex1": [0.9, 0.2, 0.1], "tex2": [0.1, 0.5, 0.8]},
    "amtc": {"type": "constant", "value": [0.7, 0.3, 0.1]},
    "famt": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0.25, "tex2": 0.75})";
const char* kParts = R"("red": {"type": "diffuse", "color": [0.8, 0.1, 0.1]}, "blue": {"type": "diffuse", "color": [0.1, 0.2, 0.8]}, )";

scene::SceneDescription jsonScene(const std::string& material, const std::string& dir) {
  return scene::parseScene(texturedPlane(kTextures, std::string(kParts) + R"("m": )" + material), dir + "/s.json");
}

RenderOptions pathOptions(int spp = 4, uint64_t seed = 5) { return test::smallRenderOptions(RenderMethod::PathTrace, spp, 3, seed); }

using test::checkHalves;  // tests/texture_checks.h

void checkSame(const scene::SceneDescription& a, const scene::SceneDescription& b) {
  Film fa = test::renderOnce(a, pathOptions()), fb = test::renderOnce(b, pathOptions());
  CHECK(test::sameImage(fa, fb));
  CHECK(test::imageSum(fa) > 0);
}

using test::checkConvert;  // tests/texture_checks.h

// The material named "m" (the JSON's materials are read in name order).
const scene::MaterialDesc& materialM(const scene::SceneDescription& d) {
  for (const scene::MaterialDesc& m : d.materials)
    if (m.name == "m") return m;
  FAIL("no material m");
  return d.materials[0];
}
const Material& builtM(const Scene& s, const scene::SceneDescription& d) {
  return s.materials[size_t(&materialM(d) - d.materials.data())];
}

// The image's mean per channel.
Rgb meanOf(const Film& f) {
  double s[3] = {0, 0, 0};
  for (const Rgb& c : f.color)
    for (int i = 0; i < 3; ++i) s[i] += c[i];
  double n = double(f.color.size());
  return {float(s[0] / n), float(s[1] / n), float(s[2] / n)};
}

}  // namespace

TEST_CASE("Oren-Nayar (matte sigma): pbrt-v3's A, B and f at known angles; cosine-sampled, weight consistent with f / pdf") {
  float A, B;
  orenNayarAB(20.0f, &A, &B);
  double s = 20.0 * M_PI / 180.0, s2 = s * s;
  CHECK(A == doctest::Approx(1.0 - s2 / (2.0 * (s2 + 0.33))).epsilon(1e-6));
  CHECK(B == doctest::Approx(0.45 * s2 / (s2 + 0.09)).epsilon(1e-6));
  orenNayarAB(0.0f, &A, &B);
  CHECK(A == 1.0f);
  CHECK(B == 0.0f);
  orenNayarAB(120.0f, &A, &B);  // clamped to 90, as pbrt-v3
  float A90, B90;
  orenNayarAB(90.0f, &A90, &B90);
  CHECK(A == A90);
  CHECK(B == B90);

  Material m;
  m.type = Material::Type::OrenNayar;
  orenNayarAB(20.0f, &m.orenA, &m.orenB);
  const Rgb albedo(0.6f);
  const float th = float(M_PI / 3);  // 60 degrees
  Vec3f w{std::sin(th), 0, std::cos(th)};
  // Local frame about +z: wo = wi = w (phi equal: cos = 1; alpha = beta = 60).
  ShadingContext c = makeShadingContext(m, albedo, {0, 0, 1}, w);
  Rgb f = bsdfEval(c, w);
  CHECK(f.r == doctest::Approx(0.6 / M_PI * (m.orenA + m.orenB * std::sin(th) * std::tan(th))).epsilon(1e-5));
  // Opposite azimuths: max(0, cos) = 0, f = R / pi * A.
  Vec3f w2{-std::sin(th), 0, std::cos(th)};
  CHECK(bsdfEval(c, w2).g == doctest::Approx(0.6 / M_PI * m.orenA).epsilon(1e-5));
  CHECK(bsdfPdf(c, w2) == doctest::Approx(std::cos(th) / M_PI).epsilon(1e-5));
  // A sample's weight is f cos / pdf.
  BsdfSample bs;
  REQUIRE(bsdfSample(c, {0.3f, 0.7f}, 0.5f, Transport::Radiance, bs));
  Vec3f wi = bs.wi;
  CHECK(bs.pdf == doctest::Approx(bsdfPdf(c, wi)).epsilon(1e-5));
  CHECK(bs.weight.r == doctest::Approx(bsdfEval(c, wi).r * wi.z / bs.pdf).epsilon(1e-5));
  // Albedo below Lambert's (energy lost to inter-reflection is what A < 1 models): the
  // hemispherical reflectance at normal incidence is R A (f = R / pi A there for every wi).
  ShadingContext n = makeShadingContext(m, albedo, {0, 0, 1}, {0, 0, 1});
  double sum = 0;
  const int N = 256;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      BsdfSample q;
      if (bsdfSample(n, {(i + 0.5f) / N, (j + 0.5f) / N}, 0.5f, Transport::Radiance, q)) sum += q.weight.r;
    }
  CHECK(sum / (N * N) == doctest::Approx(0.6 * m.orenA).epsilon(1e-4));
}

TEST_CASE("textured matte sigma: a constant texture as the constant sigma, bit for bit; each checker half as its constant") {
  std::string dir = test::makeTempDir();
  auto diffuse = [&](const std::string& sigma) {
    return jsonScene(R"({"type": "diffuse", "color": [0.7, 0.5, 0.3], "sigma": )" + sigma + "}", dir);
  };
  scene::SceneDescription t = diffuse("\"sig\"");
  REQUIRE(materialM(t).sigmaTexture >= 0);
  auto s = Scene::build(t);
  CHECK(builtM(*s, t).type == Material::Type::OrenNayar);
  scene::SceneDescription zero = diffuse("0");
  CHECK(builtM(*Scene::build(zero), zero).type == Material::Type::Diffuse);  // sigma 0: Lambert's own path
  checkSame(diffuse("\"sig20\""), diffuse("20"));
  checkHalves(t, diffuse("0"), diffuse("25"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured coating thickness: constant texture bit for bit; each checker half as its constant (coateddiffuse, coatedconductor)") {
  std::string dir = test::makeTempDir();
  auto coated = [&](const std::string& thickness) {
    return jsonScene(R"({"type": "coateddiffuse", "color": [0.7, 0.5, 0.3], "roughness": 0.1, "thickness": )" + thickness + "}", dir);
  };
  scene::SceneDescription t = coated("\"thick\"");
  REQUIRE(materialM(t).thicknessTexture >= 0);
  checkSame(coated("\"thick03\""), coated("0.3"));
  checkHalves(t, coated("0.01"), coated("0.6"));
  auto conductor = [&](const std::string& thickness) {
    return jsonScene(R"({"type": "coatedconductor", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.1], "conductor_roughness": 0.3, "thickness": )" +
                         thickness + "}",
                     dir);
  };
  checkSame(conductor("\"thick03\""), conductor("0.3"));
  checkHalves(conductor("\"thick\""), conductor("0.01"), conductor("0.6"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("per-channel mix amount: a constant RGB texture as the RGB constant; each checker half as its constant; [1,1,1] is the second alone") {
  std::string dir = test::makeTempDir();
  auto mix = [&](const std::string& amount) {
    return jsonScene(R"({"type": "mix", "materials": ["red", "blue"], "amount": )" + amount + "}", dir);
  };
  scene::SceneDescription t = mix("\"amt\"");
  REQUIRE(materialM(t).amountPerChannel);
  checkSame(mix("\"amtc\""), mix("[0.7, 0.3, 0.1]"));
  checkHalves(t, mix("[0.9, 0.2, 0.1]"), mix("[0.1, 0.5, 0.8]"));
  checkSame(mix("[1, 1, 1]"), jsonScene(R"({"type": "diffuse", "color": [0.1, 0.2, 0.8]})", dir));
  checkSame(mix("[0, 0, 0]"), jsonScene(R"({"type": "diffuse", "color": [0.8, 0.1, 0.1]})", dir));
  // A float texture keeps the stochastic choice (pbrt-v4's FloatTexture amount).
  CHECK(!materialM(mix("\"famt\"")).amountPerChannel);
  std::filesystem::remove_all(dir);
}

TEST_CASE("per-channel mix amount (1, 0, 0), path traced: red from the second material, green and blue from the first") {
  std::string dir = test::makeTempDir();
  // First "blue" (0.1, 0.2, 0.8), second "red" (0.8, 0.1, 0.1): the blend is (0.8, 0.2, 0.8).
  scene::SceneDescription m = jsonScene(R"({"type": "mix", "materials": ["blue", "red"], "amount": [1, 0, 0]})", dir);
  const int spp = 64;
  Film f = test::renderOnce(m, pathOptions(spp, 7));
  Rgb got = meanOf(f);
  Rgb first = meanOf(test::renderOnce(jsonScene(R"({"type": "diffuse", "color": [0.1, 0.2, 0.8]})", dir), pathOptions(spp, 7)));
  Rgb second = meanOf(test::renderOnce(jsonScene(R"({"type": "diffuse", "color": [0.8, 0.1, 0.1]})", dir), pathOptions(spp, 7)));
  // The constant renders are deterministic here (a directional light, one
  // plane); the mix picks the second with p = 1/3, weighted 3 in red, else
  // the first weighted 1.5 in green and blue: per sample a Bernoulli, so
  // the image mean's relative sd is sqrt((1 - p) / (p n)) over n samples.
  const double n = double(spp) * 16 * 16;
  const double sdRed = std::sqrt(2.0 / n), sdGreenBlue = std::sqrt(0.5 / n);
  INFO("got " << got.r << " " << got.g << " " << got.b << ", want " << second.r << " " << first.g << " " << first.b);
  CHECK(std::fabs(got.r / second.r - 1) < 4 * sdRed);
  CHECK(std::fabs(got.g / first.g - 1) < 4 * sdGreenBlue);
  CHECK(std::fabs(got.b / first.b - 1) < 4 * sdGreenBlue);
  // The components really differ in each channel (the test can fail).
  CHECK(std::fabs(first.r / second.r - 1) > 20 * sdRed);
  CHECK(std::fabs(first.g / second.g - 1) > 20 * sdGreenBlue);
  std::filesystem::remove_all(dir);
}

namespace {

// A white ceiling over a floor of material "m", a point light between
// them; the camera sees both, the ceiling lit mostly by the floor's bounce
// (photons that scattered off the mix).
std::string room(const std::string& floor) {
  return R"({"camera": {"position": [0, 0.5, 2.2], "target": [0, 0.5, 0], "fov": 60, "resolution": [24, 24]},
    "materials": {"red": {"type": "diffuse", "color": [0.8, 0.1, 0.1]}, "blue": {"type": "diffuse", "color": [0.1, 0.2, 0.8]},
                  "white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}, "m": )" + floor + R"(},
    "objects": [{"shape": {"type": "quad", "size": [3, 3]}, "material": "m"},
                {"shape": {"type": "quad", "size": [3, 3]}, "material": "white", "transform": {"translate": [0, 1, 0]}}],
    "lights": [{"type": "point", "position": [0, 0.3, 0], "power": [20, 20, 20]}]})";
}

// The top and bottom halves' means (ceiling, floor).
void halves(const Film& f, Rgb* top, Rgb* bottom) {
  double s[2][3] = {};
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int i = 0; i < 3; ++i) s[y < f.height / 2][i] += f.color[f.index(x, y)][i];
  double n = double(f.width) * f.height / 2;
  *top = {float(s[1][0] / n), float(s[1][1] / n), float(s[1][2] / n)};
  *bottom = {float(s[0][0] / n), float(s[0][1] / n), float(s[0][2] / n)};
}

}  // namespace

TEST_CASE("per-channel mix amount (1, 0, 0) with photons: the ceiling lit by the mix floor's photons, per channel as each material alone") {
  std::string dir = test::makeTempDir();
  RenderOptions o;
  o.method = RenderMethod::Standard;
  o.spp = 16;
  o.maxSpp = 16;
  o.seed = 3;
  o.causticPhotons = 0;
  o.globalPhotons = 200000;
  o.visualizeGlobal = true;  // the global map's estimate at the first hit: every bounce's light through photons
  o.estimate.k = 200;
  auto load = [&](const std::string& floor) { return scene::parseScene(room(floor), dir + "/r.json"); };
  Rgb topMix, bottomMix, topFirst, bottomFirst, topSecond, bottomSecond;
  // As the path-traced test: first "blue", second "red", the blend (0.8, 0.2, 0.8).
  halves(test::renderOnce(load(R"({"type": "mix", "materials": ["blue", "red"], "amount": [1, 0, 0]})"), o), &topMix, &bottomMix);
  halves(test::renderOnce(load(R"({"type": "diffuse", "color": [0.1, 0.2, 0.8]})"), o), &topFirst, &bottomFirst);
  halves(test::renderOnce(load(R"({"type": "diffuse", "color": [0.8, 0.1, 0.1]})"), o), &topSecond, &bottomSecond);
  INFO("ceiling: mix " << topMix.r << " " << topMix.g << " " << topMix.b << "; first " << topFirst.r << " " << topFirst.g
                       << " " << topFirst.b << "; second " << topSecond.r << " " << topSecond.g << " " << topSecond.b);
  INFO("floor: mix " << bottomMix.r << " " << bottomMix.g << " " << bottomMix.b << "; first " << bottomFirst.r << " "
                     << bottomFirst.g << " " << bottomFirst.b << "; second " << bottomSecond.r << " " << bottomSecond.g << " "
                     << bottomSecond.b);
  const double tol = 0.04;  // relative; measured at this seed: within 1.2% in every channel of both halves
  CHECK(std::fabs(topMix.r / topSecond.r - 1) < tol);
  CHECK(std::fabs(topMix.g / topFirst.g - 1) < tol);
  CHECK(std::fabs(topMix.b / topFirst.b - 1) < tol);
  CHECK(std::fabs(bottomMix.r / bottomSecond.r - 1) < tol);
  CHECK(std::fabs(bottomMix.g / bottomFirst.g - 1) < tol);
  CHECK(std::fabs(bottomMix.b / bottomFirst.b - 1) < tol);
  // The two floors light the ceiling differently in each channel, by far more than tol.
  CHECK(std::fabs(topFirst.r / topSecond.r - 1) > 5 * tol);
  CHECK(std::fabs(topFirst.b / topSecond.b - 1) > 5 * tol);
  std::filesystem::remove_all(dir);
}

namespace {

// The plane's textures and named materials (tests/texture_checks.h pbrtPlane).
const std::string kPbrtDefs =
    "Texture \"sig\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0 \"float tex2\" 25\n"
    "Texture \"thick\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0.01 \"float tex2\" 0.6\n"
    "Texture \"amt\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [0.9 0.2 0.1] \"rgb tex2\" [0.1 0.5 0.8]\n"
    "MakeNamedMaterial \"red\" \"string type\" \"matte\" \"rgb Kd\" [0.8 0.1 0.1]\n"
    "MakeNamedMaterial \"blue\" \"string type\" \"matte\" \"rgb Kd\" [0.1 0.2 0.8]\n";

std::string pbrtPlane(const std::string& body) { return test::pbrtPlane(kPbrtDefs, body); }
using test::importText;
void checkPbrtHalves(const std::string& textured, const std::string& tex1, const std::string& tex2) {
  test::checkPbrtHalves(kPbrtDefs, textured, tex1, tex2);
}

}  // namespace

TEST_CASE("pbrt: textured matte sigma, coating thickness, pbrt-v3 RGB mix amount; each checker half as the constant") {
  checkPbrtHalves(R"(Material "matte" "rgb Kd" [0.7 0.5 0.3] "texture sigma" "sig")",
                  R"(Material "matte" "rgb Kd" [0.7 0.5 0.3] "float sigma" 0)",
                  R"(Material "matte" "rgb Kd" [0.7 0.5 0.3] "float sigma" 25)");
  checkPbrtHalves(R"(Material "coateddiffuse" "rgb reflectance" [0.7 0.5 0.3] "texture thickness" "thick")",
                  R"(Material "coateddiffuse" "rgb reflectance" [0.7 0.5 0.3] "float thickness" 0.01)",
                  R"(Material "coateddiffuse" "rgb reflectance" [0.7 0.5 0.3] "float thickness" 0.6)");
  checkPbrtHalves(R"(Material "coatedconductor" "float conductor.roughness" 0.3 "texture thickness" "thick")",
                  R"(Material "coatedconductor" "float conductor.roughness" 0.3 "float thickness" 0.01)",
                  R"(Material "coatedconductor" "float conductor.roughness" 0.3 "float thickness" 0.6)");
  checkPbrtHalves(R"(Material "mix" "string materials" ["red" "blue"] "texture amount" "amt")",
                  R"(Material "mix" "string materials" ["red" "blue"] "rgb amount" [0.9 0.2 0.1])",
                  R"(Material "mix" "string materials" ["red" "blue"] "rgb amount" [0.1 0.5 0.8])");
  // pbrt-v3's amount weights the FIRST material: amount 1 is "red" alone, 0 "blue" alone.
  checkSame(importText(pbrtPlane(R"(Material "mix" "string materials" ["red" "blue"] "rgb amount" [1 1 1])")),
            importText(pbrtPlane(R"(Material "matte" "rgb Kd" [0.8 0.1 0.1])")));
  checkSame(importText(pbrtPlane(R"(Material "mix" "string materials" ["red" "blue"] "rgb amount" [0 0 0])")),
            importText(pbrtPlane(R"(Material "matte" "rgb Kd" [0.1 0.2 0.8])")));
  // A constant sigma maps too (it was refused), values outside [0, 90] clamped with a note.
  pbrt::ImportResult r = pbrt::importPbrtText(pbrtPlane(R"(Material "matte" "float sigma" 120)"), "dir/t.pbrt");
  CHECK(r.scene.materials.back().sigma == 90.0f);
  bool noted = false;
  for (const auto& n : r.notes) noted = noted || contains(n, "clamped to [0, 90]");
  CHECK(noted);
}

TEST_CASE("convert: textured sigma, thickness and per-channel mix amount; the JSON renders the same pixels") {
  std::string dir = test::makeTempDir();
  std::string text = pbrtPlane(R"(Material "matte" "rgb Kd" [0.7 0.5 0.3] "texture sigma" "sig")") + R"(AttributeBegin
Translate 0.5 0.2 0.5
Material "coateddiffuse" "texture thickness" "thick"
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Translate -0.5 0.2 -0.5
Material "mix" "string materials" ["red" "blue"] "texture amount" "amt"
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Translate 0.5 0.2 -0.5
Material "mix" "string materials" ["red" "blue"] "rgb amount" [0.2 0.4 0.9]
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Translate -0.5 0.2 0.5
Material "matte" "float sigma" 30
Shape "sphere" "float radius" 0.2
AttributeEnd
)";
  test::writeFile(dir + "/s.pbrt", text);
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  std::string written = checkConvert(r.scene, dir + "/s.json");
  CHECK(contains(written, "\"sigma\": \"sig\""));
  CHECK(contains(written, "\"sigma\": 30"));
  CHECK(contains(written, "\"thickness\": \"thick\""));
  CHECK(contains(written, "\"amount\": \"amt\""));
  CHECK(contains(written, "\"amount\": [\n"));  // the RGB constant
  // pbrt-v3's order swapped: tdpm's second material is the one amount weights.
  CHECK(contains(written, "\"materials\": [\n        \"blue\",\n        \"red\"\n      ]"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured sigma, thickness, RGB amount: bad input gets located errors and writes nothing") {
  std::string dir = test::makeTempDir();
  auto json = [&](const std::string& material) {
    return test::errorMessageOf([&] { jsonScene(material, dir); });
  };
  CHECK(contains(json(R"({"type": "diffuse", "sigma": "nope"})"), "materials.m.sigma: unknown texture \"nope\""));
  CHECK(contains(json(R"({"type": "diffuse", "sigma": "amt"})"),
                 "materials.m.sigma: texture \"amt\" is a spectrum texture, but a float one is expected here"));
  CHECK(contains(json(R"({"type": "diffuse", "sigma": 91})"), "materials.m.sigma: sigma (Oren-Nayar, degrees) must be in [0, 90], got 91"));
  CHECK(contains(json(R"({"type": "plastic", "sigma": 10})"), "materials.m"));  // sigma is diffuse's only
  CHECK(contains(json(R"({"type": "coateddiffuse", "thickness": "nope"})"), "materials.m.thickness: unknown texture \"nope\""));
  CHECK(contains(json(R"({"type": "mix", "materials": ["red", "blue"], "amount": "nope"})"), "materials.m.amount: unknown texture \"nope\""));
  CHECK(contains(json(R"({"type": "mix", "materials": ["red", "blue"], "amount": [0.5, 1.5, 0]})"),
                 "materials.m.amount: amount must be in [0, 1] in every channel"));
  // A thickness texture reaching below 0 (no JSON texture can: a description made in code): refused when built.
  scene::SceneDescription neg = scene::parseScene(
      texturedPlane(R"("t": {"type": "checkerboard", "float": true, "tex1": 0.1, "tex2": 0.5})", R"("m": {"type": "coateddiffuse", "thickness": "t"})"),
      dir + "/n.json");
  REQUIRE(neg.textures.size() == 1);
  neg.textures[0].a.value = Rgb(-0.1f);
  CHECK(contains(test::errorMessageOf([&] { Scene::build(neg); }), "material \"m\": its thickness texture's values [-0.1"));
  // pbrt: unknown texture names, located; tdpm convert exits non-zero and writes nothing.
  auto pbrtError = [&](const std::string& body) { return test::errorMessageOf([&] { importText(pbrtPlane(body)); }); };
  CHECK(contains(pbrtError(R"(Material "matte" "texture sigma" "nope")"), "t.pbrt:11: Material \"matte\": parameter \"texture sigma\": no texture named \"nope\""));
  CHECK(contains(pbrtError(R"(Material "coateddiffuse" "texture thickness" "nope")"), "no texture named \"nope\""));
  CHECK(contains(pbrtError(R"(Material "mix" "string materials" ["red" "blue"] "texture amount" "nope")"), "no texture named \"nope\""));
  CHECK(contains(pbrtError(R"(Material "matte" "texture sigma" "amt")"), "texture \"amt\" is a spectrum texture, but matte's sigma needs a float one"));
  for (const char* body : {R"(Material "matte" "texture sigma" "nope")", R"(Material "coatedconductor" "texture thickness" "nope")",
                           R"(Material "mix" "string materials" ["red" "blue"] "texture amount" "nope")"}) {
    test::writeFile(dir + "/bad.pbrt", pbrtPlane(body));
    auto res = test::runTdpm("convert -q '" + dir + "/bad.pbrt' -o '" + dir + "/bad.json'");
    CHECK(res.exitCode != 0);
    CHECK(contains(res.output, "bad.pbrt:11:"));
    CHECK(!test::fileExists(dir + "/bad.json"));
  }
  std::filesystem::remove_all(dir);
}
