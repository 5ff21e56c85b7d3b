// tests/test_media.cpp — participating media (issue 25 part 1): the scene
// format's media keys and their located errors (scene/parse_media.cpp),
// the runtime media (media/medium.h: transmittance and free flight against
// closed forms and quadrature), the Henyey-Greenstein phase function, and
// volumetric path tracing (render/volume_path.cpp) against Sun et al.'s
// single-scattering airlight integral, a volume furnace, and a light moving
// through fog. Fixed seeds; bounds are 4 standard errors unless stated.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "airlight_scene.h"
#include "cli_harness.h"
#include "error_capture.h"
#include "media/medium.h"
#include "media/phase.h"
#include "render/fingerprint.h"
#include "render/path_tracer.h"
#include "render_fixtures.h"
#include "scene/parse.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

using namespace tdpm;
using tdpm::scene::parseScene;
using tdpm::scene::SceneDescription;

namespace {

const std::string kFile = "media.json";

std::string errorOf(const std::string& text) {
  return test::errorMessageOf([&] { parseScene(text, kFile); });
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A scene with `media` (JSON members), and extra top-level members.
std::string sceneWith(const std::string& media, const std::string& objects = R"([{"shape": {"type": "sphere"}}])",
                      const std::string& extra = "") {
  return R"({"camera": {}, "media": {)" + media + R"(}, "objects": )" + objects + (extra.empty() ? "" : ", " + extra) +
         "}";
}

const std::string kFog = R"("fog": {"type": "homogeneous", "sigma_a": 0.1, "sigma_s": [0.2, 0.3, 0.4]})";

// Mean and standard error of n draws of f().
template <class F>
std::pair<double, double> meanAndError(int n, F&& f) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    double v = f();
    s += v;
    s2 += v * v;
  }
  double mean = s / n, var = std::max(0.0, s2 / n - mean * mean);
  return {mean, std::sqrt(var / n)};
}

}  // namespace

// ---------------------------------------------------------------- parsing

TEST_CASE("media: the JSON keys fill the description") {
  std::string grid = R"("smoke": {"type": "grid", "sigma_a": 1, "sigma_s": 2, "scale": 0.5, "g": 0.3,
                        "resolution": [2, 1, 1], "density": [0.5, 1.5], "bounds": [[0, 0, 0], [2, 1, 1]],
                        "transform": {"translate": [1, 0, 0]}})";
  SceneDescription d = parseScene(
      sceneWith(kFog + "," + grid,
                R"([{"shape": {"type": "sphere"}, "medium": "smoke", "material": "interface"},
                    {"shape": {"type": "quad"}, "medium_interface": {"inside": null, "outside": "smoke"}},
                    {"shape": {"type": "box"}}])",
                R"("exterior_medium": "fog", "lights": [{"type": "point"}, {"type": "point", "medium": null}])"),
      kFile);
  REQUIRE(d.media.size() == 2);
  const scene::MediumDesc& fog = d.media[0];
  CHECK(fog.name == "fog");
  CHECK(fog.type == scene::MediumDesc::Type::Homogeneous);
  CHECK(fog.sigmaA.r == 0.1f);
  CHECK(fog.sigmaS.b == 0.4f);
  const scene::MediumDesc& smoke = d.media[1];
  CHECK(smoke.type == scene::MediumDesc::Type::Grid);
  CHECK(smoke.scale == 0.5f);
  CHECK(smoke.g == 0.3f);
  CHECK(smoke.grid.nx == 2);
  CHECK(smoke.grid.density == std::vector<float>{0.5f, 1.5f});
  CHECK(smoke.grid.bounds.hi.x == 2.0f);
  CHECK(smoke.placement.translate.x == 1.0f);
  CHECK(d.exteriorMedium == 0);
  CHECK(d.camera.medium == 0);  // default: the exterior
  CHECK(d.lights[0].medium == 0);
  CHECK(d.lights[1].medium == -1);
  CHECK(d.objects[0].media.present);
  CHECK(d.objects[0].media.inside == 1);
  CHECK(d.objects[0].media.outside == 0);
  CHECK(d.materials[d.objects[0].material].type == scene::MaterialDesc::Type::Interface);
  CHECK(d.objects[1].media.present);
  CHECK(d.objects[1].media.inside == -1);
  CHECK(d.objects[1].media.outside == 1);
  CHECK_FALSE(d.objects[2].media.present);
}

