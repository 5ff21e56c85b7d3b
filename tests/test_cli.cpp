// tests/test_cli.cpp — `tdpm` as a user meets it: help and version, a
// render that writes an EXR (with metadata and layers) and a PNG, and for
// each kind of bad input a specific message, exit code 1 or 2 and no output.
#include <doctest/doctest.h>

#include "cli_harness.h"
#include "image/exr.h"

using namespace tdpm;
using test::runTdpm;

namespace {

const char* kTinyScene = R"({
  "camera": {"position": [0, 1, 4], "target": [0, 0.5, 0], "fov": 40, "resolution": [24, 16], "shutter": [0, 1]},
  "materials": {"white": {"type": "diffuse", "color": 0.7}},
  "objects": [
    {"shape": {"type": "quad", "size": [4, 4]}, "material": "white"},
    {"shape": {"type": "sphere", "radius": 0.4}, "material": "white",
     "transform": {"translate": [0, 0.5, 0]},
     "motion": [{"time": 0, "translate": [-0.5, 0, 0]}, {"time": 1, "translate": [0.5, 0, 0]}]}],
  "lights": [{"type": "point", "position": [0, 3, 1], "power": 200}],
  "render": {"method": "pathtrace", "spp": 4}
})";

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("cli: --help, render --help and --version") {
  auto h = runTdpm("--help");
  CHECK(h.exitCode == 0);
  CHECK(contains(h.output, "render"));
  auto rh = runTdpm("render --help");
  CHECK(rh.exitCode == 0);
  for (const char* flag : {"--output", "--method", "--spp", "--seed", "--threads", "--resolution", "--quiet", "--exposure"})
    CHECK_MESSAGE(contains(rh.output, flag), flag);
  auto v = runTdpm("--version");
  CHECK(v.exitCode == 0);
  CHECK(contains(v.output, "tdpm " TDPM_VERSION));
  CHECK(runTdpm("").exitCode == 2);  // a subcommand is required
  CHECK(runTdpm("frobnicate").exitCode == 2);
}

TEST_CASE("cli: render writes an EXR with metadata and layers, and a PNG preview") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/tiny.json", kTinyScene);
  auto r = runTdpm("render '" + dir + "/tiny.json' -o '" + dir + "/out.exr' --seed 5 --threads 2");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(contains(r.output, "out.exr"));  // the summary names the output
  image::ExrFile f = image::readExr(dir + "/out.exr");
  CHECK(f.color.width == 24);
  CHECK(f.color.height == 16);
  CHECK(f.metadata["tdpm/method"] == "pathtrace");
  CHECK(f.metadata["tdpm/spp"] == "4");
  CHECK(f.metadata["tdpm/seed"] == "5");
  CHECK(contains(f.metadata["tdpm/scene"], "tiny.json"));
  REQUIRE(f.findChannel("spp") != nullptr);
  CHECK(f.findChannel("spp")->values[0] == 4.0f);
  CHECK(f.findChannel("variance.R") != nullptr);
  CHECK(test::fileExists(dir + "/out.png"));
  double sum = 0;
  for (Rgb c : f.color.pixels) sum += c.average();
  CHECK(sum > 0);

  // Flags override the scene; --quiet prints nothing on success.
  auto q = runTdpm("render '" + dir + "/tiny.json' -o '" + dir + "/small.exr' --resolution 8x6 --spp 2 -q");
  CHECK(q.exitCode == 0);
  CHECK(q.output.empty());
  image::ExrFile s = image::readExr(dir + "/small.exr");
  CHECK(s.color.width == 8);
  CHECK(s.color.height == 6);
  CHECK(s.metadata["tdpm/spp"] == "2");
}

TEST_CASE("cli: same seed gives the same image whatever --threads is") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/tiny.json", kTinyScene);
  REQUIRE(runTdpm("render '" + dir + "/tiny.json' -o '" + dir + "/a.exr' -t 1 -q").exitCode == 0);
  REQUIRE(runTdpm("render '" + dir + "/tiny.json' -o '" + dir + "/b.exr' -t 2 -q").exitCode == 0);
  image::ExrFile a = image::readExr(dir + "/a.exr"), b = image::readExr(dir + "/b.exr");
  REQUIRE(a.color.pixels.size() == b.color.pixels.size());
  bool same = true;
  for (size_t i = 0; i < a.color.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) same &= a.color.pixels[i][c] == b.color.pixels[i][c];
  CHECK(same);
}

