// tests/test_pbrt_media.cpp — import/pbrt_media.cpp and the media keys of
// scene/json_writer.cpp: pbrt's MakeNamedMedium (homogeneous with presets,
// uniformgrid / heterogeneous, nanovdb), MediumInterface on shapes, lights
// and the camera, the "interface" material, each located refusal, and the
// JSON that `tdpm convert` writes for them (compared to expected text; the
// round trip through the JSON parser is checked where the parser reads media).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "error_capture.h"
#include "import/pbrt_import.h"
#include "scene/json_writer.h"

using namespace tdpm;

namespace {

pbrt::ImportResult importText(const std::string& text, const std::string& file = "dir/m.pbrt") {
  return pbrt::importPbrtText(text, file);
}

std::string errorOf(const std::string& text, const std::string& file = "dir/m.pbrt") {
  return test::errorMessageOf([&] { pbrt::importPbrtText(text, file); });
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

bool hasNote(const pbrt::ImportResult& r, const std::string& part) {
  for (const auto& n : r.notes)
    if (contains(n, part)) return true;
  return false;
}

void checkRgb(Rgb c, float r, float g, float b) {
  CHECK(c.r == r);
  CHECK(c.g == g);
  CHECK(c.b == b);
}

// A closed box of two triangles per face is more than needed: one quad (two
// triangles) facing +z through N, wound the other way when `flip`.
std::string quad(bool flip) {
  return std::string("Shape \"trianglemesh\" \"point3 P\" [-1 -1 5  1 -1 5  1 1 5  -1 1 5] ") +
         (flip ? "\"integer indices\" [0 2 1 0 3 2]" : "\"integer indices\" [0 1 2 0 2 3]") +
         " \"normal N\" [0 0 1 0 0 1 0 0 1 0 0 1]\n";
}

const char* kFog =
    "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.2 0.3] "
    "\"rgb sigma_s\" [0.5 0.6 0.7] \"float scale\" 2 \"float g\" 0.25\n";

}  // namespace

TEST_CASE("pbrt media: homogeneous coefficients, the camera's, lights' and shapes' media, pbrt's rules") {
  std::string text = std::string("Integrator \"volpath\"\n") +
                     "MediumInterface \"\" \"fog\"\n"  // before Camera: the camera is in fog
                     "Camera \"perspective\"\nWorldBegin\n" + kFog +
                     "LightSource \"point\" \"point3 from\" [0 0 0]\n"  // outside medium current: fog
                     "AttributeBegin\nMediumInterface \"\" \"fog\"\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n"
                     "AttributeBegin\nMediumInterface \"fog\"\nShape \"sphere\" \"float radius\" 0.25\nAttributeEnd\n"
                     "MediumInterface \"\" \"\"\nShape \"sphere\" \"float radius\" 0.1\n";
  pbrt::ImportResult r = importText(text);
  const scene::SceneDescription& d = r.scene;
  REQUIRE(d.media.size() == 1);
  const scene::MediumDesc& m = d.media[0];
  CHECK(m.name == "fog");
  CHECK(m.type == scene::MediumDesc::Type::Homogeneous);
  checkRgb(m.sigmaA, 0.1f, 0.2f, 0.3f);
  checkRgb(m.sigmaS, 0.5f, 0.6f, 0.7f);
  CHECK(m.scale == 2.0f);
  CHECK(m.g == 0.25f);
  CHECK(d.exteriorMedium == -1);  // pbrt has none
  CHECK(d.camera.medium == 0);
  REQUIRE(d.lights.size() == 1);
  CHECK(d.lights[0].medium == 0);
  REQUIRE(d.objects.size() == 3);
  CHECK(d.objects[0].media.present);
  CHECK(d.objects[0].media.inside == -1);
  CHECK(d.objects[0].media.outside == 0);
  // One name: the same medium on both sides, which pbrt treats as no boundary.
  CHECK_FALSE(d.objects[1].media.present);
  CHECK_FALSE(d.objects[2].media.present);
  CHECK(d.render.method == std::string("pathtrace"));
  CHECK(hasNote(r, "Integrator \"volpath\" mapped to pathtrace"));
  // Media may be made after they are named (pbrt-v4 resolves names at the end).
  pbrt::ImportResult late = importText("WorldBegin\nMediumInterface \"in\" \"\"\nShape \"sphere\"\n"
                                       "MakeNamedMedium \"in\" \"string type\" \"homogeneous\"\n");
  CHECK(late.scene.objects[0].media.inside == 0);
  checkRgb(late.scene.media[0].sigmaA, 1, 1, 1);  // pbrt-v4's defaults
  checkRgb(late.scene.media[0].sigmaS, 1, 1, 1);
}

TEST_CASE("pbrt media presets: pbrt's measured table; v4 replaces sigma_a/sigma_s, v3 lets them override") {
  const std::string v4 = "WorldBegin\nMakeNamedMedium \"k\" \"string type\" \"homogeneous\" \"string preset\" \"Ketchup\" "
                         "\"rgb sigma_a\" [9 9 9] \"float scale\" 10\n";
  pbrt::ImportResult r = importText(v4);
  checkRgb(r.scene.media[0].sigmaA, 0.061f, 0.97f, 1.45f);
  checkRgb(r.scene.media[0].sigmaS, 0.18f, 0.07f, 0.03f);  // sigma'_s as sigma_s, mm^-1 as pbrt uses them
  CHECK(r.scene.media[0].scale == 10.0f);
  CHECK(hasNote(r, "\"sigma_a\" ignored: a preset replaces it"));
  // pbrt-v3 (Film "image"): the preset gives defaults, sigma_a overrides.
  pbrt::ImportResult v3 = importText("Film \"image\"\n" + v4);
  checkRgb(v3.scene.media[0].sigmaA, 9, 9, 9);
  checkRgb(v3.scene.media[0].sigmaS, 0.18f, 0.07f, 0.03f);
  // pbrt-v3's defaults without a preset: its whole milk.
  pbrt::ImportResult milk = importText("Film \"image\"\nWorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n");
  checkRgb(milk.scene.media[0].sigmaA, 0.0011f, 0.0024f, 0.014f);
  checkRgb(milk.scene.media[0].sigmaS, 2.55f, 3.21f, 3.77f);
  pbrt::ImportResult ocean = importText("WorldBegin\nMakeNamedMedium \"o\" \"string type\" \"homogeneous\" "
                                        "\"string preset\" \"Pacific Ocean Surface Water\"\n");
  checkRgb(ocean.scene.media[0].sigmaA, 0.031845f, 0.031324f, 0.030147f);
}

TEST_CASE("pbrt grid media: uniformgrid and v3 heterogeneous densities, p0 p1 and the CTM as the medium's placement") {
  for (const char* type : {"uniformgrid", "heterogeneous"}) {
    CAPTURE(type);
    std::string text = std::string("WorldBegin\nAttributeBegin\nTranslate 1 2 3\nMakeNamedMedium \"smoke\" \"string type\" \"") + type +
                       "\" \"integer nx\" 2 \"integer ny\" 1 \"integer nz\" 2 \"float density\" [0 1 2 3.5] "
                       "\"point3 p0\" [-1 0 0] \"point3 p1\" [1 0.5 4] \"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [1 1 1]\n"
                       "AttributeEnd\n";
    scene::SceneDescription d = importText(text).scene;
    REQUIRE(d.media.size() == 1);
    const scene::MediumDesc& m = d.media[0];
    CHECK(m.type == scene::MediumDesc::Type::Grid);
    CHECK((m.grid.nx == 2 && m.grid.ny == 1 && m.grid.nz == 2));
    CHECK(m.grid.density == std::vector<float>{0, 1, 2, 3.5f});
    CHECK(m.grid.file.empty());
    CHECK(m.grid.bounds.lo.x == -1.0f);
    CHECK(m.grid.bounds.hi.z == 4.0f);
    // Medium space -> world, with tdpm's x mirror of pbrt's camera frame
    // (the default camera: world x -> -x).
    Affine3f a = m.placement.matrix();
    Vec3f o = a.point({0, 0, 0}), x = a.point({1, 0, 0}), z = a.point({0, 0, 1});
    CHECK(o.x == doctest::Approx(-1));
    CHECK(o.y == doctest::Approx(2));
    CHECK(o.z == doctest::Approx(3));
    CHECK(x.x == doctest::Approx(-2));
    CHECK(z.z == doctest::Approx(4));
  }
}

TEST_CASE("pbrt nanovdb medium: the file's density grid, its world bounds, named by reference") {
  std::string dir = test::makeTempDir();
  nanovdb::GridBuilder<float> builder(0.0f, nanovdb::GridClass::FogVolume);
  auto acc = builder.getAccessor();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) acc.setValue(nanovdb::Coord(i, j, k), float(1 + i + 3 * j + 6 * k));
  nanovdb::io::writeGrid(dir + "/cloud.nvdb", builder.getHandle<>(0.5, nanovdb::Vec3d(0, 0, 0), "density"));
  pbrt::ImportResult r = pbrt::importPbrtText(
      "WorldBegin\nMakeNamedMedium \"c\" \"string type\" \"nanovdb\" \"string filename\" \"cloud.nvdb\"\n", dir + "/s.pbrt");
  const scene::MediumDesc& m = r.scene.media.at(0);
  CHECK(m.grid.file == dir + "/cloud.nvdb");
  CHECK(m.grid.gridName == "density");
  CHECK((m.grid.nx == 3 && m.grid.ny == 2 && m.grid.nz == 2));
  CHECK(m.grid.density[11] == 12.0f);
  CHECK(m.grid.bounds.lo.x == -0.25f);
  CHECK(m.grid.bounds.hi.x == 1.25f);
  // The JSON names the file relative to itself, and the grid.
  nlohmann::json j = nlohmann::json::parse(pbrt::sceneToJson(r.scene, dir + "/out.json").json);
  CHECK(j["media"]["c"]["file"] == "cloud.nvdb");
  CHECK(j["media"]["c"]["grid"] == "density");
  CHECK_FALSE(j["media"]["c"].contains("density"));
  CHECK(contains(errorOf("WorldBegin\nMakeNamedMedium \"c\" \"string type\" \"nanovdb\" \"string filename\" \"none.nvdb\"\n",
                         dir + "/s.pbrt"),
                 dir + "/s.pbrt:2: MakeNamedMedium \"c\": density grid file \"" + dir + "/none.nvdb\""));
}