TEST_CASE("media: unknown medium names are located errors, wherever they are used") {
  std::string e = errorOf(sceneWith(kFog, R"([{"shape": {"type": "sphere"}}])", R"("exterior_medium": "smog")"));
  CHECK(contains(e, "media.json:1: exterior_medium: unknown medium \"smog\"; defined media: fog"));
  e = errorOf(R"({"camera": {"medium": "smog"}, "media": {)" + kFog + R"(}, "objects": []})");
  CHECK(contains(e, "camera.medium: unknown medium \"smog\""));
  e = errorOf(sceneWith(kFog, "[]", R"("lights": [{"type": "point", "medium": "smog"}])"));
  CHECK(contains(e, "lights[0].medium: unknown medium \"smog\""));
  e = errorOf(sceneWith(kFog, R"([{"shape": {"type": "sphere"}, "medium": "smog"}])"));
  CHECK(contains(e, "objects[0].medium: unknown medium \"smog\""));
  e = errorOf(sceneWith(kFog, R"([{"shape": {"type": "sphere"}, "medium_interface": {"inside": "smog"}}])"));
  CHECK(contains(e, "objects[0].medium_interface.inside: unknown medium \"smog\""));
  e = errorOf(R"({"camera": {"medium": "fog"}, "objects": []})");
  CHECK(contains(e, "camera.medium: unknown medium \"fog\"; no media are defined"));
}

TEST_CASE("media: an interior medium needs a closed shape") {
  for (std::string shape : {"quad", "disk", "cylinder"}) {
    std::string e = errorOf(sceneWith(kFog, R"([{"shape": {"type": ")" + shape + R"("}, "medium": "fog"}])"));
    CHECK(contains(e, "objects[0].medium: an interior medium needs a closed shape: a"));
    CHECK(contains(e, "open surface"));
  }
  std::string objects = R"([{"shape": {"type": "mesh", "file": "m.obj"}, "medium": "fog"}])";
  // One triangle: every edge has one face.
  scene::MeshSource open = [](const std::string&, std::vector<Vec3f>* v, std::vector<uint32_t>* i) {
    *v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    *i = {0, 1, 2};
    return true;
  };
  std::string e = test::errorMessageOf([&] { parseScene(sceneWith(kFog, objects), kFile, open); });
  CHECK(contains(e, "objects[0].medium: an interior medium needs a closed shape: the mesh is not closed"));
  scene::MeshSource tetra = [](const std::string&, std::vector<Vec3f>* v, std::vector<uint32_t>* i) {
    *v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    *i = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return true;
  };
  CHECK(parseScene(sceneWith(kFog, objects), kFile, tetra).objects[0].media.inside == 0);
  // medium_interface is for any shape.
  CHECK(parseScene(sceneWith(kFog, R"([{"shape": {"type": "quad"}, "medium_interface": {"inside": "fog"}}])"), kFile)
            .objects[0].media.present);
  e = errorOf(sceneWith(kFog, R"([{"shape": {"type": "sphere"}, "medium": "fog", "medium_interface": {}}])"));
  CHECK(contains(e, "objects[0].medium_interface: give either \"medium\" or \"medium_interface\", not both"));
}

TEST_CASE("media: coefficients, scale and g are checked") {
  auto homog = [](const std::string& members) {
    return errorOf(sceneWith(R"("fog": {"type": "homogeneous", )" + members + "}"));
  };
  CHECK(contains(homog(R"("sigma_a": -1, "sigma_s": 1)"), "media.fog.sigma_a: must be non-negative in every channel"));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": [1, -2, 1])"), "media.fog.sigma_s: must be non-negative"));
  CHECK(contains(homog(R"("sigma_a": 1)"), "media.fog: missing required key \"sigma_s\""));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": 1, "scale": -2)"), "media.fog.scale: scale must be non-negative"));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": 3e38, "scale": 10)"), "media.fog.scale: scale x (sigma_a + sigma_s) overflows"));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": 1, "g": 1)"), "media.fog.g: g (Henyey-Greenstein asymmetry) must be in (-1, 1), got 1"));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": 1, "g": -1.5)"), "media.fog.g: g"));
  CHECK(contains(homog(R"("sigma_a": 1, "sigma_s": 1, "resolution": [1, 1, 1])"), "media.fog.resolution: unknown key \"resolution\""));
  CHECK(contains(errorOf(sceneWith(R"("fog": {"type": "smoke", "sigma_a": 1, "sigma_s": 1})")), "media.fog.type:"));
}

