// tests/test_integrator_mapping.cpp — pbrt's Integrator lines mapped onto
// tdpm's methods (import/pbrt_import.cpp): directlighting onto pathtrace
// with render.direct_only (and what that renders), bdpt / mlt onto
// pathtrace or time by the scene's lights and surfaces, volpath onto
// pathtrace, sppm's photonsperiteration -1 sized from the rendered
// resolution (render.photons_per_pixel). Each with its note.
#include <doctest/doctest.h>

#include <string>

#include "cli/render_command.h"
#include "error_capture.h"
#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

pbrt::ImportResult importText(const std::string& text) { return pbrt::importPbrtText(text, "dir/t.pbrt"); }

bool hasNote(const pbrt::ImportResult& r, const std::string& part) {
  for (const std::string& n : r.notes)
    if (n.find(part) != std::string::npos) return true;
  return false;
}

const char* kPointAndGlass =
    "WorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\nMaterial \"dielectric\"\nShape \"sphere\"\n";
const char* kAreaAndGlass =
    "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\nShape \"trianglemesh\" \"point3 P\" [0 0 3 1 0 3 1 1 3 0 1 3] "
    "\"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\nMaterial \"dielectric\"\nShape \"sphere\"\n";
const char* kPointAndDiffuse = "WorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\nShape \"sphere\"\n";

}  // namespace

TEST_CASE("pbrt directlighting: pathtrace with direct_only, maxdepth kept, with a note") {
  pbrt::ImportResult r = importText("Integrator \"directlighting\" \"integer maxdepth\" 3 \"string strategy\" \"one\"\n" +
                                    std::string(kPointAndDiffuse));
  CHECK(*r.scene.render.method == "pathtrace");
  REQUIRE(r.scene.render.directOnly);
  CHECK(*r.scene.render.directOnly);
  CHECK(*r.scene.render.maxDepth == 3);
  CHECK(hasNote(r, "dir/t.pbrt:1: Integrator \"directlighting\" mapped to pathtrace with render.direct_only"));
  CHECK(hasNote(r, "\"strategy\" ignored (quality only)"));
  // tdpm convert writes it and the JSON reads it back.
  pbrt::SceneJson j = pbrt::sceneToJson(r.scene, "dir/out.json");
  CHECK(j.json.find("\"direct_only\": true") != std::string::npos);
  scene::SceneDescription back = scene::parseScene(j.json, "dir/out.json");
  CHECK(back.render.directOnly.value_or(false));
}

TEST_CASE("pbrt bdpt and mlt: time where a delta light meets glass or a mirror, else pathtrace") {
  for (const char* integ : {"bdpt", "mlt"}) {
    CAPTURE(integ);
    const std::string head = std::string("Integrator \"") + integ + "\" \"integer maxdepth\" 6\n";
    pbrt::ImportResult caustic = importText(head + kPointAndGlass);
    CHECK(*caustic.scene.render.method == "time");
    CHECK(*caustic.scene.render.maxDepth == 6);
    CHECK(hasNote(caustic, std::string("Integrator \"") + integ + "\" mapped to tdpm's time-dependent photon method"));
    pbrt::ImportResult area = importText(head + kAreaAndGlass);
    CHECK(*area.scene.render.method == "pathtrace");
    CHECK(hasNote(area, std::string("Integrator \"") + integ + "\" mapped to pathtrace"));
    pbrt::ImportResult diffuse = importText(head + kPointAndDiffuse);
    CHECK(*diffuse.scene.render.method == "pathtrace");
  }
  pbrt::ImportResult q = importText("Integrator \"mlt\" \"integer mutationsperpixel\" 100 \"float sigma\" 0.01\n" +
                                    std::string(kPointAndDiffuse));
  CHECK(hasNote(q, "\"mutationsperpixel\" ignored (quality only)"));
  CHECK(hasNote(q, "\"sigma\" ignored (quality only)"));
}

TEST_CASE("pbrt volpath is pathtrace (tdpm's path tracer traces media); a medium is imported") {
  pbrt::ImportResult r = importText("Integrator \"volpath\" \"integer maxdepth\" 4\n" + std::string(kPointAndDiffuse));
  CHECK(*r.scene.render.method == "pathtrace");
  CHECK(*r.scene.render.maxDepth == 4);
  CHECK(hasNote(r, "Integrator \"volpath\" mapped to pathtrace"));
  pbrt::ImportResult m = importText("Integrator \"volpath\"\nWorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n");
  CHECK(m.scene.media.size() == 1);
  CHECK(*m.scene.render.method == "pathtrace");
}

