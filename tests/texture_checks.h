// tests/texture_checks.h — the checks the textured-material and
// textured-parameter tests share: the textured plane's scene (texturedPlane), a textured 16-pixel-wide plane's halves
// render exactly as two constant scenes (checkHalves), a pbrt text imported
// (importText), and the JSON `tdpm convert` writes reads back to the same
// JSON and renders the same, non-black pixels (checkConvert).
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

// A 2 x 2 m quad seen from above (image x along world x, u along x), under
// a directional light from the side: the JSON scene whose textures block
// holds `textures` and materials block `materials` (material "m" is the
// quad's).
inline std::string texturedPlane(const std::string& textures, const std::string& materials) {
  return R"({"camera": {"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov": 30, "resolution": [16, 16]},
    "textures": {)" + textures + R"(}, "materials": {)" + materials + R"(},
    "objects": [{"shape": {"type": "quad", "size": [2, 2]}, "material": "m"}],
    "lights": [{"type": "directional", "direction": [-0.3, -1, 0.2], "irradiance": [3, 3, 3]}]})";
}

// The textured scene's left six columns are the pixels of scene a, its
// right six those of scene b (the seam's columns, which the pixel filter
// spans, left out), and a and b differ there: the check can fail.
inline void checkHalves(const scene::SceneDescription& textured, const scene::SceneDescription& a,
                        const scene::SceneDescription& b, RenderMethod method = RenderMethod::PathTrace) {
  RenderOptions o = smallRenderOptions(method, 4, 3, 5);
  Film t = renderOnce(textured, o), fa = renderOnce(a, o), fb = renderOnce(b, o);
  REQUIRE(t.width == 16);
  int sameA = 0, sameB = 0, differ = 0, n = 0;
  auto same = [](Rgb p, Rgb q) { return p.r == q.r && p.g == q.g && p.b == q.b; };
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < 6; ++x, ++n) {
      size_t l = size_t(y) * 16 + size_t(x), r = size_t(y) * 16 + size_t(15 - x);
      sameA += same(t.color[l], fa.color[l]);
      sameB += same(t.color[r], fb.color[r]);
      differ += !same(fa.color[l], fb.color[l]) + !same(fa.color[r], fb.color[r]);
    }
  CHECK(sameA == n);
  CHECK(sameB == n);
  CHECK(differ > n);
  CHECK(imageSum(t) > 0);
}

inline scene::SceneDescription importText(const std::string& text) {
  return pbrt::importPbrtText(text, "dir/t.pbrt").scene;
}

// A pbrt scene: a 2 x 2 uv quad seen from above under a distant light, 16 x
// 16 pixels; `defs` its textures and named materials, `body` its material.
inline std::string pbrtPlane(const std::string& defs, const std::string& body) {
  return "LookAt 0 3 0  0 0 0  0 0 -1\nCamera \"perspective\" \"float fov\" 30\n"
         "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\nWorldBegin\n"
         "LightSource \"distant\" \"rgb L\" [3 3 3] \"point3 from\" [0.3 1 -0.2] \"point3 to\" [0 0 0]\n" +
         defs + body + "\nShape \"bilinearmesh\" \"point3 P\" [-1 0 -1 1 0 -1 -1 0 1 1 0 1] \"point2 uv\" [0 0 1 0 0 1 1 1]\n";
}

// pbrt's image is mirrored in x against tdpm's camera frame
// (pbrt_import.cpp): a checkerboard's tex1 (u < 1/2) is on the image's
// right. `textured` renders as `tex1` there and as `tex2` on the left.
inline void checkPbrtHalves(const std::string& defs, const std::string& textured, const std::string& tex1,
                            const std::string& tex2) {
  checkHalves(importText(pbrtPlane(defs, textured)), importText(pbrtPlane(defs, tex2)),
              importText(pbrtPlane(defs, tex1)));
}

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