TEST_CASE("pbrt interface material: kept as an Interface object between two media, dropped without") {
  std::string text = std::string("WorldBegin\n") + kFog +
                     "MakeNamedMaterial \"glassless\" \"string type\" \"interface\"\nNamedMaterial \"glassless\"\n"
                     "Shape \"sphere\"\n"  // no media: dropped, as before
                     "AttributeBegin\nMediumInterface \"fog\" \"\"\nShape \"sphere\" \"float radius\" 2\nAttributeEnd\n";
  scene::SceneDescription d = importText(text).scene;
  REQUIRE(d.objects.size() == 1);
  CHECK(d.objects[0].shape.radius == 2.0f);
  const scene::MaterialDesc& mat = d.materials.at(d.objects[0].material);
  CHECK(mat.type == scene::MaterialDesc::Type::Interface);
  CHECK(mat.name == "interface");
  CHECK(d.objects[0].media.inside == 0);
  CHECK(d.objects[0].media.outside == -1);
}

TEST_CASE("pbrt media boundary on a mesh: its sides follow the shading normals N, as pbrt's") {
  for (bool flip : {false, true}) {
    CAPTURE(flip);
    std::string text = std::string("WorldBegin\n") + kFog + "MediumInterface \"fog\" \"\"\n" + quad(flip);
    scene::SceneDescription d = importText(text).scene;
    REQUIRE(d.objects.size() == 1);
    const scene::ShapeDesc& s = d.objects[0].shape;
    // Every triangle's winding normal points along N (+z; the x mirror
    // keeps it, the bake swapping the winding back).
    for (size_t t = 0; t < s.indices.size(); t += 3) {
      Vec3f n = cross(s.vertices[s.indices[t + 1]] - s.vertices[s.indices[t]], s.vertices[s.indices[t + 2]] - s.vertices[s.indices[t]]);
      CHECK(n.z > 0);
    }
    CHECK_FALSE(s.reverseOrientation);
  }
}

