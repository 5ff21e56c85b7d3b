// tests/test_fingerprint.cpp — render/fingerprint: the same scene and
// options give the same fingerprint; each option that changes the image,
// and any change to the scene, gives another and is named; options that do
// not change the image (threads, exposure, output, quiet) leave it alone.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "cli/render_command.h"
#include "render/fingerprint.h"
#include "scene/parse.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

scene::SceneDescription glassBall() { return scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/glass-ball.json"); }

// A small scene with a mesh (built in code: no OBJ file needed).
scene::SceneDescription meshScene() {
  scene::SceneDescription d;
  d.camera.width = 8;
  d.camera.height = 6;
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.materials.back().name = "grey";
  scene::ObjectDesc tri;
  tri.name = "tri";
  tri.shape.type = scene::ShapeDesc::Type::Mesh;
  tri.shape.meshFile = "/somewhere/tri.obj";
  tri.shape.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.shape.indices = {0, 1, 2};
  d.objects.push_back(tri);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.name = "lamp";
  l.position = {0, 2, 0};
  l.power = Rgb(10.0f);
  d.lights.push_back(l);
  return d;
}

}  // namespace

TEST_CASE("fingerprint: same scene and options, same fingerprint") {
  const RenderOptions o;
  RenderFingerprint a = fingerprintOf(glassBall(), o);
  RenderFingerprint b = fingerprintOf(glassBall(), o);
  CHECK(a.value.size() == 32);
  CHECK(a.value == b.value);
  CHECK(a.settings == b.settings);
  CHECK(settingDifferences(a.settings, b.settings, "old.exr").empty());
  // Where the scene was read from does not matter; its content does.
  scene::SceneDescription moved = glassBall();
  moved.sourcePath = "/elsewhere/copy.json";
  CHECK(fingerprintOf(moved, o).value == a.value);
  scene::SceneDescription m1 = meshScene(), m2 = meshScene();
  m2.objects[0].shape.meshFile = "/another/place/tri.obj";
  CHECK(fingerprintOf(m1, o).value == fingerprintOf(m2, o).value);
  // Material names do not change the image (and duplicates, which a pbrt
  // import could make, do not stop the digest).
  m2.materials[0].name = "renamed";
  CHECK(fingerprintOf(m1, o).value == fingerprintOf(m2, o).value);
  // The scene's own render block enters only through the merged options.
  scene::SceneDescription withBlock = glassBall();
  withBlock.render.exposure = 3.0f;
  withBlock.render.photons = 12345;
  CHECK(sceneDigest(withBlock) == sceneDigest(glassBall()));
}

