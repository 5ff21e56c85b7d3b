// tests/test_pbrt_hostile.cpp — issue 27's pbrt, convert and compare cases:
// the import's budgets (file size before reading, total bytes, include
// count, nesting depth, instanced triangles), a FIFO named by Include or
// plymesh, one set of limits for pbrt and JSON (the imported scene passes
// the JSON checks or gets a located error), messages that name the right
// cause and place, `tdpm convert` refusing outputs that are inputs (by file
// identity) before writing anything, and `tdpm compare` reading sizes from
// headers and refusing outputs that are inputs by identity.
#include <doctest/doctest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "cli_harness.h"
#include "core/regular_file.h"
#include "error_capture.h"
#include "image/image_header.h"
#include "import/pbrt_import.h"
#include "import/ply_reader.h"
#include "scene/json_writer.h"
#include "scene/limits.h"
#include "scene/parse.h"

using namespace tdpm;

namespace {

std::string errorOf(const std::string& text, const std::string& file = "dir/q.pbrt") {
  return test::errorMessageOf([&] { pbrt::importPbrtText(text, file); });
}

std::string fileErrorOf(const std::string& path) {
  return test::errorMessageOf([&] { pbrt::importPbrtFile(path); });
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const std::string kCamera =
    "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
    "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 6\n";

}  // namespace

// ---------------------------------------------------------------- item 4: budgets

TEST_CASE("pbrt budgets: an Include larger than the per-file limit is refused by its size, before it is read") {
  std::string dir = test::makeTempDir();
  // A sparse file: its size is known from stat, no byte of it is read.
  { std::ofstream(dir + "/big.pbrt"); }
  REQUIRE(truncate((dir + "/big.pbrt").c_str(), off_t(scene::limits::kMaxPbrtFileBytes + 1)) == 0);
  test::writeFile(dir + "/main.pbrt", "WorldBegin\n\nInclude \"big.pbrt\"\n");
  std::string e = fileErrorOf(dir + "/main.pbrt");
  CHECK(contains(e, dir + "/main.pbrt:3: Include: "));
  CHECK(contains(e, "pbrt file is too large (268435457 bytes; at most 256 MiB per file"));
  std::remove((dir + "/big.pbrt").c_str());
}

TEST_CASE("pbrt budgets: files including each other repeatedly stop at the include count, at the Include's line") {
  std::string dir = test::makeTempDir();
  // 26 files each including the next twice: 2^25 includes without a count.
  for (int i = 0; i < 26; ++i)
    test::writeFile(dir + "/f" + std::to_string(i) + ".pbrt",
                    i < 25 ? "Include \"f" + std::to_string(i + 1) + ".pbrt\"\nInclude \"f" + std::to_string(i + 1) + ".pbrt\"\n"
                           : "Shape \"sphere\"\n");
  test::writeFile(dir + "/main.pbrt", "WorldBegin\nInclude \"f0.pbrt\"\n");
  std::string e = fileErrorOf(dir + "/main.pbrt");
  CHECK(contains(e, ".pbrt:1: Include \"f"));
  CHECK(contains(e, "more than 4096 Include/Import statements in one scene"));
}

TEST_CASE("pbrt budgets: the total bytes of all files are bounded (a file included many times counts each time)") {
  // Checked without writing 512 MiB: a 1 MiB file, included until the
  // total passes the limit, is refused by the total, not the count.
  std::string dir = test::makeTempDir();
  std::string body(1 << 20, ' ');
  body += "\n";
  test::writeFile(dir + "/pad.pbrt", body);
  std::string main = "WorldBegin\n";
  for (int i = 0; i < 600; ++i) main += "Include \"pad.pbrt\"\n";
  test::writeFile(dir + "/main.pbrt", main);
  std::string e = fileErrorOf(dir + "/main.pbrt");
  CHECK(contains(e, "main.pbrt:"));
  CHECK(contains(e, "the scene's files together are larger than 512 MiB"));
}

TEST_CASE("pbrt budgets: AttributeBegin nesting deeper than the limit is refused at the statement") {
  std::string text = "WorldBegin\n";
  for (int i = 0; i < scene::limits::kMaxPbrtNesting + 5; ++i) text += "AttributeBegin\n";
  std::string e = errorOf(text);
  CHECK(e == "dir/q.pbrt:" + std::to_string(scene::limits::kMaxPbrtNesting + 2) +
                 ": AttributeBegin: AttributeBegin/TransformBegin/ObjectBegin nested more than 1024 deep");
  // 1024 open levels are fine (closed again).
  std::string ok = "WorldBegin\n";
  for (int i = 0; i < scene::limits::kMaxPbrtNesting; ++i) ok += "TransformBegin\n";
  for (int i = 0; i < scene::limits::kMaxPbrtNesting; ++i) ok += "TransformEnd\n";
  CHECK(test::errorMessageOf([&] { pbrt::importPbrtText(ok, "dir/q.pbrt"); }) == "(no error)");
}

TEST_CASE("pbrt budgets: instanced triangles are counted before each copy is made") {
  // The budget is lowered to 1000 for the test (the real one, 2^27, would
  // need gigabytes to reach): a 100-triangle object fits 10 times.
  std::string P, idx;
  for (int i = 0; i < 102; ++i) P += std::to_string(i % 51) + " " + std::to_string(i / 51) + " 0 ";
  for (int i = 0; i < 50; ++i)
    idx += std::to_string(i) + " " + std::to_string(i + 1) + " " + std::to_string(i + 52) + " " + std::to_string(i) + " " +
           std::to_string(i + 52) + " " + std::to_string(i + 51) + " ";
  std::string text = "WorldBegin\nObjectBegin \"strip\"\nShape \"trianglemesh\" \"point P\" [" + P + "] \"integer indices\" [" + idx +
                     "]\nObjectEnd\n";
  for (int i = 0; i < 10; ++i) text += "ObjectInstance \"strip\"\n";
  pbrt::ImportResult ok = pbrt::importPbrtText(text, "dir/q.pbrt", 1000);
  CHECK(ok.scene.objects.size() == 10);
  text += "ObjectInstance \"strip\"\n";  // line 15: the 11th copy
  // The copies still to come in the file are counted at the first one
  // (line 5), once its size is known: 10 more copies are not built first.
  std::string e = test::errorMessageOf([&] { pbrt::importPbrtText(text, "dir/q.pbrt", 1000); });
  CHECK(e == "dir/q.pbrt:5: ObjectInstance \"strip\" (its 10 later copies in this file): the scene would have 1100 triangles, "
             "more than tdpm's limit of 1000 (instanced copies count in full)");
  // An included file's copies are counted with that file's own later ones.
  std::string dir = test::makeTempDir();
  std::string more;
  for (int i = 0; i < 5; ++i) more += "ObjectInstance \"strip\"\n";
  test::writeFile(dir + "/more.pbrt", more);
  std::string head = text.substr(0, text.find("ObjectInstance"));
  std::string main = head;
  for (int i = 0; i < 6; ++i) main += "ObjectInstance \"strip\"\n";
  main += "Include \"more.pbrt\"\n";
  e = test::errorMessageOf([&] { pbrt::importPbrtText(main, dir + "/q.pbrt", 1000); });
  CHECK(e == dir + "/more.pbrt:1: ObjectInstance \"strip\" (with its 4 later copies in this file): the scene would have 1100 "
                   "triangles, more than tdpm's limit of 1000 (instanced copies count in full)");
  // Without instancing, the shape itself is counted at its line.
  e = test::errorMessageOf([&] {
    pbrt::importPbrtText("WorldBegin\nShape \"trianglemesh\" \"point P\" [" + P + "] \"integer indices\" [" + idx + "]\n",
                         "dir/q.pbrt", 99);
  });
  CHECK(e == "dir/q.pbrt:2: Shape \"trianglemesh\": the scene would have 100 triangles, more than tdpm's limit of 99 "
             "(instanced copies count in full)");
}

TEST_CASE("pbrt budgets: a PLY claiming more vertices than 32-bit indices allow names the limit, not a malformed line") {
  std::string e = test::errorMessageOf([] {
    pbrt::parsePly("ply\nformat ascii 1.0\nelement vertex 1099511627776\nproperty float x\nend_header\n", "m.ply");
  });
  CHECK(e == "m.ply: element \"vertex\" claims 1099511627776 entries, more than tdpm's limit of 4294967295");
  // Leading zeros do not hide a small count.
  CHECK(!contains(test::errorMessageOf([] {
    pbrt::parsePly("ply\nformat ascii 1.0\nelement vertex 0000000000003\nproperty float x\nend_header\n1\n2\n3\n", "m.ply");
  }), "limit"));
}

// ---------------------------------------------------------------- item 6: FIFOs

TEST_CASE("pbrt: a FIFO named by Include or plymesh is refused before open (which would block)") {
  std::string dir = test::makeTempDir();
  REQUIRE(mkfifo((dir + "/pipe.pbrt").c_str(), 0600) == 0);
  REQUIRE(mkfifo((dir + "/pipe.ply").c_str(), 0600) == 0);
  test::writeFile(dir + "/a.pbrt", "WorldBegin\nInclude \"pipe.pbrt\"\n");
  CHECK(fileErrorOf(dir + "/a.pbrt") == dir + "/a.pbrt:2: Include: " + dir +
                                           "/pipe.pbrt: cannot read scene file: it is a FIFO (named pipe), not a regular file");
  test::writeFile(dir + "/b.pbrt", "WorldBegin\nShape \"plymesh\" \"string filename\" \"pipe.ply\"\n");
  CHECK(contains(fileErrorOf(dir + "/b.pbrt"), "b.pbrt:2: Shape \"plymesh\": " + dir +
                                                   "/pipe.ply: cannot read PLY file: it is a FIFO (named pipe)"));
  // The main scene file itself, too.
  CHECK(contains(fileErrorOf(dir + "/pipe.pbrt"), "it is a FIFO (named pipe)"));
  CHECK(checkRegularFile(dir + "/a.pbrt").ok);
  CHECK(checkRegularFile(dir).problem == "it is a directory");
  CHECK(checkRegularFile(dir + "/none").problem == "it does not exist");
}

// ---------------------------------------------------------------- item 9: one set of limits

TEST_CASE("pbrt and JSON share their limits: what the JSON refuses, the import refuses at the pbrt statement") {
  std::string light = "LightSource \"point\" \"point from\" [0 0 -4] \"rgb I\" [5 5 5]\n";
  // Keyframes 1e-30 apart (TransformTimes 0 1e-30): the JSON parser's gap rule.
  std::string e = errorOf(kCamera.substr(0, kCamera.find("Camera")) + "TransformTimes 0 1e-30\n" +
                          kCamera.substr(kCamera.find("Camera")) + "WorldBegin\n" + light +
                          "AttributeBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\nShape \"sphere\"\nAttributeEnd\n");
  CHECK(contains(e, "dir/q.pbrt:11: tdpm's scene checks refuse what Shape \"sphere\" (dir/q.pbrt:11) maps to"));
  CHECK(contains(e, "objects[0].motion[1].time: keyframe time 1e-30 is too close to the previous one"));
  // A moving scale of 1e-20: degenerate, said as such.
  e = errorOf(kCamera + "WorldBegin\n" + light +
              "AttributeBegin\nActiveTransform EndTime\nScale 1e-20 1e-20 1e-20\nActiveTransform All\nShape \"sphere\"\nAttributeEnd\n");
  CHECK(e == "dir/q.pbrt:10: Shape \"sphere\": its EndTime transform is unusable: it scales an axis by 1e-20, which is "
             "degenerate (too small); tdpm needs scale factors in [1e-12, 1e+12]");
  // The accepted scene passes the JSON checks and keeps its meshes (lent, given back).
  pbrt::ImportResult ok = pbrt::importPbrtText(
      kCamera + "WorldBegin\n" + light + "Shape \"trianglemesh\" \"point P\" [-1 -1 0 1 -1 0 1 1 0] \"integer indices\" [0 1 2]\n",
      "dir/q.pbrt");
  REQUIRE(ok.scene.objects.size() == 1);
  CHECK(ok.scene.objects[0].shape.vertices.size() == 3);
  CHECK(ok.scene.objects[0].shape.indices.size() == 3);
}

TEST_CASE("pbrt: a pbrt-v4 exposure that makes lights infinite is refused at the Film") {
  std::string e = errorOf("Camera \"perspective\" \"float shutterclose\" 1e30\nFilm \"rgb\" \"float iso\" 1e30\nWorldBegin\n"
                          "LightSource \"point\" \"rgb I\" [5 5 5]\nShape \"sphere\"\n");
  CHECK(e == "dir/q.pbrt:2: Film: pbrt-v4 scales the image by exposure time x ISO / 100 = 1e+58, which makes LightSource "
             "\"point\" (dir/q.pbrt:4) infinitely bright (its power overflows a float)");
  // A light whose own numbers overflow is refused at the light.
  e = errorOf("WorldBegin\nLightSource \"point\" \"rgb I\" [3e38 1 1] \"float scale\" 1e10\n");
  CHECK(e == "dir/q.pbrt:2: LightSource \"point\" (dir/q.pbrt:2): its power is not a finite float (too bright after its scale factors)");
}

// ---------------------------------------------------------------- item 17: messages

TEST_CASE("pbrt messages: a uniform tiny scale is degenerate, not 'non-uniform or shear'") {
  std::string e = errorOf("WorldBegin\nScale 1e-30 1e-30 1e-30\nShape \"sphere\"\n");
  CHECK(e == "dir/q.pbrt:3: Shape \"sphere\": its transform is unusable: it scales an axis by 1e-30, which is degenerate "
             "(too small); tdpm needs scale factors in [1e-12, 1e+12]");
  e = errorOf("WorldBegin\nScale 1e-30 1e-30 1e-30\nLightSource \"spot\"\n");
  CHECK(contains(e, "dir/q.pbrt:3: LightSource \"spot\": its transform is unusable: it scales an axis by 1e-30"));
  // A real non-uniform scale still says so.
  CHECK(contains(errorOf("WorldBegin\nScale 1 2 1\nShape \"sphere\"\n"), "non-uniform scale"));
}

TEST_CASE("pbrt messages: a trianglemesh without indices names its line") {
  CHECK(errorOf("WorldBegin\n\nShape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n") ==
        "dir/q.pbrt:3: Shape \"trianglemesh\": missing parameter \"integer indices\" (only a single triangle of 3 points may omit it)");
  CHECK(errorOf("WorldBegin\n\nShape \"trianglemesh\" \"integer indices\" [0 1 2]\n") ==
        "dir/q.pbrt:3: Shape \"trianglemesh\": missing parameter \"point3 P\"");
}

TEST_CASE("pbrt messages: sppm photons are named by the Integrator statement") {
  pbrt::ImportResult r = pbrt::importPbrtText(
      "Integrator \"sppm\" \"integer photonsperiteration\" 1000 \"integer numiterations\" 4\nWorldBegin\n", "dir/q.pbrt");
  CHECK(*r.scene.render.photons == 4000);
  CHECK(r.settingSources.at("photons") == "dir/q.pbrt:1: Integrator \"sppm\" (photonsperiteration x numiterations)");
  // Over the JSON's photon limit: refused there, not clamped.
  CHECK(errorOf("Integrator \"sppm\" \"integer photonsperiteration\" 1073741824 \"integer numiterations\" 3\nWorldBegin\n") ==
        "dir/q.pbrt:1: Integrator \"sppm\": photonsperiteration x numiterations = 1073741824 x 3 photons is more than tdpm's "
        "limit of 2147483648 (render.photons)");
}

// ---------------------------------------------------------------- item 10: convert

TEST_CASE("cli: convert refuses outputs that are its inputs (by identity) and checks every output before writing") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/inc.json", "LightSource \"point\" \"rgb I\" [1 1 1]\n");
  test::writeFile(dir + "/out.mesh1.obj",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  test::writeFile(dir + "/s.pbrt", "WorldBegin\nInclude \"inc.json\"\nShape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0]\n"
                                   "Shape \"plymesh\" \"string filename\" \"out.mesh1.obj\"\n");
  auto readAll = [](const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  std::string inc = readAll(dir + "/inc.json"), ply = readAll(dir + "/out.mesh1.obj");
  // The PLY is named like convert's second mesh output.
  auto r = test::runTdpm("convert -q '" + dir + "/s.pbrt' -o '" + dir + "/out.json'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "would overwrite '" + dir + "/out.mesh1.obj', which the scene reads"));
  CHECK(!test::fileExists(dir + "/out.json"));
  CHECK(!test::fileExists(dir + "/out.mesh0.obj"));
  // -o names an included file, through a symbolic link.
  REQUIRE(symlink((dir + "/inc.json").c_str(), (dir + "/link.json").c_str()) == 0);
  r = test::runTdpm("convert -q '" + dir + "/s.pbrt' -o '" + dir + "/link.json'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "which the scene reads"));
  CHECK(readAll(dir + "/inc.json") == inc);
  CHECK(readAll(dir + "/out.mesh1.obj") == ply);
  CHECK(!test::fileExists(dir + "/link.mesh0.obj"));
  // -o names a directory: nothing is written, not even the first mesh.
  REQUIRE(mkdir((dir + "/d.json").c_str(), 0700) == 0);
  r = test::runTdpm("convert -q '" + dir + "/s.pbrt' -o '" + dir + "/d.json'");
  CHECK(r.exitCode == 1);
  CHECK(!test::fileExists(dir + "/d.mesh0.obj"));
  CHECK(!test::fileExists(dir + "/d.mesh1.obj"));
  // A free name works and writes all three files.
  r = test::runTdpm("convert -q '" + dir + "/s.pbrt' -o '" + dir + "/ok.json'");
  CHECK(r.exitCode == 0);
  CHECK(test::fileExists(dir + "/ok.json"));
  CHECK(test::fileExists(dir + "/ok.mesh0.obj"));
  CHECK(test::fileExists(dir + "/ok.mesh1.obj"));
}

// ---------------------------------------------------------------- items 5, 11: compare

namespace {
// A PNG whose IHDR claims w x h; its pixel data is not needed (never decoded).
std::string pngClaiming(uint32_t w, uint32_t h) {
  std::string s = "\x89PNG\r\n\x1a\n";
  s += std::string("\0\0\0\x0d", 4) + "IHDR";
  for (uint32_t v : {w, h})
    for (int k = 3; k >= 0; --k) s += char((v >> (8 * k)) & 0xff);
  s += std::string("\x08\x02\0\0\0", 5) + "CRC!";  // 8-bit RGB; CRC not checked by the header read
  return s;
}
}  // namespace

TEST_CASE("compare: sizes come from the headers and differing sizes are refused before decoding") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/huge.png", pngClaiming(20000, 20000));
  test::writeFile(dir + "/small.pfm", "PF\n4 3\n-1\n" + std::string(4 * 3 * 3 * 4, '\0'));
  test::writeFile(dir + "/t.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 5\n");
  auto h = image::readImageHeader(dir + "/huge.png");
  REQUIRE(h);
  CHECK(h->width == 20000);
  CHECK(h->channels == 3);
  auto p = image::readImageHeader(dir + "/small.pfm");
  REQUIRE(p);
  CHECK((p->width == 4 && p->height == 3 && p->channels == 3));
  auto r = image::readImageHeader(dir + "/t.hdr");
  REQUIRE(r);
  CHECK((r->width == 5 && r->height == 3));
  // The PNG's data is garbage: had it been decoded, the error would be a PNG one.
  auto c = test::runTdpm("compare '" + dir + "/huge.png' '" + dir + "/small.pfm'");
  CHECK(c.exitCode == 1);
  CHECK(contains(c.output, "image sizes differ: " + dir + "/huge.png is 20000x20000 but " + dir + "/small.pfm is 4x3"));
}

TEST_CASE("compare: --csv that is a link to an input image is refused (file identity, not names)") {
  std::string dir = test::makeTempDir();
  std::string pfm = "PF\n2 1\n-1\n" + std::string(2 * 3 * 4, '\0');
  test::writeFile(dir + "/a.pfm", pfm);
  test::writeFile(dir + "/b.pfm", pfm);
  REQUIRE(symlink((dir + "/a.pfm").c_str(), (dir + "/lnk.csv").c_str()) == 0);
  auto c = test::runTdpm("compare '" + dir + "/a.pfm' '" + dir + "/b.pfm' --profile-row 0 --csv '" + dir + "/lnk.csv'");
  CHECK(c.exitCode == 1);
  CHECK(contains(c.output, "--csv: '" + dir + "/lnk.csv' is the input image '" + dir + "/a.pfm' (the same file)"));
  std::ifstream in(dir + "/a.pfm", std::ios::binary);
  CHECK(std::string(std::istreambuf_iterator<char>(in), {}) == pfm);
  // --plot through another spelling of the reference's path.
  c = test::runTdpm("compare '" + dir + "/a.pfm' '" + dir + "/b.pfm' --profile-row 0 --plot '" + dir + "/./b.pfm.svg'");
  CHECK(c.exitCode == 0);  // a different file: fine
  c = test::runTdpm("compare '" + dir + "/a.pfm' '" + dir + "/b.pfm' --profile-row 0 --csv '" + dir + "/./a.pfm'");
  CHECK(c.exitCode == 1);
  CHECK(contains(c.output, "is the input image"));
}

// ---------------------------------------------------------------- issue 23 item 10: small exact mappings

TEST_CASE("pbrt convert: a spot light survives the JSON bit for bit (direction, cone, falloff, power)") {
  // caustic-glass's spot light: from (0 5 9) to (-5 2.75 0), a bright RGB I.
  pbrt::ImportResult r = pbrt::importPbrtText(
      "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 6\nWorldBegin\n"
      "LightSource \"spot\" \"point from\" [0 5 9] \"point to\" [-5 2.75 0] \"float coneangle\" 30 "
      "\"float conedeltaangle\" 5 \"rgb I\" [139.8113403320 118.6366500854 105.3887557983]\nShape \"sphere\"\n",
      "dir/q.pbrt");
  REQUIRE(r.scene.lights.size() == 1);
  pbrt::SceneJson js = pbrt::sceneToJson(r.scene, "dir/q.json");
  scene::SceneDescription back = scene::parseScene(js.json, "dir/q.json");
  REQUIRE(back.lights.size() == 1);
  const scene::LightDesc &a = r.scene.lights[0], &b = back.lights[0];
  CHECK(a.direction.x == b.direction.x);
  CHECK(a.direction.y == b.direction.y);
  CHECK(a.direction.z == b.direction.z);
  CHECK(a.position.x == b.position.x);
  CHECK(a.coneAngle == b.coneAngle);
  CHECK(a.falloffStart == b.falloffStart);
  CHECK(a.power.r == b.power.r);
  CHECK(a.power.g == b.power.g);
  CHECK(a.power.b == b.power.b);
}

namespace {
bool hasNote(const pbrt::ImportResult& r, const std::string& part) {
  for (const std::string& n : r.notes)
    if (contains(n, part)) return true;
  return false;
}
int countNotes(const pbrt::ImportResult& r, const std::string& part) {
  int k = 0;
  for (const std::string& n : r.notes) k += contains(n, part);
  return k;
}
const std::string kQuadLight =
    "AttributeBegin\nAreaLightSource \"%s\" \"rgb L\" [2 2 2]%s\n"
    "Shape \"trianglemesh\" \"point P\" [-1 0 -1 1 0 -1 1 0 1 -1 0 1] \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n";
std::string quadLight(const std::string& type, const std::string& extra = "") {
  std::string s = kQuadLight;
  s.replace(s.find("%s"), 2, type);
  s.replace(s.find("%s"), 2, extra);
  return s;
}
}  // namespace

TEST_CASE("pbrt-v3 Film \"image\" \"float scale\" scales every light (linear transport: exact)") {
  std::string world = "WorldBegin\nLightSource \"point\" \"rgb I\" [1 2 3]\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n";
  pbrt::ImportResult one = pbrt::importPbrtText("Film \"image\"\n" + world, "dir/q.pbrt");
  pbrt::ImportResult four = pbrt::importPbrtText("Film \"image\" \"float scale\" 4\n" + world, "dir/q.pbrt");
  // The point light and the infinite light (an environment light): power and radiance both x4.
  REQUIRE(four.scene.lights.size() == 2);
  CHECK(four.scene.lights[0].power.g == 4 * one.scene.lights[0].power.g);
  CHECK(four.scene.lights[1].type == scene::LightDesc::Type::Environment);
  CHECK(four.scene.lights[1].radiance.r == 2.0f);
  CHECK(hasNote(four, "dir/q.pbrt:1: Film: pbrt-v3's Film \"image\" scales the image by \"scale\" = 4; the import scales every light by it"));
  CHECK(contains(errorOf("Film \"image\" \"float scale\" 0\nWorldBegin\n"), "dir/q.pbrt:1: Film \"image\": parameter \"float scale\": must be positive"));
}

TEST_CASE("pbrt-v3 AreaLightSource \"area\" is the diffuse area light") {
  scene::SceneDescription a = pbrt::importPbrtText("WorldBegin\n" + quadLight("area"), "dir/q.pbrt").scene;
  scene::SceneDescription d = pbrt::importPbrtText("WorldBegin\n" + quadLight("diffuse"), "dir/q.pbrt").scene;
  REQUIRE(a.lights.size() == 1);
  REQUIRE(d.lights.size() == 1);
  CHECK(a.lights[0].power.r == d.lights[0].power.r);
  CHECK(a.lights[0].areaSize.x == d.lights[0].areaSize.x);
  CHECK(contains(errorOf("WorldBegin\n" + quadLight("goniometric")), "(only \"diffuse\", or pbrt-v3's alias \"area\")"));
}

TEST_CASE("pbrt: light sample counts are ignored with a note, not an error") {
  pbrt::ImportResult r = pbrt::importPbrtText("WorldBegin\n" + quadLight("diffuse", " \"integer nsamples\" 4") +
                                                  "LightSource \"infinite\" \"integer nsamples\" 8\n",
                                              "dir/q.pbrt");
  CHECK(hasNote(r, "dir/q.pbrt:3: AreaLightSource: \"nsamples\" ignored (quality only"));
  CHECK(hasNote(r, "dir/q.pbrt:6: LightSource \"infinite\": \"nsamples\" ignored (quality only"));
}

TEST_CASE("pbrt: the spot falloff note is for pbrt-v4 files only (the quartic is pbrt-v3's own curve)") {
  std::string world = "WorldBegin\nLightSource \"spot\" \"float coneangle\" 30 \"float conedeltaangle\" 5\n";
  CHECK(!hasNote(pbrt::importPbrtText("Film \"image\"\n" + world, "dir/q.pbrt"), "smoothstep"));
  CHECK(hasNote(pbrt::importPbrtText("Film \"rgb\"\n" + world, "dir/q.pbrt"), "smoothstep"));
}

TEST_CASE("pbrt: a PLY's normal (nx, ny, nz) is one shading normal: used, no note") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/n.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property float nx\nproperty float ny\nproperty float nz\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
  test::writeFile(dir + "/s.pbrt", "WorldBegin\nShape \"plymesh\" \"string filename\" \"n.ply\"\n");
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  CHECK(countNotes(r, "plymesh") == 0);
  CHECK(r.scene.objects.at(0).shape.normals.size() == 3);
}

TEST_CASE("pbrt: texture errors name every supported kind and type") {
  CHECK(contains(errorOf("WorldBegin\nTexture \"t\" \"bogus\" \"constant\"\n"), "(float, spectrum, or pbrt-v3's color/rgb)"));
  CHECK(contains(errorOf("WorldBegin\nTexture \"t\" \"spectrum\" \"wrinkled\"\n"),
                 "type \"wrinkled\" is not supported (supported: constant, scale, mix, checkerboard, imagemap)"));
}

TEST_CASE("pbrt: options errors are reported in file order (the first wrong statement, not the first mapped)") {
  // Film is mapped before Camera and Integrator (their values depend on
  // it), but the error named is the first in the file.
  CHECK(errorOf("Integrator \"ambientocclusion\"\nCamera \"orthographic\"\nFilm \"bogus\"\nWorldBegin\n") ==
        "dir/q.pbrt:1: Integrator \"ambientocclusion\" is not supported (path, volpath, directlighting, bdpt, mlt, sppm)");
  CHECK(errorOf("Camera \"orthographic\"\nFilm \"bogus\"\nWorldBegin\n") ==
        "dir/q.pbrt:1: Camera \"orthographic\" is not supported (only perspective)");
  CHECK(errorOf("Film \"bogus\"\nCamera \"orthographic\"\nWorldBegin\n") ==
        "dir/q.pbrt:1: Film \"bogus\" is not supported (image, rgb, gbuffer, spectral)");
  CHECK(errorOf("Sampler \"bogus\"\nPixelFilter \"box\" \"float xradius\" 100\nWorldBegin\n") ==
        "dir/q.pbrt:1: Sampler \"bogus\" is not supported");
}

TEST_CASE("cli: render of a pbrt scene refuses an output that is a file the scene includes") {
  std::string dir = test::makeTempDir();
  // A mislabelled include: "out.png" is pbrt text, and would be the preview.
  test::writeFile(dir + "/out.png", "LightSource \"point\" \"rgb I\" [1 1 1]\n");
  test::writeFile(dir + "/s.pbrt", "Film \"image\" \"integer xresolution\" 4 \"integer yresolution\" 3\nWorldBegin\nInclude \"out.png\"\nShape \"sphere\"\n");
  auto r = test::runTdpm("render -q '" + dir + "/s.pbrt' -m pathtrace --spp 1 -o '" + dir + "/out.exr'");
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "is a file the scene reads '" + dir + "/out.png'; writing it would destroy an input"));
  CHECK(!test::fileExists(dir + "/out.exr"));
}