TEST_CASE("pbrt media: each refusal names file:line and the reason") {
  auto world = [](const std::string& body) { return "WorldBegin\n" + body; };
  const std::string medium = "MakeNamedMedium \"m\" \"string type\" ";
  struct Case {
    std::string text, expected;
  } cases[] = {
      {world("MediumInterface \"nope\" \"\"\nShape \"sphere\"\n"),
       "dir/m.pbrt:2: MediumInterface: no medium named \"nope\" has been made (MakeNamedMedium); used by Shape \"sphere\" at dir/m.pbrt:3"},
      {"MediumInterface \"\" \"air\"\nCamera \"perspective\"\nWorldBegin\n",
       "dir/m.pbrt:1: the camera's medium: no medium named \"air\""},
      {world(medium + "\"homogeneous\" \"string preset\" \"Jam\"\n"), "dir/m.pbrt:2: MakeNamedMedium \"m\": parameter \"string preset\": unknown preset \"Jam\""},
      {world(medium + "\"rgbgrid\"\n"), "dir/m.pbrt:2: MakeNamedMedium \"m\": \"rgbgrid\""},
      {world(medium + "\"cloud\"\n"), "dir/m.pbrt:2: MakeNamedMedium \"m\": \"cloud\""},
      {world(medium + "\"smog\"\n"), "unknown medium type \"smog\""},
      {world(medium + "\"homogeneous\" \"rgb Le\" [1 1 1]\n"), "an emissive medium (\"Le\") is not supported"},
      {world(medium + "\"uniformgrid\" \"integer nx\" 2 \"float density\" [1]\n"), "1 values, expected nx x ny x nz = 2 x 1 x 1"},
      {world(medium + "\"uniformgrid\" \"float density\" [-1]\n"), "densities must be finite and >= 0"},
      {world(medium + "\"uniformgrid\" \"float density\" [1] \"float temperature\" [900]\n"), "emit light"},
      {world(medium + "\"homogeneous\" \"float g\" 1\n"), "g must be in (-1, 1), got 1"},
      {world(medium + "\"homogeneous\" \"rgb sigma_s\" [1 -1 1]\n"), "parameter \"rgb sigma_s\": must be finite and >= 0"},
      {world(medium + "\"homogeneous\"\n" + medium + "\"homogeneous\"\n"), "dir/m.pbrt:3: MakeNamedMedium \"m\": a medium of that name has already been made"},
      {world("MakeNamedMedium \"\" \"string type\" \"homogeneous\"\n"), "a medium needs a name"},
      {world(medium + "\"nanovdb\"\n"), "missing parameter \"string filename\""},
      {world(medium + "\"uniformgrid\" \"float density\" [1]\nMediumInterface \"m\" \"\"\nShape \"sphere\"\n"),
       "dir/m.pbrt:4: Shape \"sphere\" (dir/m.pbrt:4): its MediumInterface names the grid medium \"m\""},
      {world(medium + "\"homogeneous\"\nMediumInterface \"m\" \"\"\nAreaLightSource \"diffuse\" \"bool twosided\" true\n" + quad(false)),
       "a two-sided emitter between two media"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.text);
    std::string e = errorOf(c.text);
    CHECK_MESSAGE(contains(e, c.expected), e);
  }
}

