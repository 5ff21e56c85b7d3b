// tests/test_media_majorant.cpp — the majorant grid of density-grid media
// (media/medium.h): every cell bounds the density it can be read at; ratio
// tracking and delta / spectral tracking over it keep the closed forms
// (transmittance exp(-optical depth) by quadrature, collision probability
// 1 - T and the first-collision distance's distribution 1 - T(t)) in a grid
// whose one corner is dense and the rest empty, still and moving; and one
// majorant cell reproduces the global majorant. Fixed seeds; bounds are 4
// standard errors.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "media/medium.h"

using namespace tdpm;

namespace {

// A 24^3 grid on [0, 2]^3 (grid = world), zero except a dense blob in the
// corner cells x, y, z < 6 (density 2 + the cell's index sum / 4, up to 5.75),
// plus one thin sheet of density 0.5 at x cells 16-17 (so a ray through the
// empty part still meets some medium). sigma_t per density: grey 1, or
// chromatic (0.4, 1.0, 1.6).
scene::MediumDesc cornerDesc(bool chromatic) {
  scene::MediumDesc m;
  m.type = scene::MediumDesc::Type::Grid;
  m.sigmaA = chromatic ? Rgb(0.1f, 0.5f, 0.6f) : Rgb(0.25f);
  m.sigmaS = chromatic ? Rgb(0.3f, 0.5f, 1.0f) : Rgb(0.75f);
  const int n = 24;
  m.grid.nx = m.grid.ny = m.grid.nz = n;
  m.grid.density.assign(size_t(n) * n * n, 0.0f);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        float& v = m.grid.density[(size_t(z) * n + size_t(y)) * n + size_t(x)];
        if (x < 6 && y < 6 && z < 6) v = 2.0f + float(x + y + z) / 4.0f;
        if (x == 16 || x == 17) v = 0.5f;
      }
  m.grid.bounds = {{0, 0, 0}, {2, 2, 2}};
  return m;
}

// Optical depth (channel c) along o + s d, s in [0, tMax], by the midpoint
// rule on the grid's own lookup, the grid shifted by `offset` in world.
double opticalDepth(const media::Medium& m, Vec3f o, Vec3f d, float tMax, int c, Vec3f offset = Vec3f(0.0f)) {
  const int n = 40000;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += media::gridDensity(m, o + d * ((float(i) + 0.5f) * tMax / n) - offset);
  float st = c == 0 ? m.sigmaT.r : c == 1 ? m.sigmaT.g : m.sigmaT.b;
  return sum * tMax / n * st;
}

template <class F>
std::pair<double, double> meanAndError(int n, F&& f) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    double v = f();
    s += v;
    s2 += v * v;
  }
  double mean = s / n, var = std::max(0.0, s2 / n - mean * mean);
  return {mean, std::sqrt(var / n)};
}

float channel(Rgb v, int c) { return c == 0 ? v.r : c == 1 ? v.g : v.b; }

// The rays: through the dense corner and on through the sheet; diagonal
// through the whole grid; through the empty part and the sheet only.
struct Ray {
  Vec3f o, d;
  float tMax;
};
std::vector<Ray> rays() {
  return {{{-0.5f, 0.2f, 0.3f}, normalize(Vec3f(1.0f, 0.05f, 0.02f)), 3.0f},
          {{-0.1f, -0.1f, -0.1f}, normalize(Vec3f(1.0f, 1.0f, 1.0f)), 3.8f},
          {{0.1f, 1.4f, 1.1f}, normalize(Vec3f(1.0f, -0.1f, 0.2f)), 2.2f},
          {{1.9f, 1.9f, 0.05f}, normalize(Vec3f(-1.0f, -0.9f, 0.1f)), 2.7f}};
}

}  // namespace