TEST_CASE("cli: bad input gets a specific message, a non-zero exit and no output") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/tiny.json", kTinyScene);
  test::writeFile(dir + "/typo.json", std::string(kTinyScene).replace(std::string(kTinyScene).find("\"fov\""), 5, "\"fob\""));
  test::writeFile(dir + "/broken.json", "{\"camera\": {\"position\": [0, 1, 4],\n  \"fov\": }");
  const std::string out = " -o '" + dir + "/x.exr'";
  struct Case {
    std::string args;
    int exitCode;
    std::vector<std::string> mentions;
  };
  std::vector<Case> cases = {
      {"render '" + dir + "/missing.json'" + out, 1, {"missing.json"}},
      {"render '" + dir + "/typo.json'" + out, 1, {"typo.json", "camera", "fob"}},
      {"render '" + dir + "/broken.json'" + out, 1, {"broken.json", ":2"}},
      {"render '" + dir + "/tiny.json' --spp 0" + out, 2, {"--spp"}},
      {"render '" + dir + "/tiny.json' --threads 0" + out, 2, {"--threads"}},
      {"render '" + dir + "/tiny.json' --resolution 10by10" + out, 1, {"--resolution", "10by10"}},
      {"render '" + dir + "/tiny.json' --resolution 0x10" + out, 1, {"--resolution"}},
      {"render '" + dir + "/tiny.json' --method bogus" + out, 1, {"--method", "bogus", "pathtrace"}},
      {"render '" + dir + "/tiny.json' --seed -3" + out, 2, {"--seed"}},
      {"render '" + dir + "/tiny.json' -o '" + dir + "/nodir/x.exr'", 1, {"nodir"}},
      {"render '" + dir + "/tiny.json' -o '" + dir + "/x.png'", 1, {".exr"}},
  };
  for (const Case& c : cases) {
    auto r = runTdpm(c.args);
    INFO(c.args);
    INFO(r.output);
    CHECK(r.exitCode == c.exitCode);
    for (const std::string& m : c.mentions) CHECK_MESSAGE(contains(r.output, m), m);
  }
  // Only the three scene files: nothing was written, not even a temporary.
  CHECK(test::countEntries(dir) == 3);
}

TEST_CASE("cli: a scene that can only be black says so, and still renders") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/dark.json", R"({"camera": {"position": [0, 1, 4], "target": [0, 0, 0], "resolution": [8, 6]},
    "objects": [{"shape": {"type": "quad", "size": [4, 4]}}]})");
  // Its own method (time) renders in passes by default: one is enough here.
  auto r = runTdpm("render '" + dir + "/dark.json' -o '" + dir + "/dark.exr' -q --passes 1");
  CHECK(r.exitCode == 0);
  CHECK(contains(r.output, "warning: the scene has no lights and a black background"));
  CHECK(test::fileExists(dir + "/dark.exr"));
}

TEST_CASE("cli: max_spp below spp names where each value came from, and writes nothing") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", R"({"camera": {"position": [0, 1, 4], "target": [0, 0, 0], "resolution": [8, 6]},
    "objects": [{"shape": {"type": "quad", "size": [4, 4]}}],
    "render": {"method": "pathtrace", "spp": 8, "max_spp": 16}})");
  auto flag = runTdpm("render '" + dir + "/s.json' -o '" + dir + "/a.exr' --spp 32");
  CHECK(flag.exitCode == 1);
  CHECK(contains(flag.output, "max_spp 16 (render.max_spp in"));
  CHECK(contains(flag.output, "is below spp 32 (--spp)"));
  auto both = runTdpm("render '" + dir + "/s.json' -o '" + dir + "/b.exr' --max-spp 4");
  CHECK(both.exitCode == 1);
  CHECK(contains(both.output, "max_spp 4 (--max-spp) is below spp 8 (render.spp in"));
  CHECK(test::countEntries(dir) == 1);  // only the scene file
}
