// tests/test_environment.cpp — environment lights (scene/environment.*,
// the "environment" JSON light, pbrt "infinite"): a diffuse sphere under a
// constant sky and under a one-texel map reflects albedo x L (direct and
// full depth: a convex object never sees itself); the map's sampling
// density integrates to 1, matches pdf() and its histogram (chi-square);
// photons from the sky disc carry the analytic flux onto a disc; the photon
// methods agree with pathtrace; maps that are missing, negative, empty or
// (pbrt-v4) not square are located errors; convert round-trips the light.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "core/error.h"
#include "core/rng.h"
#include "error_capture.h"
#include "image/pfm.h"
#include "import/pbrt_import.h"
#include "render/fingerprint.h"
#include "render/renderer.h"
#include "scene/environment.h"
#include "scene/json_writer.h"
#include "scene/light.h"
#include "scene/parse.h"
#include "scene/scene.h"
#include "render_fixtures.h"

using namespace tdpm;

namespace {

const std::filesystem::path& tempDir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("tdpm_env_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::string writeMap(const std::string& name, const image::ImageRgb& img) {
  std::string p = (tempDir() / name).string();
  image::writePfm(p, img);
  return p;
}

// 8 x 4 map: dim grey sky and one bright texel in the upper rows.
image::ImageRgb testMap() {
  image::ImageRgb m(8, 4, Rgb(0.1f));
  m.at(2, 0) = Rgb(40.0f, 30.0f, 20.0f);  // a sun 22.5 degrees from light-space +z
  m.at(5, 0) = Rgb(0.0f);  // a black texel: never sampled
  m.at(6, 2) = Rgb(2.0f, 0.5f, 0.1f);
  return m;
}

scene::SceneDescription parseText(const std::string& json) {
  return scene::parseScene(json, (tempDir() / "scene.json").string());
}

// A diffuse sphere (radius 1, albedo a) filling the middle of the view.
std::string sphereScene(float albedo, const std::string& light) {
  std::ostringstream s;
  s << R"({"camera": {"position": [0,0,5], "target": [0,0,0], "up": [0,1,0], "fov": 30, "resolution": [24,24]},
 "materials": {"m": {"type": "diffuse", "color": [)"
    << albedo << "," << albedo << "," << albedo << R"(]}},
 "objects": [{"name": "ball", "shape": {"type": "sphere", "radius": 1}, "material": "m"}],
 "lights": [)" << light << "]}";
  return s.str();
}

Film renderWith(const scene::SceneDescription& d, const std::string& method, int spp, int maxDepth,
                size_t globalPhotons = 40000) {
  RenderOptions o = test::smallRenderOptions(*parseRenderMethod(method), spp, maxDepth, 11);
  o.causticPhotons = 0;
  o.globalPhotons = globalPhotons;
  return test::renderOnce(d, o);
}

// Mean and standard error of the mean over the pixels of a square crop.
void cropMean(const Film& f, int x0, int y0, int n, Rgb* mean, double* stderrG) {
  double sum[3] = {0, 0, 0}, sq = 0;
  for (int y = y0; y < y0 + n; ++y)
    for (int x = x0; x < x0 + n; ++x) {
      const Rgb& c = f.color[f.index(x, y)];
      sum[0] += c.r;
      sum[1] += c.g;
      sum[2] += c.b;
      sq += double(c.g) * c.g;
    }
  double k = double(n) * n;
  *mean = Rgb(float(sum[0] / k), float(sum[1] / k), float(sum[2] / k));
  *stderrG = std::sqrt(std::max(0.0, sq / k - (sum[1] / k) * (sum[1] / k)) / k);
}

}  // namespace

TEST_CASE("environment: a diffuse sphere under a constant sky reflects albedo x L, and the sky is seen") {
  for (int depth : {1, 16}) {
    CAPTURE(depth);
    Film f = renderWith(parseText(sphereScene(0.6f, R"({"type": "environment", "L": [1, 2, 0.5], "scale": 1.5})")),
                        "pathtrace", 32, depth);
    Rgb m;
    double se;
    cropMean(f, 9, 9, 6, &m, &se);  // on the sphere
    // A convex object never sees itself: every bounce beyond the first escapes.
    CHECK(std::fabs(m.g - 0.6 * 3.0) < 5 * se + 1e-4);
    CHECK(m.r / m.g == doctest::Approx(0.5).epsilon(0.02));
    CHECK(se < 0.01);
    // A camera ray that escapes sees the sky at full weight.
    const Rgb& corner = f.color[f.index(0, 0)];
    CHECK(corner.r == doctest::Approx(1.5f));
    CHECK(corner.g == doctest::Approx(3.0f));
    CHECK(corner.b == doctest::Approx(0.75f));
  }
}