TEST_CASE("media: grids are checked before anything is allocated") {
  auto grid = [](const std::string& members) {
    return errorOf(sceneWith(R"("g": {"type": "grid", "sigma_a": 1, "sigma_s": 1)" + (members.empty() ? "" : ", " + members) + "}"));
  };
  CHECK(contains(grid(R"("resolution": [2, 2, 1], "density": [1, 2, 3])"),
                 "media.g.density: resolution 2 x 2 x 1 needs 4 density values, got 3"));
  CHECK(contains(grid(R"("resolution": [2, 1, 1], "density": [1, -2])"), "media.g.density[1]: density must be non-negative"));
  std::string big = grid(R"("resolution": [65536, 65536, 65536], "density": [1])");
  CHECK(contains(big, "media.g.resolution: the density grid 65536 x 65536 x 65536 needs 1125899906842624 bytes; at most"));
  CHECK(contains(grid(R"("resolution": [0, 1, 1], "density": [])"), "media.g.resolution[0]: each resolution must be in [1,"));
  CHECK(contains(grid(R"("density": [1])"), "media.g: missing required key \"resolution\""));
  CHECK(contains(grid(R"("sigma": 1)"), "media.g.sigma: unknown key"));
  CHECK(contains(grid(""), "media.g: a grid medium needs \"resolution\" and \"density\""));
  CHECK(contains(grid(R"("file": "a.vdb", "resolution": [1, 1, 1], "density": [1])"), "media.g.file: give either"));
  CHECK(contains(grid(R"("resolution": [1, 1, 1], "density": [1], "bounds": [[0, 0, 0], [1, 0, 1]])"),
                 "media.g.bounds: the first corner must be below the second"));
  // A file goes to media::loadDensityGridFile, located at the key.
  std::string file = grid(R"("file": "smoke.vdb", "grid": "density")");
  CHECK(contains(file, "media.g.file"));
  CHECK(contains(file, "smoke.vdb"));
}

TEST_CASE("media: the interface material, defined or by its reserved name") {
  SceneDescription d = parseScene(
      R"({"camera": {}, "materials": {"none": {"type": "interface"}},
          "objects": [{"shape": {"type": "sphere"}, "material": "none"}, {"shape": {"type": "box"}, "material": "interface"}]})",
      kFile);
  CHECK(d.materials[d.objects[0].material].type == scene::MaterialDesc::Type::Interface);
  CHECK(d.materials[d.objects[1].material].type == scene::MaterialDesc::Type::Interface);
  CHECK(contains(errorOf(R"({"camera": {}, "materials": {"interface": {"type": "diffuse"}}, "objects": []})"),
                 "materials.interface: the material name \"interface\" is reserved"));
  CHECK(contains(errorOf(R"({"camera": {}, "materials": {"i": {"type": "interface", "color": 1}}, "objects": []})"),
                 "materials.i.color: unknown key \"color\""));
}

// ---------------------------------------------------------------- runtime media

namespace {

scene::MediumDesc homogeneousDesc(Rgb sa, Rgb ss, float g = 0.0f) {
  scene::MediumDesc m;
  m.sigmaA = sa;
  m.sigmaS = ss;
  m.g = g;
  return m;
}

// A grid on [0, 4] x [0, 1] x [0, 1] whose density rises linearly along x
// (cell centres (i + 0.5) / 8 for 32 cells), sigma_t = (1, 2, 3) per density.
scene::MediumDesc rampDesc() {
  scene::MediumDesc m = homogeneousDesc(Rgb(0.5f, 1.0f, 1.5f), Rgb(0.5f, 1.0f, 1.5f));
  m.type = scene::MediumDesc::Type::Grid;
  m.grid.nx = 32;
  m.grid.ny = m.grid.nz = 1;
  for (int i = 0; i < 32; ++i) m.grid.density.push_back((float(i) + 0.5f) / 8.0f);
  m.grid.bounds = {{0, 0, 0}, {4, 1, 1}};
  return m;
}

// The optical depth of channel c along o + s d, s in [0, tMax], by the
// midpoint rule on the grid's own lookup (world = grid space here, shifted
// by `offset`).
double opticalDepth(const media::Medium& m, Vec3f o, Vec3f d, float tMax, int c, Vec3f offset = Vec3f(0.0f)) {
  const int n = 20000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    float s = (float(i) + 0.5f) * tMax / n;
    sum += media::gridDensity(m, o + d * s - offset);
  }
  float st = c == 0 ? m.sigmaT.r : c == 1 ? m.sigmaT.g : m.sigmaT.b;
  return sum * tMax / n * st;
}

}  // namespace

