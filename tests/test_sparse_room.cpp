// tests/test_sparse_room.cpp — scenes/sparse-room.json (issue 24's kind: a
// large diffuse room, one small light near a wall, two moving boxes) at a
// small size against the path tracer: the photon methods' image mean with a
// sparse global map, and the final gather's salt at the defaults (the
// gather guide on) and without the guide. The minutes-long version at the Done-when's settings is
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

// The salt case's size: at 48x36 one pixel is 0.058% of the image, and the
// room's edges (a 5x5 median spanning two surfaces) hold ~10 salt pixels
// whatever the gather does.
constexpr int kSaltW = 96, kSaltH = 72;

scene::SceneDescription sparseRoom(int w = kW, int h = kH) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/sparse-room.json");
  d.camera.width = w;
  d.camera.height = h;
  return d;
}

bool lampRow(int y, int h) { return y >= int(0.23 * h) && y < int(0.35 * h); }

double meanOutsideLamp(const Film& f) {
  double s = 0.0;
  size_t n = 0;
  for (int y = 0; y < f.height; ++y) {
    if (lampRow(y, f.height)) continue;
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

Film photonRender(bool fourD, size_t globalPhotons, int spp, uint64_t seed, bool guide = true, int w = kW,
                  int h = kH) {
  RenderOptions o = test::smallRenderOptions(RenderMethod::Time, spp, 16, seed);
  o.progressive = false;
  o.spaceTime4D = fourD;
  o.globalPhotons = globalPhotons;
  o.gatherGuide = guide;
  return test::renderOnce(sparseRoom(w, h), o);
}

}  // namespace

// Before issue 24's fix the 4D estimate read this room's 5,000-photon
// global map at 2.08x the path tracer (a clipped volume defined by the
// photons found; scenes/README.md) and the real scene's two-pass at 1.29x.
// Measured (seed 3, gather guide on): two-pass 1.006, 4D 1.003 (1.010,
// 1.007 with the BSDF-only gather); the bound is 3%.
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
// beside the lamp, and its pixel is several times its neighbours. The
// default gather pairs each BSDF ray with one aimed by the global photons'
// directions (balance heuristic), so those rays come in proportion to the
// light they bring and such a pixel no longer stands out. Measured at
// 160x120 over seeds 1-4 (bench/sparse-room/check.py): 0.82% salt unguided,
// 0.037% at the defaults (issue 24's bound: 0.05%). Here at 96x72, seed 4,
// against a 256-spp path trace (which finds the same salt pixels as a
// 1024-spp one): 74 pixels (1.07%) unguided, 4 (0.058%) at the defaults,
// the rest of them at the room's edges.
TEST_CASE("sparse room: at the defaults the final gather leaves no salt, and keeps the mean") {
  static const Film ref =
      test::renderOnce(sparseRoom(kSaltW, kSaltH), test::smallRenderOptions(RenderMethod::PathTrace, 256, 16, 9));
  image::ImageRgb r = toImage(ref);
  image::PixelRect all{0, 0, kSaltW, kSaltH};
  Film off = photonRender(false, 50000, 16, 4, false, kSaltW, kSaltH);
  Film on = photonRender(false, 50000, 16, 4, true, kSaltW, kSaltH);
  double saltOff = image::countSalt(toImage(off), r, all).share;
  double saltOn = image::countSalt(toImage(on), r, all).share;
  double meanOff = meanOutsideLamp(off) / meanOutsideLamp(ref), meanOn = meanOutsideLamp(on) / meanOutsideLamp(ref);
  MESSAGE("salt share off " << saltOff << ", on " << saltOn << "; mean off " << meanOff << ", on " << meanOn);
  CHECK(saltOff > 0.005);  // the test can fail: the unguided gather is salty here
  CHECK(saltOn <= 0.001);  // at most 7 pixels of 6,912
  CHECK(saltOn < saltOff / 8.0);
  CHECK(meanOn == doctest::Approx(1.0).epsilon(0.03));
  CHECK(meanOff == doctest::Approx(1.0).epsilon(0.03));
}