TEST_CASE("environment: without BSDF rays to carry it, a constant sky is sampled by next-event estimation") {
  // No global map: no final gather, so the photon methods' direct light is
  // light sampling alone (uniform over the sphere for a constant sky).
  Film f = renderWith(parseText(sphereScene(0.6f, R"({"type": "environment", "L": [1, 2, 0.5]})")), "standard", 64, 8, 0);
  Rgb m;
  double se;
  cropMean(f, 9, 9, 6, &m, &se);
  CHECK(std::fabs(m.g - 0.6 * 2.0) < 5 * se + 1e-4);
  CHECK(se > 0);  // it is sampled (a zero would mean the sky was lost)
  CHECK(se < 0.02);
}

TEST_CASE("environment: a one-texel map lights like the constant it holds") {
  image::ImageRgb one(1, 1, Rgb(0.25f, 0.5f, 1.0f));
  std::string p = writeMap("one.pfm", one);
  Film f = renderWith(parseText(sphereScene(0.5f, R"({"type": "environment", "filename": ")" + p + R"("})")),
                      "pathtrace", 32, 4);
  Rgb m;
  double se;
  cropMean(f, 9, 9, 6, &m, &se);
  CHECK(std::fabs(m.g - 0.25) < 5 * se + 1e-4);
  CHECK(m.b / m.g == doctest::Approx(2.0).epsilon(0.02));
  CHECK(se < 0.01);
  CHECK(f.color[f.index(0, 0)].b == doctest::Approx(1.0f));
}

TEST_CASE("environment: the map's sampling density integrates to 1, matches pdf() and the luminance histogram") {
  image::ImageRgb img = testMap();
  Affine3f toWorld = Affine3f::rotate(Quaternion::fromAxisAngle(normalize(Vec3f{1, 2, 0.5f}), 0.7f));
  EnvironmentMap env = EnvironmentMap::fromLatLong(img, Rgb(1.0f), toWorld);
  // Integral of pdf over the sphere by a fine midpoint rule in world (theta, phi).
  const int nt = 400, np = 800;
  double integral = 0, radiance = 0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      double t = (i + 0.5) * kPi / nt, ph = (j + 0.5) * 2 * kPi / np;
      Vec3f w{float(std::sin(t) * std::cos(ph)), float(std::sin(t) * std::sin(ph)), float(std::cos(t))};
      double dw = std::sin(t) * (kPi / nt) * (2 * kPi / np);
      integral += env.pdf(w) * dw;
      radiance += env.radiance(w).g * dw;
    }
  CHECK(integral == doctest::Approx(1.0).epsilon(0.01));
  CHECK(radiance == doctest::Approx(env.integral().g).epsilon(0.01));

  // Samples: density and radiance agree with pdf() and radiance(); the
  // texel histogram matches luminance x solid angle (chi-square, 31 dof
  // after the black texel; 70 is beyond the 99.99th percentile); and the
  // mean of L / pdf is the integral of L.
  Rng rng(42, 1);
  const int n = 200000;
  std::vector<double> count(img.pixelCount(), 0.0);
  Affine3f toLight = toWorld.inverse();
  double sumG = 0, sumG2 = 0;
  for (int k = 0; k < n; ++k) {
    Vec3f w;
    Rgb L;
    float pdf;
    REQUIRE(env.sample({rng.uniform(), rng.uniform()}, w, L, pdf));
    CHECK_MESSAGE(std::fabs(pdf / env.pdf(w) - 1.0f) < 1e-2f, "pdf of a sampled direction");
    Vec3f d = normalize(toLight.vector(w));
    double phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * kPi;
    int x = std::min(7, int(phi / (2 * kPi) * 8)), y = std::min(3, int(std::acos(std::clamp(d.z, -1.0f, 1.0f)) / kPi * 4));
    count[size_t(y * 8 + x)] += 1;
    double v = L.g / pdf;
    sumG += v;
    sumG2 += v * v;
  }
  CHECK(count[5] == 0);
  double total = 0;
  std::vector<double> expected(img.pixelCount());
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      double band = (2 * kPi / 8) * (std::cos(kPi * y / 4) - std::cos(kPi * (y + 1) / 4));
      // The distribution uses sin(theta) at the row's centre, the lat-long
      // element of pbrt-v3: compare against exactly that.
      double sinC = std::sin(kPi * (y + 0.5) / 4);
      expected[size_t(y * 8 + x)] = img.at(x, y).luminance() * sinC;
      total += expected[size_t(y * 8 + x)];
      (void)band;
    }
  double chi2 = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (expected[i] == 0) continue;
    double e = expected[i] / total * n;
    chi2 += (count[i] - e) * (count[i] - e) / e;
  }
  CHECK(chi2 < 70.0);
  double mean = sumG / n, se = std::sqrt((sumG2 / n - mean * mean) / n);
  CHECK(std::fabs(mean - env.integral().g) < 5 * se);
}