TEST_CASE("media: homogeneous transmittance is exp(-sigma_t d) exactly") {
  media::Medium m = media::makeMedium(homogeneousDesc(Rgb(0.1f, 0.2f, 0.3f), Rgb(0.4f, 0.1f, 0.0f)), nullptr);
  Rng rng(1);
  Rgb T = media::transmittance(m, {0, 0, 0}, {0, 0, 1}, 2.5f, 0.5f, rng);
  CHECK(T.r == std::exp(-0.5f * 2.5f));
  CHECK(T.g == std::exp(-(0.2f + 0.1f) * 2.5f));
  CHECK(T.b == std::exp(-0.3f * 2.5f));
  Rgb inf = media::transmittance(m, {0, 0, 0}, {0, 0, 1}, std::numeric_limits<float>::infinity(), 0.5f, rng);
  CHECK(inf.r == 0.0f);
}

TEST_CASE("media: the grid interpolates linearly between cell centres and is zero outside") {
  media::Medium m = media::makeMedium(rampDesc(), nullptr);
  CHECK(media::gridDensity(m, {1.0f, 0.5f, 0.5f}) == doctest::Approx(1.0f));
  CHECK(media::gridDensity(m, {2.3f, 0.5f, 0.5f}) == doctest::Approx(2.3f));
  CHECK(media::gridDensity(m, {4.1f, 0.5f, 0.5f}) == 0.0f);
  CHECK(m.majorant == doctest::Approx(3.0f * 31.5f / 8.0f));
}

TEST_CASE("media: ratio tracking through a density ramp is exp(-optical depth), still and moving") {
  media::Medium still = media::makeMedium(rampDesc(), nullptr);
  Vec3f o{-1.0f, 0.5f, 0.5f}, d = normalize(Vec3f(1.0f, 0.02f, 0.0f));
  float tMax = 4.0f;
  for (int c = 0; c < 3; ++c) {
    double expected = std::exp(-opticalDepth(still, o, d, tMax, c));
    Rng rng(7 + uint64_t(c));
    auto [mean, err] = meanAndError(40000, [&] {
      Rgb T = media::transmittance(still, o, d, tMax, 0.5f, rng);
      return double(c == 0 ? T.r : c == 1 ? T.g : T.b);
    });
    CHECK(std::fabs(mean - expected) < 4 * err + 1e-4);
    CHECK(err < 0.01 * expected + 1e-3);  // the bound is tight enough to mean something
  }
  // The same grid inside an object that moves +x by 1.5 over the shutter:
  // at time 0.4 it sits 0.6 to the right (grid coordinates are object space).
  Motion motion = Motion::keyframed({0.0f, Vec3f(0.0f), Quaternion{}, Vec3f(1.0f)},
                                    {{0.0f, Vec3f(0.0f), Quaternion{}, Vec3f(1.0f)},
                                     {1.0f, Vec3f(1.5f, 0, 0), Quaternion{}, Vec3f(1.0f)}},
                                    Shutter{0.0f, 1.0f});
  media::Medium moving = media::makeMedium(rampDesc(), &motion);
  REQUIRE(moving.moving);
  double expected = std::exp(-opticalDepth(still, o, d, tMax, 1, {0.6f, 0, 0}));
  double stillValue = std::exp(-opticalDepth(still, o, d, tMax, 1));
  Rng rng(11);
  auto [mean, err] = meanAndError(40000, [&] { return double(media::transmittance(moving, o, d, tMax, 0.4f, rng).g); });
  CHECK(std::fabs(mean - expected) < 4 * err + 1e-4);
  CHECK(std::fabs(expected - stillValue) > 20 * err);  // the motion matters at this precision
}