TEST_CASE("pbrt sppm photonsperiteration -1: photons per pixel of the image rendered") {
  pbrt::ImportResult r = importText(
      "Integrator \"sppm\" \"integer numiterations\" 3\nFilm \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30\n" +
      std::string(kPointAndDiffuse));
  CHECK(*r.scene.render.method == "time");
  CHECK_FALSE(r.scene.render.photons.has_value());
  REQUIRE(r.scene.render.photonsPerPixel);
  CHECK(*r.scene.render.photonsPerPixel == 3);
  CHECK(hasNote(r, "photons = numiterations (3) x the rendered image's pixels"));
  // The count follows the resolution rendered, not the file's.
  cli::RenderArgs a;
  a.scene = "dir/t.pbrt";
  CHECK(cli::renderOptionsFor(a, r.scene).causticPhotons == 3u * 40 * 30);
  scene::SceneDescription smaller = r.scene;
  smaller.camera.width = 10;
  smaller.camera.height = 8;
  CHECK(cli::renderOptionsFor(a, smaller).causticPhotons == 3u * 10 * 8);
  a.photons = 777;  // --photons wins
  CHECK(cli::renderOptionsFor(a, smaller).causticPhotons == 777u);
  // Converted: the JSON keeps the per-pixel count.
  pbrt::SceneJson j = pbrt::sceneToJson(r.scene, "dir/out.json");
  CHECK(j.json.find("\"photons_per_pixel\": 3") != std::string::npos);
  // A given count is unchanged.
  pbrt::ImportResult given = importText("Integrator \"sppm\" \"integer numiterations\" 2 \"integer photonsperiteration\" 50\n" +
                                        std::string(kPointAndDiffuse));
  CHECK(*given.scene.render.photons == 100);
  CHECK_FALSE(given.scene.render.photonsPerPixel.has_value());
}

TEST_CASE("JSON direct_only and photons_per_pixel: checks") {
  auto errorOf = [](const std::string& render) {
    return test::errorMessageOf(
        [&] { scene::parseScene(R"({"camera": {"resolution": [4, 4]}, "objects": [], "render": )" + render + "}", "dir/s.json"); });
  };
  CHECK(errorOf(R"({"method": "time", "direct_only": true})")
            .find("render.direct_only: direct_only is a pathtrace setting: it needs render.method \"pathtrace\", not \"time\"") !=
        std::string::npos);
  CHECK(errorOf(R"({"direct_only": true})").find("it needs render.method \"pathtrace\" (none is given)") != std::string::npos);
  CHECK(errorOf(R"({"method": "pathtrace", "direct_only": false})") == "(no error)");
  CHECK(errorOf(R"({"direct_only": 1})").find("render.direct_only: expected true or false") != std::string::npos);
  CHECK(errorOf(R"({"photons": 5, "photons_per_pixel": 2})").find("give photons or photons_per_pixel, not both") !=
        std::string::npos);
  CHECK(errorOf(R"({"photons_per_pixel": 0})").find("photons_per_pixel must be at least 1") != std::string::npos);
  // The method given on the command line is checked too.
  scene::SceneDescription d = scene::parseScene(R"({"camera": {"resolution": [4, 4]}, "objects": [], "render": {"method": "pathtrace", "direct_only": true}})", "dir/s.json");
  cli::RenderArgs a;
  a.scene = "dir/s.json";
  a.method = "time";
  CHECK(test::errorMessageOf([&] { cli::renderOptionsFor(a, d); }).find("render.direct_only in dir/s.json is a pathtrace setting") !=
        std::string::npos);
  // Over the photon limit at the rendered size.
  scene::SceneDescription big = scene::parseScene(
      R"({"camera": {"resolution": [65536, 65536]}, "objects": [], "render": {"photons_per_pixel": 1000}})", "dir/s.json");
  a.method.reset();
  CHECK(test::errorMessageOf([&] { cli::renderOptionsFor(a, big); }).find("more than tdpm's limit") != std::string::npos);
}

namespace {

// A floor and a wall (diffuse), a mirror, a point light: where direct-only
// differs from full path tracing (interreflection) and from depth 1 (the
// mirror shows the lit floor).
scene::SceneDescription directStage(bool withMirror) {
  auto d = test::emptyScene(32, 24);
  d.camera.position = {0, 1.5f, 5};
  d.camera.target = {0, 0.5f, 0};
  d.materials.push_back(test::diffuse(Rgb(0.8f)));
  scene::MaterialDesc mirror;
  mirror.type = scene::MaterialDesc::Type::Mirror;
  d.materials.push_back(mirror);
  d.objects.push_back(test::quad({6, 6}, {0, 0, 0}, 0));
  d.objects.push_back(test::box({6, 3, 0.2f}, {0, 1.5f, -2}, 0));
  if (withMirror) d.objects.push_back(test::sphere(0.6f, {0.5f, 0.6f, 0.5f}, 1));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {-1, 2.5f, 1};
  l.power = Rgb(300.0f);
  d.lights.push_back(l);
  return d;
}

}  // namespace

TEST_CASE("direct_only renders pbrt's directlighting: direct light, through specular bounces only") {
  RenderOptions direct = test::smallRenderOptions(RenderMethod::PathTrace, 4, 5, 3);
  direct.directOnly = true;
  RenderOptions depth1 = test::smallRenderOptions(RenderMethod::PathTrace, 4, 1, 3);
  RenderOptions full = test::smallRenderOptions(RenderMethod::PathTrace, 4, 5, 3);
  // Diffuse only: direct-only is exactly a path of one scattering vertex.
  Film a = test::renderOnce(directStage(false), direct);
  Film b = test::renderOnce(directStage(false), depth1);
  CHECK(test::sameImage(a, b));
  // Full path tracing adds the interreflection between floor and wall.
  CHECK(test::imageSum(test::renderOnce(directStage(false), full)) > 1.05 * test::imageSum(a));
  // With a mirror: direct-only sees the lit floor in it (depth 1 does not)
  // and still lacks the interreflection.
  double sDirect = test::imageSum(test::renderOnce(directStage(true), direct));
  double sDepth1 = test::imageSum(test::renderOnce(directStage(true), depth1));
  double sFull = test::imageSum(test::renderOnce(directStage(true), full));
  CHECK(sDirect > 1.01 * sDepth1);
  CHECK(sFull > 1.05 * sDirect);
}
