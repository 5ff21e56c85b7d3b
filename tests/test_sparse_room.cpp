// tests/test_sparse_room.cpp — scenes/sparse-room.json (issue 24's kind: a
// large diffuse room, one small light near a wall, two moving boxes) at a
// small size against the path tracer: the photon methods' image mean with a
// sparse global map, and the final gather's salt with and without the
// gather guide. The minutes-long version at the Done-when's settings is
// bench/sparse-room/check.py.
//
// The image mean leaves out the band of rows holding the lamp (rows
// [0.23 h, 0.35 h)): its pixels are hundreds of times brighter than the
// room, and how many of a pixel's samples land on it moves a 16-spp image's
// mean by a few percent with the seed, alike in every method (the "-2%" of
// the previous measurement; docs/photon-map.md).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "image/image.h"
#include "image/metrics.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "scene/parse.h"

using namespace tdpm;

namespace {

constexpr int kW = 48, kH = 36;

scene::SceneDescription sparseRoom() {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/sparse-room.json");
  d.camera.width = kW;
  d.camera.height = kH;
  return d;
}

bool lampRow(int y) { return y >= int(0.23 * kH) && y < int(0.35 * kH); }

double meanOutsideLamp(const Film& f) {
  double s = 0.0;
  size_t n = 0;
  for (int y = 0; y < f.height; ++y) {
    if (lampRow(y)) continue;
    for (int x = 0; x < f.width; ++x, ++n) s += f.color[f.index(x, y)].average();
  }
  return s / double(n);
}

image::ImageRgb toImage(const Film& f) {
  image::ImageRgb im(f.width, f.height);
  im.pixels = f.color;
  return im;
}

// The path-traced reference, rendered once for every case of this file.
const Film& reference() {
  static const Film ref = test::renderOnce(sparseRoom(), test::smallRenderOptions(RenderMethod::PathTrace, 1024, 16, 9));
  return ref;
}

Film photonRender(bool fourD, size_t globalPhotons, int spp, uint64_t seed, bool guide = true) {
  RenderOptions o = test::smallRenderOptions(RenderMethod::Time, spp, 16, seed);
  o.progressive = false;
  o.spaceTime4D = fourD;
  o.globalPhotons = globalPhotons;
  o.gatherGuide = guide;
  return test::renderOnce(sparseRoom(), o);
}

}  // namespace

// Before issue 24's fix the 4D estimate read this room's 5,000-photon
// global map at 2.08x the path tracer (a clipped volume defined by the
// photons found; scenes/README.md) and the real scene's two-pass at 1.29x.
// Measured now (seed 3): two-pass 1.010, 4D 1.007; the bound is 3%.
TEST_CASE("sparse room: time (two-pass and 4D) with 5,000 global photons within 3% of the path tracer") {
  const double ref = meanOutsideLamp(reference());
  for (bool fourD : {false, true}) {
    double ratio = meanOutsideLamp(photonRender(fourD, 5000, 32, 3)) / ref;
    MESSAGE(std::string(fourD ? "4D" : "two-pass") << " / pathtrace: " << ratio);
    CHECK(ratio == doctest::Approx(1.0).epsilon(0.03));
  }
}

// The salt of a fixed-budget render here was the final gather's: one gather
// ray in a few hundred from the floor hits the bright patch of back wall
// beside the lamp, and its pixel is several times its neighbours. Aimed by
// the global photons' directions, those rays are drawn in proportion to the
// light they bring, so such a pixel no longer stands out (measured at
// 160x120: 0.82% of the pixels salt without the guide, 0.03-0.05% with; at
// this test's 48x36, seed 4: 1.6% and 0.58%, the rest at the room's edges
// where a 5x5 median spans two surfaces).
TEST_CASE("sparse room: the gather guide removes the final gather's salt, and keeps the mean") {
  const Film& ref = reference();
  image::ImageRgb r = toImage(ref);
  image::PixelRect all{0, 0, kW, kH};
  Film off = photonRender(false, 50000, 16, 4, false);
  Film on = photonRender(false, 50000, 16, 4);
  double saltOff = image::countSalt(toImage(off), r, all).share;
  double saltOn = image::countSalt(toImage(on), r, all).share;
  double meanOff = meanOutsideLamp(off) / meanOutsideLamp(ref), meanOn = meanOutsideLamp(on) / meanOutsideLamp(ref);
  MESSAGE("salt share off " << saltOff << ", on " << saltOn << "; mean off " << meanOff << ", on " << meanOn);
  CHECK(saltOff > 0.003);  // the test can fail: the unguided gather is salty here
  CHECK(saltOn < 0.5 * saltOff);
  CHECK(meanOn == doctest::Approx(1.0).epsilon(0.03));
  CHECK(meanOff == doctest::Approx(1.0).epsilon(0.03));
}