TEST_CASE("majorant grid: every cell bounds the density anywhere in it, and empty cells are 0") {
  media::Medium m = media::makeMedium(cornerDesc(true), nullptr);
  REQUIRE(m.mx == 16);
  REQUIRE(m.my == 16);
  REQUIRE(m.mz == 16);
  const std::vector<float>& maj = *m.majorants;
  Rng rng(2);
  for (int i = 0; i < 200000; ++i) {
    Vec3f p(2.0f * rng.uniform(), 2.0f * rng.uniform(), 2.0f * rng.uniform());
    int cx = std::min(15, int(p.x * 8.0f)), cy = std::min(15, int(p.y * 8.0f)), cz = std::min(15, int(p.z * 8.0f));
    float bound = maj[(size_t(cz) * 16 + size_t(cy)) * 16 + size_t(cx)];
    REQUIRE(media::gridDensity(m, p) * 1.6f <= bound * (1.0f + 1e-6f));
  }
  // Cells whose footprint holds no non-zero sample are 0 (tracking skips
  // them), and the corner's bound is far below the global one elsewhere.
  int zero = 0;
  for (float v : maj) zero += v == 0.0f;
  CHECK(zero > 16 * 16 * 16 / 2);
  CHECK(maj[(size_t(15) * 16 + 15) * 16 + 11] == doctest::Approx(0.5f * 1.6f));  // the sheet only
  CHECK(maj[0] < m.majorant);
  CHECK(*std::max_element(maj.begin(), maj.end()) == m.majorant);
  // One cell is the global majorant exactly.
  media::Medium one = media::makeMedium(cornerDesc(true), nullptr, nullptr, 1);
  REQUIRE(one.majorants->size() == 1);
  CHECK((*one.majorants)[0] == one.majorant);
  CHECK(one.majorant == m.majorant);
  // A grid whose cells bound at least half the global majorant on average
  // (here uniform, then mostly dense) collapses to one cell.
  scene::MediumDesc uniform = cornerDesc(false);
  for (float& v : uniform.grid.density) v = 1.0f;
  CHECK(media::makeMedium(uniform, nullptr).majorants->size() == 1);
  for (size_t i = 0; i < uniform.grid.density.size(); i += 7) uniform.grid.density[i] = 0.0f;
  CHECK(media::makeMedium(uniform, nullptr).majorants->size() == 1);
}

TEST_CASE("majorant grid: ratio tracking keeps exp(-optical depth), still and moving, in every channel") {
  media::Medium m = media::makeMedium(cornerDesc(true), nullptr);
  uint64_t seed = 100;
  for (const Ray& r : rays()) {
    for (int c = 0; c < 3; ++c) {
      double expected = std::exp(-opticalDepth(m, r.o, r.d, r.tMax, c));
      Rng rng(++seed);
      auto [mean, err] = meanAndError(40000, [&] { return double(channel(media::transmittance(m, r.o, r.d, r.tMax, 0.5f, rng), c)); });
      CHECK(std::fabs(mean - expected) < 4 * err + 1e-4);
      CHECK(err < 0.01 * expected + 2e-3);
    }
  }
  // Inside an object moving +y by 0.8 over the shutter: at time 0.25 the
  // grid (and its majorant grid, in grid space) sits 0.2 higher.
  Motion motion = Motion::keyframed({0.0f, Vec3f(0.0f), Quaternion{}, Vec3f(1.0f)},
                                    {{0.0f, Vec3f(0.0f), Quaternion{}, Vec3f(1.0f)},
                                     {1.0f, Vec3f(0, 0.8f, 0), Quaternion{}, Vec3f(1.0f)}},
                                    Shutter{0.0f, 1.0f});
  media::Medium moving = media::makeMedium(cornerDesc(true), &motion);
  REQUIRE(moving.moving);
  const Ray r = rays()[0];
  double expected = std::exp(-opticalDepth(m, r.o, r.d, r.tMax, 2, {0, 0.2f, 0}));
  double stillValue = std::exp(-opticalDepth(m, r.o, r.d, r.tMax, 2));
  Rng rng(9);
  auto [mean, err] = meanAndError(40000, [&] { return double(media::transmittance(moving, r.o, r.d, r.tMax, 0.25f, rng).b); });
  CHECK(std::fabs(mean - expected) < 4 * err + 1e-4);
  CHECK(std::fabs(expected - stillValue) > 20 * err);  // the motion matters at this precision
}