TEST_CASE("fingerprint: every image-changing option changes it, and is named") {
  const scene::SceneDescription scene = glassBall();
  const RenderOptions base;
  const RenderFingerprint f0 = fingerprintOf(scene, base);
  struct Change {
    const char* key;
    std::function<void(RenderOptions&)> apply;
  };
  const std::vector<Change> changes = {
      {"method", [](RenderOptions& o) { o.method = RenderMethod::Standard; }},
      {"seed", [](RenderOptions& o) { o.seed = 2; }},
      {"sampler", [](RenderOptions& o) { o.sampler = SamplerKind::Random; }},
      {"spp", [](RenderOptions& o) { o.spp = 8; }},
      {"max_spp", [](RenderOptions& o) { o.maxSpp = 64; }},
      {"contrast", [](RenderOptions& o) { o.contrast = 0.1f; }},
      {"max_depth", [](RenderOptions& o) { o.maxDepth = 5; }},
      {"photons", [](RenderOptions& o) { o.causticPhotons = 100000; }},
      {"global_photons", [](RenderOptions& o) { o.globalPhotons = 1; }},
      {"frames", [](RenderOptions& o) { o.frames = 4; }},
      {"search", [](RenderOptions& o) { o.spaceTime4D = true; }},
      {"kappa", [](RenderOptions& o) { o.kappa = 2.0f; }},
      {"k", [](RenderOptions& o) { o.estimate.k = 50; }},
      {"ks", [](RenderOptions& o) { o.estimate.ks = 50; }},
      {"fraction", [](RenderOptions& o) { o.estimate.fraction = 0.25f; }},
      {"max_radius", [](RenderOptions& o) { o.estimate.maxRadius = 0.1f; }},
      {"max_dt", [](RenderOptions& o) { o.estimate.maxTimeDistance = 0.05f; }},
      {"max_radius_fraction", [](RenderOptions& o) { o.maxRadiusFraction = 0.03f; }},
      {"max_dt_fraction", [](RenderOptions& o) { o.maxDtFraction = 0.2f; }},
      {"kernel_space", [](RenderOptions& o) { o.estimate.spaceKernel = estimate::SpaceKernel::Cone; }},
      {"kernel_time", [](RenderOptions& o) { o.estimate.timeKernel = estimate::TimeKernel::Epanechnikov; }},
      {"cone_k", [](RenderOptions& o) { o.estimate.coneK = 1.2f; }},
      {"min_radius2", [](RenderOptions& o) { o.estimate.minRadius2 = 1e-10f; }},
      {"gather", [](RenderOptions& o) { o.gatherRays = 0; }},
      {"global_direct", [](RenderOptions& o) { o.visualizeGlobal = true; }},
      {"filter", [](RenderOptions& o) { o.filter = FilterKind::Gaussian; }},
      {"filter_radius", [](RenderOptions& o) { o.filterRadius = 2.0f; }},
      {"kernel_footprint", [](RenderOptions& o) { o.kernelFootprint = 2.0f; }},
      {"alpha", [](RenderOptions& o) { o.alpha = 0.5f; }},
      {"extra_samples", [](RenderOptions& o) { o.passExtraSamples = 0.5f; }},
      {"gather_guide", [](RenderOptions& o) { o.gatherGuide = false; }},
      {"direct_only", [](RenderOptions& o) { o.directOnly = true; }},
      // The smallest change a float can have: still seen.
      {"contrast", [](RenderOptions& o) { o.contrast = std::nextafter(o.contrast, 1.0f); }},
  };
  for (const Change& c : changes) {
    CAPTURE(c.key);
    RenderOptions o = base;
    c.apply(o);
    RenderFingerprint f = fingerprintOf(scene, o);
    CHECK(f.value != f0.value);
    std::vector<std::string> diff = settingDifferences(f0.settings, f.settings, "old.exr");
    REQUIRE(diff.size() == 1);
    CHECK(diff[0].rfind(std::string(c.key) + ": ", 0) == 0);
  }
  // Settings added after states were first written are keys only when on, so
  // a state written before they existed still resumes at their default.
  for (const char* added : {"extra_samples", "direct_only", "gather_guide"}) CHECK(f0.settings.count(added) == 0);
  // The message names both values and where the old one is.
  RenderOptions fewer = base;
  fewer.causticPhotons = 100000;
  CHECK(settingDifferences(fingerprintOf(scene, RenderOptions{}).settings, fingerprintOf(scene, fewer).settings,
                           "old.exr") == std::vector<std::string>{"photons: 200000 in old.exr, 100000 now"});
  // The resolution.
  scene::SceneDescription bigger = scene;
  bigger.camera.width = 320;
  CHECK(settingDifferences(f0.settings, fingerprintOf(bigger, base).settings, "old.exr") ==
        std::vector<std::string>{"resolution: 640x360 in old.exr, 320x360 now"});
  // A setting that only one side has (a newer or older tdpm).
  std::map<std::string, std::string> withAlpha = f0.settings;
  withAlpha["future_option"] = "0.7";
  CHECK(settingDifferences(withAlpha, f0.settings, "old.exr") ==
        std::vector<std::string>{"future_option: 0.7 in old.exr, not set now"});
  CHECK(fingerprintOfSettings(withAlpha) != f0.value);
  // A state written before the estimator had a version (an older tdpm), or
  // with another version: named as such, and a different fingerprint.
  CHECK(f0.settings.at(kEstimatorSettingKey) == kEstimatorVersion);
  std::map<std::string, std::string> older = f0.settings;
  older.erase(kEstimatorSettingKey);
  CHECK(settingDifferences(older, f0.settings, "old.exr") ==
        std::vector<std::string>{"the estimator differs (an older version in old.exr, version " +
                                 std::string(kEstimatorVersion) + " now): it was written by another tdpm"});
  CHECK(fingerprintOfSettings(older) != f0.value);
  std::map<std::string, std::string> other = f0.settings;
  other[kEstimatorSettingKey] = "1";
  CHECK(settingDifferences(other, f0.settings, "old.exr").size() == 1);
  CHECK(settingDifferences(other, f0.settings, "old.exr")[0].find("version 1 in old.exr") != std::string::npos);
}

