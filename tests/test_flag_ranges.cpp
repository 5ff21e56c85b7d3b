// tests/test_flag_ranges.cpp — every float range of scene/limits.h, end
// points included, accepted by its flag and (where there is one) by its
// scene key; a value just outside refused with a message whose end points
// are themselves accepted (issue 27 item 14: "--alpha 0.001" was "not in
// range 0.001 to 0.999", the check compared the double 0.001 with 1e-3f).
// The flags are parsed by the real render command (cli/render_command.cpp),
// in-process: nothing is rendered.
#include <doctest/doctest.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "cli/progressive_options.h"
#include "cli/render_command.h"
#include "core/error.h"
#include "scene/limits.h"
#include "scene/parse.h"

using namespace tdpm;
namespace limits = tdpm::scene::limits;

namespace {

// "" when `tdpm render s.json FLAG VALUE` parses, else CLI11's message.
std::string parseError(const std::string& flag, const std::string& value) {
  CLI::App app;
  cli::RenderArgs args;
  cli::addRenderCommand(app, args);
  std::vector<std::string> argv = {value, flag, "s.json", "render"};  // CLI11 takes them reversed
  try {
    app.parse(argv);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

std::string sceneError(const std::string& key, const std::string& value) {
  std::string json = R"({"camera": {"position": [0, 1, 5], "target": [0, 0, 0], "resolution": [8, 6]},
    "objects": [{"shape": {"type": "sphere", "radius": 0.5}}],
    "render": {")" + key + R"(": )" + value + "}}";
  try {
    scene::parseScene(json, "s.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

struct FloatFlag {
  const char* flag;
  const char* key;  // the scene's render key, or nullptr
  limits::FloatRange range;
};

const std::vector<FloatFlag> kFloatFlags = {
    {"--fraction", "fraction", limits::kFraction},
    {"--exposure", "exposure", limits::kExposure},
    {"--max-radius", "max_radius", limits::kMaxRadius},
    {"--filter-radius", "filter_radius", limits::kFilterRadius},
    {"--kernel-footprint", nullptr, limits::kKernelFootprint},
    {"--alpha", nullptr, limits::kAlpha},
    {"--time-limit", "time_limit", limits::kTimeLimit},
    {"--caustic-guiding", nullptr, limits::kCausticGuiding},
    {"--extra-samples", nullptr, cli::kExtraSamplesRange},
};

// A value just outside an end point (relative step 1e-5, far above float
// rounding; for 0 a tiny negative number).
std::string outside(double bound, bool lower) {
  double v = bound == 0 ? (lower ? -1e-6 : 1e-6) : bound * (lower == (bound > 0) ? 1 - 1e-5 : 1 + 1e-5);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

TEST_CASE("flag ranges: the end points the issue names are accepted as typed") {
  CHECK(parseError("--alpha", "0.001") == "");
  CHECK(parseError("--alpha", "0.999") == "");
  CHECK(parseError("--caustic-guiding", "0.95") == "");
  CHECK(parseError("--max-radius", "1.1e-19") == "");
  CHECK(parseError("--max-radius", "1.8e19") == "");
  CHECK(sceneError("max_radius", "1.1e-19") == "");
  // And just outside them, refused (the check can fail).
  CHECK(parseError("--alpha", "0.00099") != "");
  CHECK(parseError("--caustic-guiding", "0.9501") != "");
  CHECK(parseError("--max-radius", "1.09e-19") != "");
  CHECK(sceneError("max_radius", "1.09e-19") != "");
}

TEST_CASE("flag ranges: every float flag and its scene key accept both documented end points, refuse just outside") {
  for (const FloatFlag& f : kFloatFlags) {
    const std::string lo = limits::boundText(f.range.lo, true, true), hi = limits::boundText(f.range.hi, false, true);
    INFO(f.flag << " [" << lo << ", " << hi << "]");
    // The shortest text: 3 significant digits unless those fall outside.
    CHECK(lo.size() <= 9);
    CHECK(hi.size() <= 9);
    CHECK(parseError(f.flag, lo) == "");
    CHECK(parseError(f.flag, hi) == "");
    std::string below = parseError(f.flag, outside(f.range.lo, true));
    std::string above = parseError(f.flag, outside(f.range.hi, false));
    CHECK(below.find("not in range " + lo + " to " + hi) != std::string::npos);
    CHECK(above.find("not in range " + lo + " to " + hi) != std::string::npos);
    if (!f.key) continue;
    CHECK(sceneError(f.key, lo) == "");
    CHECK(sceneError(f.key, hi) == "");
    CHECK(sceneError(f.key, outside(f.range.lo, true)).find("must be in [" + lo + ", " + hi + "]") != std::string::npos);
    CHECK(sceneError(f.key, outside(f.range.hi, false)).find("must be in [" + lo + ", " + hi + "]") != std::string::npos);
  }
}

TEST_CASE("flag ranges: kappa's end points for a 1 s shutter are named so that both are accepted") {
  limits::KappaRange r = limits::kappaRange(1.0);
  const std::string lo = limits::boundText(r.lo, true, true), hi = limits::boundText(r.hi, false, true);
  CHECK(lo == "7.704e-34");  // 7.7037e-34: "7.7e-34" is below it
  CHECK(hi == "8.507e+37");  // 8.50706e37: "8.51e+37" is above it
  CHECK(float(std::strtod(lo.c_str(), nullptr)) >= r.lo);
  CHECK(float(std::strtod(hi.c_str(), nullptr)) <= r.hi);
  CHECK(sceneError("kappa", lo) == "");
  CHECK(sceneError("kappa", hi) == "");
  CHECK(sceneError("kappa", "7.7e-34").find("needs kappa in [7.704e-34, 8.507e+37]") != std::string::npos);
  CHECK(sceneError("kappa", "8.51e37").find("needs kappa in [7.704e-34, 8.507e+37]") != std::string::npos);
}

TEST_CASE("flag ranges: every integer flag and its scene key accept both end points, refuse one past them") {
  struct IntFlag {
    const char* flag;
    const char* key;
    limits::IntRange range;
  };
  const IntFlag flags[] = {
      {"--spp", "spp", limits::kSpp},
      {"--max-spp", nullptr, limits::kSpp},
      {"--max-depth", "max_depth", limits::kMaxDepth},
      {"--photons", "photons", limits::kPhotons},
      {"--global-photons", "global_photons", limits::kPhotons},
      {"--frames", "frames", limits::kFrames},
      {"--k", "k", limits::kK},
      {"--gather", "gather", limits::kGather},
      {"--passes", nullptr, limits::kPasses},
      {"--extra-cap", nullptr, cli::kExtraCapRange},
  };
  for (const IntFlag& f : flags) {
    INFO(f.flag << " [" << f.range.lo << ", " << f.range.hi << "]");
    CHECK(parseError(f.flag, std::to_string(f.range.lo)) == "");
    CHECK(parseError(f.flag, std::to_string(f.range.hi)) == "");
    CHECK(parseError(f.flag, std::to_string(f.range.lo - 1)) != "");
    CHECK(parseError(f.flag, std::to_string(f.range.hi + 1)) != "");
    if (!f.key) continue;
    CHECK(sceneError(f.key, std::to_string(f.range.lo)) == "");
    CHECK(sceneError(f.key, std::to_string(f.range.hi)) == "");
    CHECK(sceneError(f.key, std::to_string(f.range.lo - 1)) != "");
    CHECK(sceneError(f.key, std::to_string(f.range.hi + 1)) != "");
  }
}
