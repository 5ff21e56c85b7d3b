// tests/render_fixtures.h — one small render of a scene description, for the
// tests that compare images or their sums: the options every such test
// starts from (one method, exactly spp samples everywhere, a fixed seed),
// the render, and bit-for-bit image equality.
#pragma once
#include <cstdint>

#include "render/renderer.h"
#include "scene/description.h"
#include "scene/render_method.h"
#include "scene/scene.h"

namespace tdpm::test {

// `spp` samples in every pixel (no adaptive batches), `seed` fixed so that a
// failure replays; the photon counts are the caller's to set.
inline RenderOptions smallRenderOptions(RenderMethod method, int spp, int maxDepth, uint64_t seed) {
  RenderOptions o;
  o.method = method;
  o.spp = spp;
  o.maxSpp = spp;
  o.maxDepth = maxDepth;
  o.seed = seed;
  return o;
}

inline Film renderOnce(const scene::SceneDescription& d, const RenderOptions& o) {
  auto s = Scene::build(d);
  RenderStats st;
  return render(*s, o, Progress{}, st);
}

// Bit-identical colour (same size, every channel of every pixel).
inline bool sameImage(const Film& a, const Film& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (size_t i = 0; i < a.color.size(); ++i)
    if (a.color[i].r != b.color[i].r || a.color[i].g != b.color[i].g || a.color[i].b != b.color[i].b) return false;
  return true;
}

// Sum of all channels of all pixels.
inline double imageSum(const Film& f) {
  double s = 0;
  for (const Rgb& c : f.color) s += c.r + c.g + c.b;
  return s;
}

}  // namespace tdpm::test