TEST_CASE("environment: photons from the sky disc carry pi L x the area of a disc facing up") {
  // Constant L over the upper and lower hemisphere; a horizontal disc of
  // radius rho at the origin receives pi L (pi rho^2) from above.
  Light light;
  light.type = Light::Type::Environment;
  const float L = 2.0f, rho = 0.5f;
  light.env = std::make_shared<const EnvironmentMap>(EnvironmentMap::constant(Rgb(L), Affine3f::identity()));
  finalizeLight(light);
  Bounds3f bounds;
  bounds.extend({-1, -1, -1});
  bounds.extend({1, 1, 1});
  Rgb power = emittedPower(light, bounds);
  float R = 0.5f * length(bounds.diagonal()) * 1.001f;
  CHECK(power.r == doctest::Approx(kPi * R * R * 4 * kPi * L));
  Rng rng(3, 7);
  const int n = 400000;
  double onDisc = 0, all = 0;
  for (int k = 0; k < n; ++k) {
    EmittedRay ray;
    REQUIRE(emitFromLight(light, 0.5f, bounds, {rng.uniform(), rng.uniform()}, {rng.uniform(), rng.uniform()}, ray));
    all += ray.flux.r;
    // Outside the bounding sphere, travelling into it.
    CHECK(length(ray.origin) >= R * 0.999f);
    if (ray.direction.y >= 0) continue;  // from below
    float t = -ray.origin.y / ray.direction.y;
    Vec3f p = ray.origin + ray.direction * t;
    if (t > 0 && p.x * p.x + p.z * p.z <= rho * rho) onDisc += ray.flux.r;
  }
  CHECK(all / n == doctest::Approx(power.r).epsilon(1e-4));
  double expected = kPi * L * kPi * rho * rho;
  // Binomial spread of the hits: relative error ~ 1/sqrt(hits) (~1000 hits).
  CHECK(onDisc / n == doctest::Approx(expected).epsilon(0.07));
}

TEST_CASE("environment: the photon methods agree with pathtrace on a sky- and lamp-lit floor and ball") {
  std::string p = writeMap("sky.pfm", testMap());
  std::string json = R"({"camera": {"position": [0,2.5,2.5], "target": [0,0.3,0], "up": [0,1,0], "fov": 40, "resolution": [24,18]},
 "materials": {"grey": {"type": "diffuse", "color": [0.9,0.9,0.9]}, "red": {"type": "diffuse", "color": [0.9,0.5,0.4]}},
 "objects": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.6}, "material": "red", "transform": {"translate": [0,0.6,0]}},
   {"name": "floor", "shape": {"type": "quad", "size": [8,8]}, "material": "grey"}],
 "lights": [{"type": "environment", "filename": ")" + p + R"(", "transform": {"rotate": {"axis": [1,0,0], "angle": -90}}},
            {"type": "point", "position": [1.5, 1.2, 0.8], "power": 60}]})";
  scene::SceneDescription d = parseText(json);
  auto mean = [](const Film& f) {
    double s = 0;
    for (const Rgb& c : f.color) s += c.g;
    return s / double(f.color.size());
  };
  // Indirect light (what the photons carry) = full - direct, each at 1024
  // spp so that the direct part's noise does not hide it. The point light
  // makes photons be chosen by power between two lights. Measured: direct
  // 1.5236, indirect 0.0670 (pathtrace), 0.0683 (standard and time); the
  // sky alone: 1.3497, 0.0548 and 0.0559.
  double ref = mean(renderWith(d, "pathtrace", 1024, 8)), direct = mean(renderWith(d, "pathtrace", 1024, 1));
  double indirect = ref - direct;
  MESSAGE("pathtrace ", ref, ", direct ", direct);
  CHECK(indirect > 0.03 * ref);  // large enough for a wrong photon flux to show
  for (const char* m : {"standard", "time"}) {
    CAPTURE(std::string(m));
    double v = mean(renderWith(d, m, 256, 8));
    MESSAGE(std::string(m), " ", v);
    CHECK(v == doctest::Approx(ref).epsilon(0.01));
    CHECK((v - direct) == doctest::Approx(indirect).epsilon(0.15));
  }
}

