// tests/convert_round_trip.h — the round trip the texture and material tests
// share: the JSON `tdpm convert` writes for a description reads back to the
// same JSON and renders the same, non-black pixels (pathtrace, 4 spp).
#pragma once
#include <doctest/doctest.h>

#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"

namespace tdpm::test {

// Writes d as JSON to `json`, checks the round trip, returns the text.
inline std::string checkConvert(const scene::SceneDescription& d, const std::string& json) {
  pbrt::writeSceneJson(d, json);
  std::ifstream in(json);
  std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  scene::SceneDescription back = scene::loadScene(json);
  CHECK(nlohmann::json::parse(pbrt::sceneToJson(back, "/x/s.json").json) ==
        nlohmann::json::parse(pbrt::sceneToJson(d, "/x/s.json").json));
  RenderOptions o = smallRenderOptions(RenderMethod::PathTrace, 4, 4, 11);
  Film a = renderOnce(d, o), b = renderOnce(back, o);
  CHECK(sameImage(a, b));
  CHECK(imageSum(a) > 0);
  return written;
}

}  // namespace tdpm::test