TEST_CASE("tdpm convert's JSON: the media keys exactly as the format says") {
  std::string text = std::string("MediumInterface \"\" \"fog\"\nCamera \"perspective\"\nWorldBegin\n") + kFog +
                     "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [0.5 2] "
                     "\"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [1 1 1] \"float g\" -0.5\n"
                     "LightSource \"point\"\n"
                     "MakeNamedMaterial \"none\" \"string type\" \"interface\"\nNamedMaterial \"none\"\n"
                     "MediumInterface \"smoke\" \"fog\"\n" + quad(false);
  scene::SceneDescription d = importText(text).scene;
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(pbrt::sceneToJson(d, "/tmp/x/s.json").json);
  CHECK(j["media"].dump() ==
        "{\"fog\":{\"type\":\"homogeneous\",\"sigma_a\":[0.1,0.2,0.3],\"sigma_s\":[0.5,0.6,0.7],\"scale\":2.0,\"g\":0.25},"
        "\"smoke\":{\"type\":\"grid\",\"sigma_a\":[0.0,0.0,0.0],\"sigma_s\":[1.0,1.0,1.0],\"scale\":1.0,\"g\":-0.5,"
        "\"resolution\":[2,1,1],\"density\":[0.5,2.0],\"bounds\":[[0.0,0.0,0.0],[1.0,1.0,1.0]],"
        "\"transform\":{\"scale\":[-1.0,1.0,1.0]}}}");
  CHECK_FALSE(j.contains("exterior_medium"));  // pbrt has none: vacuum, the JSON's default
  CHECK(j["camera"]["medium"] == "fog");
  CHECK(j["lights"][0]["medium"] == "fog");
  REQUIRE(j["objects"].size() == 1);
  CHECK(j["objects"][0]["material"] == "interface");
  CHECK(j["objects"][0]["medium_interface"].dump() == "{\"inside\":\"smoke\",\"outside\":\"fog\"}");
  CHECK(j["materials"]["interface"].dump() == "{\"type\":\"interface\"}");
  // Vacuum on a side is null; a scene without media writes none of the keys.
  d.objects[0].media.inside = -1;
  j = nlohmann::ordered_json::parse(pbrt::sceneToJson(d, "/tmp/x/s.json").json);
  CHECK(j["objects"][0]["medium_interface"].dump() == "{\"inside\":null,\"outside\":\"fog\"}");
  scene::SceneDescription plain = importText("WorldBegin\nShape \"sphere\"\nLightSource \"point\"\n").scene;
  std::string js = pbrt::sceneToJson(plain, "/tmp/x/p.json").json;
  for (const char* key : {"media", "exterior_medium", "\"medium\"", "medium_interface"}) CHECK_FALSE(contains(js, key));
}

