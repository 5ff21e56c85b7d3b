// tests/test_render_metadata.cpp — the one EXR metadata block
// (cli/render_metadata.h): a single image and an animation frame carry the
// same settings (frames used to lack tdpm/filter, tdpm/search and
// tdpm/caustic_guiding), each method its own figures.
#include <doctest/doctest.h>

#include <map>
#include <string>

#include "cli/render_metadata.h"

using namespace tdpm;

namespace {

RenderStats someStats() {
  RenderStats st;
  st.seconds = 1.25;
  st.minSpp = 4;
  st.maxSpp = 12;
  st.maps[MapKind::Caustic].stored = 1234;
  st.maps[MapKind::Global].stored = 567;
  return st;
}

}  // namespace

TEST_CASE("render metadata: a frame carries the image's settings plus its place in the timeline") {
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Standard, RenderMethod::Time}) {
    RenderOptions o;
    o.method = m;
    o.filter = FilterKind::Gaussian;
    o.spaceTime4D = true;
    CAPTURE(renderMethodName(m));
    const RenderStats st = someStats();
    std::map<std::string, std::string> image = cli::renderMetadata("s.json", o, st);
    const cli::FrameTag tag{3, 0.125, 0.1875};
    std::map<std::string, std::string> frame = cli::renderMetadata("s.json", o, st, &tag);
    CHECK(frame.at("tdpm/frame") == "3");
    CHECK(frame.at("tdpm/frame_shutter") == "0.125 0.1875");
    frame.erase("tdpm/frame");
    frame.erase("tdpm/frame_shutter");
    CHECK(frame == image);
    CHECK(image.at("tdpm/method") == renderMethodName(m));
    CHECK(image.at("tdpm/filter") == "gaussian");
    CHECK(image.at("tdpm/spp_taken") == "4-12");
    CHECK(image.at("tdpm/render_seconds") == "1.250");
    if (m == RenderMethod::PathTrace) {
      CHECK(image.at("tdpm/caustic_guiding") == "0.5");
      CHECK(image.count("tdpm/caustic_photons") == 0);
    } else {
      CHECK(image.count("tdpm/caustic_guiding") == 0);
      CHECK(image.at("tdpm/caustic_photons") == "1234");
      CHECK(image.at("tdpm/global_photons") == "567");
    }
    CHECK(image.count("tdpm/search") == (m == RenderMethod::Time ? 1u : 0u));
    if (m == RenderMethod::Time) CHECK(image.at("tdpm/search") == "4d");
  }
}

TEST_CASE("render metadata: accumulation names its frames only with a fixed budget") {
  RenderOptions o;
  o.method = RenderMethod::Accumulation;
  o.frames = 5;
  CHECK(cli::renderMetadata("s.json", o, someStats()).at("tdpm/frames") == "5");
  o.progressive = true;
  CHECK(cli::renderMetadata("s.json", o, someStats()).count("tdpm/frames") == 0);
}