TEST_CASE("majorant grid: delta tracking's first collision follows 1 - T(t) through the dense corner") {
  media::Medium m = media::makeMedium(cornerDesc(false), nullptr);
  for (const Ray& r : rays()) {
    const int n = 60000;
    std::vector<float> hits;
    int absorbs = 0;
    Rng rng(31);
    for (int i = 0; i < n; ++i) {
      Rgb beta(1.0f);
      media::FreeFlight f = media::sampleFreeFlight(m, r.o, r.d, r.tMax, 0.5f, rng, beta);
      REQUIRE(beta.r == 1.0f);  // grey: plain delta tracking, weight untouched
      if (f.event == media::FreeFlight::Event::Escape) continue;
      REQUIRE(f.t > 0.0f);
      REQUIRE(f.t < r.tMax);
      hits.push_back(f.t);
      absorbs += f.event == media::FreeFlight::Event::Absorb;
    }
    // P(first collision before t) = 1 - T(t) at eight points along the ray.
    for (int q = 1; q <= 8; ++q) {
      float t = r.tMax * float(q) / 8.0f;
      double expected = 1.0 - std::exp(-opticalDepth(m, r.o, r.d, t, 0));
      double p = double(std::count_if(hits.begin(), hits.end(), [&](float h) { return h < t; })) / n;
      double err = std::sqrt(std::max(expected * (1 - expected), 1e-6) / n);
      CHECK(std::fabs(p - expected) < 4 * err + 1e-5);
    }
    if (hits.size() > 5000) CHECK(std::fabs(double(absorbs) / double(hits.size()) - 0.25) < 0.015);
  }
}

TEST_CASE("majorant grid: spectral tracking estimates each channel's transmittance through the corner") {
  media::Medium m = media::makeMedium(cornerDesc(true), nullptr);
  for (const Ray& r : rays()) {
    const int n = 60000;
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    Rng rng(17);
    for (int i = 0; i < n; ++i) {
      Rgb beta(1.0f);
      media::FreeFlight f = media::sampleFreeFlight(m, r.o, r.d, r.tMax, 0.5f, rng, beta);
      if (f.event != media::FreeFlight::Event::Escape) continue;
      for (int c = 0; c < 3; ++c) sum[c] += channel(beta, c), sum2[c] += double(channel(beta, c)) * channel(beta, c);
    }
    for (int c = 0; c < 3; ++c) {
      double mean = sum[c] / n, err = std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / n);
      double expected = std::exp(-opticalDepth(m, r.o, r.d, r.tMax, c));
      CHECK(std::fabs(mean - expected) < 4 * err + 1e-4);
    }
  }
}

TEST_CASE("majorant grid: a ray through empty cells only never collides") {
  media::Medium m = media::makeMedium(cornerDesc(true), nullptr);
  Rng rng(4);
  for (int i = 0; i < 1000; ++i) {
    Rgb beta(1.0f);
    // Along z at x = y = 1.2: every cell on the way is empty (sheet at x in [1.33, 1.5]).
    media::FreeFlight f = media::sampleFreeFlight(m, {1.2f, 1.2f, -1.0f}, {0, 0, 1}, 4.0f, 0.5f, rng, beta);
    REQUIRE(f.event == media::FreeFlight::Event::Escape);
    REQUIRE((beta.r == 1.0f && beta.g == 1.0f && beta.b == 1.0f));
    Rgb T = media::transmittance(m, {1.2f, 1.2f, -1.0f}, {0, 0, 1}, 4.0f, 0.5f, rng);
    REQUIRE((T.r == 1.0f && T.g == 1.0f && T.b == 1.0f));
  }
}

TEST_CASE("media: a homogeneous medium is never marched: closed-form transmittance, one draw pair per grey free flight") {
  scene::MediumDesc d;
  d.sigmaA = Rgb(0.2f);
  d.sigmaS = Rgb(0.6f);
  media::Medium m = media::makeMedium(d, nullptr);
  REQUIRE(m.homogeneous());
  CHECK(!m.majorants);  // no majorant grid: nothing to walk
  Rng rng(8), copy(8);
  for (float tMax : {0.01f, 1.0f, 30.0f}) {
    Rgb T = media::transmittance(m, {0, 0, 0}, {0, 1, 0}, tMax, 0.5f, rng);
    CHECK(T.r == std::exp(-0.8f * tMax));
  }
  CHECK(rng.uniform() == copy.uniform());  // transmittance drew nothing
  // Grey free flight: one exponential distance, and when it lands before
  // tMax one uniform for absorb / scatter (the first tentative collision
  // is always real: sigma_bar = sigma_t). Far fewer draws than any march.
  for (int i = 0; i < 1000; ++i) {
    Rgb beta(1.0f);
    media::FreeFlight f = media::sampleFreeFlight(m, {0, 0, 0}, {0, 1, 0}, 2.0f, 0.5f, rng, beta);
    copy.uniform();
    if (f.event != media::FreeFlight::Event::Escape) copy.uniform();
    REQUIRE(rng.uniform() == copy.uniform());
  }
}