TEST_CASE("media: free flight in a homogeneous medium has mean 1 / sigma_t; in a grid it collides with probability 1 - T") {
  media::Medium m = media::makeMedium(homogeneousDesc(Rgb(0.0f), Rgb(0.8f)), nullptr);
  Rng rng(3);
  auto [mean, err] = meanAndError(100000, [&] {
    Rgb beta(1.0f);
    media::FreeFlight f = media::sampleFreeFlight(m, {0, 0, 0}, {1, 0, 0}, std::numeric_limits<float>::infinity(), 0, rng, beta);
    REQUIRE(f.event == media::FreeFlight::Event::Scatter);
    REQUIRE(beta.r == 1.0f);  // grey and non-absorbing: weight exactly 1
    return double(f.t);
  });
  CHECK(std::fabs(mean - 1.25) < 4 * err);
  // Grey grid (sigma_t = 1 per density): P(interaction before tMax) = 1 - T.
  scene::MediumDesc gd = rampDesc();
  gd.sigmaA = Rgb(0.3f);
  gd.sigmaS = Rgb(0.7f);
  media::Medium grid = media::makeMedium(gd, nullptr);
  Vec3f o{0.2f, 0.5f, 0.5f}, d{1, 0, 0};
  double expected = 1.0 - std::exp(-opticalDepth(grid, o, d, 1.5f, 0));
  int scatters = 0, absorbs = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    Rgb beta(1.0f);
    media::FreeFlight f = media::sampleFreeFlight(grid, o, d, 1.5f, 0, rng, beta);
    if (f.event == media::FreeFlight::Event::Scatter) ++scatters;
    if (f.event == media::FreeFlight::Event::Absorb) ++absorbs;
  }
  double p = double(scatters + absorbs) / n, err2 = std::sqrt(expected * (1 - expected) / n);
  CHECK(std::fabs(p - expected) < 4 * err2);
  CHECK(std::fabs(double(absorbs) / (scatters + absorbs) - 0.3) < 0.01);  // albedo 0.7
}

TEST_CASE("media: chromatic free flight (spectral tracking) estimates each channel's transmittance") {
  // E[beta_c x escape] = T_c for every channel at once.
  media::Medium m = media::makeMedium(homogeneousDesc(Rgb(0.1f, 0.5f, 1.0f), Rgb(0.2f, 0.0f, 0.5f)), nullptr);
  Rng rng(5);
  const int n = 100000;
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    Rgb beta(1.0f);
    media::FreeFlight f = media::sampleFreeFlight(m, {0, 0, 0}, {0, 1, 0}, 1.0f, 0, rng, beta);
    if (f.event != media::FreeFlight::Event::Escape) continue;
    sum[0] += beta.r, sum[1] += beta.g, sum[2] += beta.b;
  }
  CHECK(sum[0] / n == doctest::Approx(std::exp(-0.3)).epsilon(0.01));
  CHECK(sum[1] / n == doctest::Approx(std::exp(-0.5)).epsilon(0.01));
  CHECK(sum[2] / n == doctest::Approx(std::exp(-1.5)).epsilon(0.02));
}

TEST_CASE("media: Henyey-Greenstein integrates to 1 and its sampler follows it") {
  for (float g : {-0.7f, 0.0f, 0.3f, 0.9f}) {
    // Quadrature over cos theta: 2 pi integral of p d(cos).
    const int n = 200000;
    double integral = 0;
    for (int i = 0; i < n; ++i) integral += media::henyeyGreenstein(-1.0f + 2.0f * (float(i) + 0.5f) / n, g);
    integral *= 2.0 * M_PI * 2.0 / n;
    CHECK(integral == doctest::Approx(1.0).epsilon(1e-3));
    // Histogram of sampled cos over 16 bins against the pdf's mass in each.
    Rng rng(9);
    const int samples = 160000, bins = 16;
    std::vector<int> hist(bins, 0);
    Vec3f wo{0, 0, 1};
    for (int i = 0; i < samples; ++i) {
      Vec3f wi;
      float pdf = media::sampleHenyeyGreenstein(wo, g, rng.uniform(), rng.uniform(), wi);
      REQUIRE(pdf == doctest::Approx(media::henyeyGreenstein(dot(wo, wi), g)).epsilon(1e-3));
      int b = std::min(bins - 1, int((dot(wo, wi) + 1.0f) * 0.5f * bins));
      ++hist[size_t(b)];
    }
    for (int b = 0; b < bins; ++b) {
      double mass = 0;
      for (int k = 0; k < 1000; ++k) {
        float c = -1.0f + 2.0f * (float(b) + (float(k) + 0.5f) / 1000) / bins;
        mass += media::henyeyGreenstein(c, g) * 2.0 * M_PI * (2.0 / bins) / 1000;
      }
      double expected = mass * samples, sd = std::sqrt(expected * (1 - mass));
      CHECK(std::fabs(hist[size_t(b)] - expected) < 4 * sd + 2);
    }
  }
}