TEST_CASE("environment: bad maps and parameters are located errors") {
  auto errorOf = [](const std::string& light) {
    return test::errorMessageOf([&] { parseText(sphereScene(0.5f, light)); });
  };
  std::string missing = errorOf(R"({"type": "environment", "filename": "nope.exr"})");
  CHECK(missing.find("lights[0].filename") != std::string::npos);
  CHECK(missing.find("nope.exr") != std::string::npos);
  image::ImageRgb neg(2, 1, Rgb(1.0f));
  neg.at(1, 0) = Rgb(1.0f, -1.0f, 0.0f);
  std::string negative = errorOf(R"({"type": "environment", "filename": ")" + writeMap("neg.pfm", neg) + R"("})");
  CHECK(negative.find("texel (1, 0)") != std::string::npos);
  CHECK(negative.find("non-negative") != std::string::npos);
  std::string notSquare = errorOf(R"({"type": "environment", "mapping": "equal-area", "filename": ")" +
                                  writeMap("wide.pfm", image::ImageRgb(4, 2, Rgb(1.0f))) + R"("})");
  CHECK(notSquare.find("must be square, got 4 x 2") != std::string::npos);
  CHECK(errorOf(R"({"type": "environment", "L": [1, -1, 1]})").find("lights[0].L") != std::string::npos);
  CHECK(errorOf(R"({"type": "environment", "scale": -2})").find("lights[0].scale") != std::string::npos);
  CHECK(errorOf(R"({"type": "environment", "motion": []})").find("does not move") != std::string::npos);
  CHECK(errorOf(R"({"type": "environment", "transform": {"scale": [1, 2, 1]}})").find("lights[0].transform.scale") !=
        std::string::npos);
  // A file of no texels: readers refuse it, and the message names it.
  std::string empty = (tempDir() / "empty.pfm").string();
  { std::ofstream(empty) << "PF\n0 0\n-1.0\n"; }
  std::string zero = errorOf(R"({"type": "environment", "filename": ")" + empty + R"("})");
  CHECK(zero.find("empty.pfm") != std::string::npos);
  CHECK(zero.find("lights[0].filename") != std::string::npos);

  // pbrt: a v4 "filename" that is not square, a missing map.
  std::string wide = writeMap("wide2.pfm", image::ImageRgb(4, 2, Rgb(1.0f)));
  std::string pbrtNotSquare = test::errorMessageOf([&] {
    pbrt::importPbrtText("WorldBegin\nLightSource \"infinite\" \"string filename\" \"" + wide + "\"\n", "dir/t.pbrt");
  });
  CHECK(pbrtNotSquare.find("dir/t.pbrt:2: LightSource \"infinite\": ") == 0);
  CHECK(pbrtNotSquare.find("must be square") != std::string::npos);
  std::string pbrtMissing = test::errorMessageOf(
      [&] { pbrt::importPbrtText("WorldBegin\nLightSource \"infinite\" \"string mapname\" \"sky.exr\"\n", "dir/t.pbrt"); });
  CHECK(pbrtMissing.find("dir/t.pbrt:2: LightSource \"infinite\": dir/sky.exr") == 0);
}