TEST_CASE("cli: tdpm convert writes a pbrt scene with media as JSON with its media") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/f.pbrt", std::string("Integrator \"volpath\"\nCamera \"perspective\"\nWorldBegin\n") + kFog +
                                       "LightSource \"point\" \"point3 from\" [0 0 2]\n"
                                       "AttributeBegin\nMediumInterface \"\" \"fog\"\nShape \"sphere\"\nAttributeEnd\n");
  auto c = test::runTdpm("convert '" + dir + "/f.pbrt' -o '" + dir + "/f.json' -q");
  REQUIRE_MESSAGE(c.exitCode == 0, c.output);
  std::ifstream in(dir + "/f.json");
  nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["media"]["fog"]["type"] == "homogeneous");
  CHECK(j["objects"][0]["medium_interface"]["outside"] == "fog");
  CHECK(j["objects"][0]["medium_interface"]["inside"].is_null());
  CHECK(j["render"]["method"] == "pathtrace");
  std::filesystem::remove_all(dir);
}

TEST_CASE("cli: without the OpenVDB module a .vdb grid is a located error, nothing written") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/smoke.vdb", "not read: the reader is missing\n");
  test::writeFile(dir + "/f.pbrt", "WorldBegin\nMakeNamedMedium \"s\" \"string type\" \"nanovdb\" \"string filename\" \"smoke.vdb\"\n");
  auto c = test::runShell("TDPM_OPENVDB_MODULE=" + dir + "/none.so '" + TDPM_BINARY + "' convert '" + dir + "/f.pbrt' -o '" + dir +
                          "/f.json' -q");
  CHECK(c.exitCode == 1);
  CHECK(contains(c.output, dir + "/f.pbrt:2: MakeNamedMedium \"s\": density grid file \"" + dir +
                               "/smoke.vdb\": OpenVDB support (libtdpm_openvdb.so) could not be loaded"));
  CHECK_FALSE(test::fileExists(dir + "/f.json"));
  std::filesystem::remove_all(dir);
}