// ---------------------------------------------------------------- volumetric path tracing

namespace {

// Sun et al.'s airlight integral: test::airlight (tests/airlight_scene.h).
using test::airlight;

// The same by direct quadrature along the ray (checks the formula's use).
double airlightDirect(double I, double sigmaS, double sigmaT, double x0, double h, double D) {
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    double t = D * (i + 0.5) / n, d2 = h * h + (t - x0) * (t - x0);
    sum += sigmaS * std::exp(-sigmaT * t) / (4 * M_PI) * I * std::exp(-sigmaT * std::sqrt(d2)) / d2;
  }
  return sum * D / n;
}

// Camera ray from the origin along +z, a black wall at z = D, a point light
// at (h, 0, x0), fog everywhere.
scene::SceneDescription airlightScene(float I, float sigmaA, float sigmaS, float x0, float h, float D) {
  auto d = test::emptyScene(1, 1);
  d.camera.position = {0, 0, 0};
  d.camera.target = {0, 0, 1};
  d.materials.push_back(test::diffuse(Rgb(0.0f)));
  auto wall = test::quad({100, 100}, {0, 0, D}, 0);
  wall.placement.rotate = Quaternion::fromAxisAngle({1, 0, 0}, -kPi / 2);  // normal -z, toward the camera
  d.objects.push_back(wall);
  d.media.push_back(homogeneousDesc(Rgb(sigmaA), Rgb(sigmaS)));
  d.media[0].name = "fog";
  d.exteriorMedium = d.camera.medium = 0;
  d.lights.push_back(test::pointLightIn(0, {h, 0, x0}, I));
  return d;
}

}  // namespace

TEST_CASE("media: single scattering by pathtrace matches Sun et al.'s airlight integral") {
  const float I = 10, sa = 0.05f, ss = 0.25f, x0 = 2, h = 0.7f, D = 5;
  double expected = airlight(I, ss, sa + ss, x0, h, D);
  CHECK(expected == doctest::Approx(airlightDirect(I, ss, sa + ss, x0, h, D)).epsilon(1e-3));
  auto scene = Scene::build(airlightScene(I, sa, ss, x0, h, D));
  REQUIRE(scene->hasMedia());
  PathTracer pt(*scene, /*maxDepth=*/1);
  Rng rng(17);
  auto [mean, err] = meanAndError(100000, [&] { return double(pt.radiance({0, 0, 0}, {0, 0, 1}, 0.5f, rng).g); });
  CHECK(std::fabs(mean - expected) < 4 * err);
  CHECK(err < 0.02 * expected);
}

TEST_CASE("media: a light moving through fog gives the time average of the airlight integral") {
  const float I = 10, sa = 0.05f, ss = 0.25f, h = 0.7f, D = 5;
  auto d = airlightScene(I, sa, ss, 0, h, D);
  d.lights[0].position = {0, 0, 0};
  d.lights[0].motion = test::translation({h, 0, 0.5f}, {h, 0, 4.0f});  // x0 from 0.5 to 4 over the shutter
  double expected = 0;
  const int steps = 400;
  for (int i = 0; i < steps; ++i) expected += airlight(I, ss, sa + ss, 0.5 + 3.5 * (i + 0.5) / steps, h, D) / steps;
  auto scene = Scene::build(d);
  PathTracer pt(*scene, 1);
  Rng rng(23);
  auto [mean, err] = meanAndError(100000, [&] { return double(pt.radiance({0, 0, 0}, {0, 0, 1}, rng.uniform(), rng).r); });
  CHECK(std::fabs(mean - expected) < 4 * err);
  // The light held where it is at shutter open (what a time-less estimate
  // of photons traced at open would see) is far from the average.
  CHECK(std::fabs(airlight(I, ss, sa + ss, 0.5, h, D) - expected) > 10 * err);
}

