// tests/test_render_method.cpp — the methods as a type (scene/render_method.h):
// the one parser and its table, and that no file under src/ compares a
// method's name as a string (issue 22: every such question goes to the table).
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scene/render_method.h"

using namespace tdpm;

namespace {

const RenderMethod kAll[] = {RenderMethod::PathTrace, RenderMethod::Static, RenderMethod::Accumulation,
                             RenderMethod::Standard, RenderMethod::Time};

// A comparison with a method's name: `x == "time"`, `"static" != x`,
// `method == "..."` with any name, or `.compare("standard")`.
const std::regex& nameComparison() {
  static const std::regex re(
      R"re((==|!=)\s*"(pathtrace|static|accumulation|standard|time)"|"(pathtrace|static|accumulation|standard|time)"\s*(==|!=)|method\w*\s*(==|!=)\s*"|compare\(\s*"(pathtrace|static|accumulation|standard|time)")re");
  return re;
}

// "path:line: text" of every line of `text` that compares a method's name.
std::vector<std::string> nameComparisons(const std::string& path, const std::string& text) {
  std::vector<std::string> hits;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (std::regex_search(line, nameComparison())) hits.push_back(path + ":" + std::to_string(n) + ": " + line);
  return hits;
}

}  // namespace

TEST_CASE("render methods: every name parses back to its value, other text to nothing") {
  for (RenderMethod m : kAll) {
    CAPTURE(renderMethodName(m));
    REQUIRE(parseRenderMethod(renderMethodName(m)).has_value());
    CHECK(*parseRenderMethod(renderMethodName(m)) == m);
    CHECK(renderMethodTraits(m).method == m);
  }
  for (const char* bad : {"", "Time", "photon", "time ", "pathtracer"}) CHECK_FALSE(parseRenderMethod(bad).has_value());
  CHECK(renderMethodList() == "pathtrace | static | accumulation | standard | time");
  CHECK(renderMethodNames().size() == size_t(kRenderMethodCount));
}

TEST_CASE("render methods: the table says what the renderer does") {
  const RenderMethodTraits& pt = renderMethodTraits(RenderMethod::PathTrace);
  const RenderMethodTraits& st = renderMethodTraits(RenderMethod::Static);
  const RenderMethodTraits& acc = renderMethodTraits(RenderMethod::Accumulation);
  const RenderMethodTraits& std_ = renderMethodTraits(RenderMethod::Standard);
  const RenderMethodTraits& time = renderMethodTraits(RenderMethod::Time);
  CHECK_FALSE(pt.photonMaps);
  CHECK(st.photonMaps);
  CHECK(acc.photonMaps);
  // Photons spread over the shutter: standard and time only.
  CHECK_FALSE(st.spreadsPhotonsInTime);
  CHECK_FALSE(acc.spreadsPhotonsInTime);
  CHECK(std_.spreadsPhotonsInTime);
  CHECK(time.spreadsPhotonsInTime);
  for (RenderMethod m : kAll) {
    const RenderMethodTraits& t = renderMethodTraits(m);
    CAPTURE(t.name);
    // The time-dependent estimate needs photon times; passes need photon maps.
    if (t.timeDependentEstimate) CHECK(t.spreadsPhotonsInTime);
    if (t.progressive) CHECK(t.photonMaps);
    CHECK(t.timeDependentEstimate == (m == RenderMethod::Time));
    CHECK(t.inBetweenFrames == (m == RenderMethod::Accumulation));
    CHECK((t.defaultShrink == KernelShrink::SpaceTime) == (m == RenderMethod::Time));
  }
  CHECK(acc.progressive);
  CHECK_FALSE(st.progressive);
  CHECK_FALSE(pt.progressive);
  CHECK(pt.animation);
  CHECK(std_.animation);
  CHECK(time.animation);
  CHECK_FALSE(acc.animation);
  CHECK_FALSE(st.animation);
}

TEST_CASE("render methods: the source check finds a name comparison (so it can fail)") {
  CHECK(nameComparisons("x", "  if (opt.method == \"time\") return;").size() == 1);
  CHECK(nameComparisons("x", "bool a = \"static\" != m;").size() == 1);
  CHECK(nameComparisons("x", "if (methodName == \"photon\")").size() == 1);
  CHECK(nameComparisons("x", "m.compare(\"standard\")").size() == 1);
  CHECK(nameComparisons("x", "if (renderMethodTraits(opt.method).photonMaps) {}\nkey.required(\"time\");").empty());
}

TEST_CASE("render methods: no file under src/ compares a method's name outside the table") {
  namespace fs = std::filesystem;
  const fs::path src = fs::path(TDPM_SOURCE_DIR) / "src";
  REQUIRE(fs::is_directory(src));
  std::vector<std::string> hits;
  size_t files = 0;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(src)) {
    const std::string ext = e.path().extension().string();
    if (!e.is_regular_file() || (ext != ".cpp" && ext != ".h")) continue;
    const std::string rel = fs::relative(e.path(), src).generic_string();
    if (rel == "scene/render_method.cpp") continue;  // the table and its parser
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    ++files;
    for (std::string& h : nameComparisons(rel, text.str())) hits.push_back(std::move(h));
  }
  CHECK(files > 50);
  std::string all;
  for (const std::string& h : hits) all += h + "\n";
  CHECK_MESSAGE(hits.empty(), "method names compared as strings (ask scene/render_method.h's table):\n" << all);
}