TEST_CASE("environment: equal-area maps convert to lat-long by Clarberg's mapping") {
  // The mapping is a bijection of the square and the sphere.
  Rng rng(5, 5);
  for (int i = 0; i < 1000; ++i) {
    Vec2f p{rng.uniform(), rng.uniform()};
    Vec3f d = equalAreaSquareToSphere(p);
    CHECK(length(d) == doctest::Approx(1.0f).epsilon(1e-4));
    Vec2f q = equalAreaSphereToSquare(d);
    CHECK(q.x == doctest::Approx(p.x).epsilon(1e-3));
    CHECK(q.y == doctest::Approx(p.y).epsilon(1e-3));
  }
  // Upper-hemisphere texels (the square's inner diamond, +z) land in the
  // upper half of the lat-long map.
  image::ImageRgb sq(16, 16, Rgb(0.0f));
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      if (equalAreaSquareToSphere({(x + 0.5f) / 16, (y + 0.5f) / 16}).z > 0) sq.at(x, y) = Rgb(1.0f);
  image::ImageRgb ll = equalAreaToLatLong(sq);
  CHECK(ll.width == 32);
  CHECK(ll.height == 16);
  CHECK(ll.at(3, 2).r == 1.0f);
  CHECK(ll.at(3, 13).r == 0.0f);
  // Illuminance of a constant 1 over the upper hemisphere is pi.
  CHECK(upperHemisphereIlluminance(image::ImageRgb(64, 32, Rgb(1.0f))) == doctest::Approx(kPi).epsilon(1e-4));
}

TEST_CASE("environment: pbrt infinite lights import, scale, and convert to JSON that renders the same pixels") {
  std::string sq = writeMap("sq.pfm", [] {
    image::ImageRgb m(8, 8, Rgb(0.2f));
    m.at(3, 3) = Rgb(5.0f, 4.0f, 3.0f);
    return m;
  }());
  std::string ll = writeMap("ll.pfm", testMap());
  const std::string head = R"(LookAt 0 3 3  0 0.3 0  0 1 0
Camera "perspective" "float fov" 35
Film "rgb" "integer xresolution" 16 "integer yresolution" 12
WorldBegin
AttributeBegin
  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
  Shape "sphere" "float radius" 0.6
AttributeEnd
AttributeBegin
Rotate -90 1 0 0
)";
  for (const std::string& light : {std::string("LightSource \"infinite\" \"string filename\" \"") + sq + "\" \"float scale\" 2\n",
                                   std::string("LightSource \"infinite\" \"string mapname\" \"") + ll + "\" \"rgb L\" [1 0.5 0.25]\n",
                                   std::string("LightSource \"infinite\" \"rgb L\" [0.3 0.4 0.5] \"float illuminance\" 10\n")}) {
    CAPTURE(light);
    scene::SceneDescription d = pbrt::importPbrtText(head + light + "AttributeEnd\n", (tempDir() / "t.pbrt").string()).scene;
    REQUIRE(d.lights.size() == 1);
    REQUIRE(d.lights[0].type == scene::LightDesc::Type::Environment);
    if (light.find("illuminance") != std::string::npos) CHECK(d.lights[0].radiance.g == doctest::Approx(0.4 * 10 / kPi));
    if (light.find("scale") != std::string::npos) CHECK(d.lights[0].radiance.g == doctest::Approx(2.0));
    std::string jsonPath = (tempDir() / "converted.json").string();
    pbrt::writeSceneJson(d, jsonPath);
    std::ifstream in(jsonPath);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    scene::SceneDescription back = scene::parseScene(text, jsonPath);
    Film a = renderWith(d, "pathtrace", 4, 3), b = renderWith(back, "pathtrace", 4, 3);
    bool same = a.color.size() == b.color.size();
    for (size_t i = 0; same && i < a.color.size(); ++i)
      same = a.color[i].r == b.color[i].r && a.color[i].g == b.color[i].g && a.color[i].b == b.color[i].b;
    CHECK(same);
  }
}

TEST_CASE("environment: the resume fingerprint holds the map's texels, not its path") {
  image::ImageRgb a(4, 2, Rgb(0.5f)), b = a;
  b.at(3, 1) = Rgb(0.5f, 0.5f, 0.6f);
  auto digestOf = [](const std::string& file) {
    return sceneDigest(parseText(sphereScene(0.5f, R"({"type": "environment", "filename": ")" + file + R"("})")));
  };
  std::string da = digestOf(writeMap("fa.pfm", a));
  CHECK(digestOf(writeMap("fa-copy.pfm", a)) == da);  // a copy elsewhere resumes
  CHECK(digestOf(writeMap("fa.pfm", b)) != da);       // one texel changed does not
}