TEST_CASE("media: volume furnace: a non-absorbing ball under a white sky is white") {
  auto d = test::emptyScene(6, 6);
  d.camera.position = {0, 0, 4};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = 20;
  scene::MaterialDesc none;
  none.type = scene::MaterialDesc::Type::Interface;
  d.materials.push_back(none);
  d.media.push_back(homogeneousDesc(Rgb(0.0f), Rgb(1.5f, 1.2f, 0.9f), 0.4f));
  auto ball = test::sphere(1.0f, {0, 0, 0}, 0);
  ball.media.present = true;
  ball.media.inside = 0;
  d.objects.push_back(ball);
  scene::LightDesc sky;
  sky.type = scene::LightDesc::Type::Environment;
  sky.radiance = Rgb(1.0f);
  d.lights.push_back(sky);
  // Grey: every path escapes with weight exactly 1, so every pixel is 1.
  auto o = test::smallRenderOptions(RenderMethod::PathTrace, 8, 1000, 3);
  d.media[0].sigmaS = Rgb(2.0f);
  Film grey = test::renderOnce(d, o);
  for (const Rgb& c : grey.color) CHECK(c.g == doctest::Approx(1.0).epsilon(1e-4));
  // Chromatic but non-absorbing: spectral tracking's per-channel weights
  // are not 1 path by path, but their mean is. The pixels are independent:
  // each channel's image mean within 4 standard errors of 1.
  d.media[0].sigmaS = Rgb(1.5f, 1.2f, 0.9f);
  o = test::smallRenderOptions(RenderMethod::PathTrace, 64, 1000, 3);
  Film f = test::renderOnce(d, o);
  for (int c = 0; c < 3; ++c) {
    double s = 0, s2 = 0, n = double(f.color.size());
    for (const Rgb& p : f.color) {
      double v = c == 0 ? p.r : c == 1 ? p.g : p.b;
      s += v, s2 += v * v;
    }
    double mean = s / n, err = std::sqrt(std::max(0.0, s2 / n - mean * mean) / n);
    CHECK(std::fabs(mean - 1.0) < 4 * err + 1e-3);
    CHECK(err < 0.05);
  }
}