TEST_CASE("fingerprint: any change to the scene is 'the scene differs'") {
  const RenderOptions o;
  const scene::SceneDescription s0 = glassBall();
  const RenderFingerprint f0 = fingerprintOf(s0, o);
  const std::vector<std::function<void(scene::SceneDescription&)>> edits = {
      [](scene::SceneDescription& d) { d.lights[0].power.r += 1.0f; },
      [](scene::SceneDescription& d) { d.objects[1].placement.translate.y = std::nextafter(d.objects[1].placement.translate.y, 2.0f); },
      [](scene::SceneDescription& d) { d.objects[1].motion = scene::MotionDesc{}; },
      [](scene::SceneDescription& d) { d.background.g = 0.5f; },
      [](scene::SceneDescription& d) { d.camera.fovDegrees = 40; },
      [](scene::SceneDescription& d) {
        for (scene::MaterialDesc& m : d.materials)
          if (m.type == scene::MaterialDesc::Type::Dielectric) m.ior = 1.33f;
      },
      [](scene::SceneDescription& d) { d.objects.pop_back(); },
  };
  for (size_t i = 0; i < edits.size(); ++i) {
    CAPTURE(i);
    scene::SceneDescription d = s0;
    edits[i](d);
    RenderFingerprint f = fingerprintOf(d, o);
    CHECK(f.value != f0.value);
    CHECK(settingDifferences(f0.settings, f.settings, "old.exr") == std::vector<std::string>{"the scene differs"});
  }
  // Mesh contents: one vertex moved by one float step.
  scene::SceneDescription m = meshScene();
  const std::string d0 = sceneDigest(m);
  m.objects[0].shape.vertices[2].y = std::nextafter(1.0f, 2.0f);
  CHECK(sceneDigest(m) != d0);
  m = meshScene();
  m.objects[0].shape.indices = {0, 2, 1};
  CHECK(sceneDigest(m) != d0);
}

TEST_CASE("fingerprint: threads, exposure, output, quiet and stats do not change it") {
  const scene::SceneDescription scene = glassBall();
  cli::RenderArgs a;
  a.scene = "scenes/glass-ball.json";
  a.photons = 100000;
  const RenderFingerprint f0 = fingerprintOf(scene, cli::renderOptionsFor(a, scene));
  cli::RenderArgs b = a;
  b.threads = 1;
  b.exposure = 2.0f;
  b.output = "/tmp/elsewhere.exr";
  b.quiet = true;
  b.stats = true;
  const RenderFingerprint f1 = fingerprintOf(scene, cli::renderOptionsFor(b, scene));
  CHECK(f1.value == f0.value);
  b.threads = 2;
  CHECK(fingerprintOf(scene, cli::renderOptionsFor(b, scene)).value == f0.value);
  // The same value from the flag or from the scene's block: the same render.
  cli::RenderArgs c;
  c.scene = a.scene;
  scene::SceneDescription fromBlock = scene;
  fromBlock.render.photons = 100000;
  CHECK(fingerprintOf(fromBlock, cli::renderOptionsFor(c, fromBlock)).value == f0.value);
  // And a flag that changes the image does change it, through the same path.
  b.seed = 7;
  CHECK(fingerprintOf(scene, cli::renderOptionsFor(b, scene)).value != f0.value);
  // None of the non-image names is a setting.
  for (const char* key : {"threads", "passes", "time_limit", "exposure", "output", "quiet", "stats"})
    CHECK(f0.settings.count(key) == 0);
}