TEST_CASE("media: interface surfaces are invisible, with and without media") {
  auto d = test::emptyScene(8, 8);
  d.camera.position = {0, 0, 4};
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(test::quad({4, 4}, {0, -1, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 1, 0};
  d.lights.push_back(l);
  auto o = test::smallRenderOptions(RenderMethod::PathTrace, 4, 4, 1);
  Film plain = test::renderOnce(d, o);
  scene::MaterialDesc none;
  none.type = scene::MaterialDesc::Type::Interface;
  d.materials.push_back(none);
  d.objects.push_back(test::sphere(0.5f, {0, 0, 0}, 1));
  CHECK(test::sameImage(plain, test::renderOnce(d, o)));
  // A vacuum ball inside vacuum (media defined, interface vacuum on both
  // sides): still no media in effect, still the same image.
  d.media.push_back(homogeneousDesc(Rgb(1.0f), Rgb(1.0f)));
  d.objects.back().media.present = true;
  CHECK_FALSE(Scene::build(d)->hasMedia());
  CHECK(test::sameImage(plain, test::renderOnce(d, o)));
  // An absorbing ball behind an interface darkens what is seen through it.
  d.objects.back().media.inside = 0;
  auto s = Scene::build(d);
  CHECK(s->hasMedia());
  CHECK(test::imageSum(test::renderOnce(d, o)) < 0.9 * test::imageSum(plain));
}

TEST_CASE("media: progressive accumulation refuses a scene with media instead of rendering without them") {
  auto d = airlightScene(1, 0.1f, 0.1f, 1, 1, 3);
  // time, standard, static and accumulation render media
  // (tests/test_media_photon_methods.cpp); progressive accumulation not.
  {
    auto o = test::smallRenderOptions(RenderMethod::Accumulation, 1, 2, 1);
    o.progressive = true;
    std::string e = test::errorMessageOf([&] { test::renderOnce(d, o); });
    CHECK(contains(e, "participating media, which need -m pathtrace, time or standard"));
    CHECK(contains(e, "method 'accumulation' with --progressive"));
  }
  auto o = test::smallRenderOptions(RenderMethod::PathTrace, 1, 2, 1);
  o.progressive = true;
  // Progressive pathtrace is no method's passes, media or not.
  CHECK(contains(test::errorMessageOf([&] { test::renderOnce(d, o); }),
                 "--progressive works with the methods time, accumulation and standard, not 'pathtrace'"));
}

TEST_CASE("media: bad media input on the command line: located error, nothing written") {
  std::string dir = test::makeTempDir();
  auto check = [&](const std::string& scene, const std::string& flags, const std::string& message) {
    test::writeFile(dir + "/s.json", scene);
    auto r = test::runTdpm("render '" + dir + "/s.json' -o '" + dir + "/out.exr' -q " + flags);
    CHECK(r.exitCode != 0);
    CHECK(contains(r.output, message));
    CHECK(test::countEntries(dir) == 1);  // only the scene
  };
  check(sceneWith(kFog, R"([{"shape": {"type": "quad"}, "medium": "fog"}])"), "",
        "s.json:1: objects[0].medium: an interior medium needs a closed shape");
  check(sceneWith(kFog, "[]", R"("exterior_medium": "mist")"), "", "exterior_medium: unknown medium \"mist\"");
  check(sceneWith(R"("fog": {"type": "homogeneous", "sigma_a": 1, "sigma_s": 1, "g": 2})"), "", "media.fog.g:");
  check(sceneWith(kFog, "[]", R"("exterior_medium": "fog")"), "-m accumulation --progressive --resolution 4x4",
        "need -m pathtrace, time or standard");
}

TEST_CASE("media: the scene digest covers the media and where they are") {
  auto d = airlightScene(1, 0.1f, 0.1f, 1, 1, 3);
  std::string base = sceneDigest(d);
  auto changed = d;
  changed.media[0].sigmaS = Rgb(0.2f);
  CHECK(sceneDigest(changed) != base);
  changed = d;
  changed.camera.medium = -1;
  CHECK(sceneDigest(changed) != base);
  changed = d;
  changed.media[0].g = 0.5f;
  CHECK(sceneDigest(changed) != base);
  CHECK(sceneDigest(d) == base);
}

TEST_CASE("media: a ray through an absorbing ball behind an interface keeps exp(-sigma_a 2R) of the sky") {
  auto d = test::emptyScene(1, 1);
  d.camera.position = {0, 0, 5};
  d.camera.target = {0, 0, 0};
  scene::MaterialDesc none;
  none.type = scene::MaterialDesc::Type::Interface;
  d.materials.push_back(none);
  d.media.push_back(homogeneousDesc(Rgb(0.4f, 0.2f, 0.1f), Rgb(0.0f)));
  auto ball = test::sphere(1.5f, {0, 0, 0}, 0);
  ball.media.present = true;
  ball.media.inside = 0;
  d.objects.push_back(ball);
  d.background = Rgb(1.0f);
  auto scene = Scene::build(d);
  REQUIRE(scene->hasMedia());
  CHECK(scene->cameraMedium == -1);
  PathTracer pt(*scene, 8);
  Rng rng(31);
  for (int c = 0; c < 3; ++c) {
    double expected = std::exp(-(c == 0 ? 0.4 : c == 1 ? 0.2 : 0.1) * 3.0);
    auto [mean, err] = meanAndError(20000, [&] {
      Rgb L = pt.radiance({0, 0, 5}, {0, 0, -1}, 0.5f, rng);
      return double(c == 0 ? L.r : c == 1 ? L.g : L.b);
    });
    CHECK(std::fabs(mean - expected) < 4 * err + 1e-6);
    CHECK(err < 0.02);
  }
}

TEST_CASE("media: a grid inside a moving object moves with it; media outside objects are static") {
  auto d = test::emptyScene(1, 1);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.media.push_back(rampDesc());
  d.media.push_back(homogeneousDesc(Rgb(0.1f), Rgb(0.1f)));
  auto a = test::box({1, 1, 1}, {0, 0, 0}, 0);
  a.motion = test::translation({0, 0, 0}, {1, 0, 0});
  a.media = {true, 0, 1};
  auto b = test::box({1, 1, 1}, {3, 0, 0}, 0);
  b.media = {true, 0, -1};
  d.objects.push_back(a);
  d.objects.push_back(b);
  d.exteriorMedium = d.camera.medium = 1;
  auto s = Scene::build(d);
  // The grid twice (one instance per object it moves with), the fog once.
  REQUIRE(s->media.size() == 3);
  const media::Medium& inA = s->media[size_t(s->objects[0].mediumInterface.inside)];
  const media::Medium& inB = s->media[size_t(s->objects[1].mediumInterface.inside)];
  CHECK(inA.moving);
  CHECK_FALSE(inB.moving);
  CHECK(inA.density == inB.density);  // shared, not copied
  CHECK(s->objects[0].mediumInterface.outside == s->cameraMedium);
  CHECK(s->media[size_t(s->cameraMedium)].homogeneous());
}
