// tests/test_filter.cpp — sampling/filter.h: the Gaussian filter's offsets
// follow the filter (chi-square over its own bins, and moments against an
// independent integration), a box of radius 0.5 is the unfiltered sampler,
// a rendered edge takes the filter's profile while the image mean stays,
// and filtered renders are deterministic across threads and batches.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include <tbb/global_control.h>

#include "core/rng.h"
#include "render/renderer.h"
#include "sampling/filter.h"
#include "scene/parse.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

// pbrt-v4's 1D Gaussian filter, evaluated directly (not from the table):
// exp(-x^2 / (2 sigma^2)) minus its value at the radius, 0 outside.
double smoothGaussian(double x, double r) {
  const double s = kGaussianFilterSigma;
  if (std::fabs(x) >= r) return 0;
  return std::exp(-x * x / (2 * s * s)) - std::exp(-r * r / (2 * s * s));
}

// Integral of smoothGaussian over [a, b] by composite Simpson (independent
// of the erf the filter tabulates with).
double integrate(double a, double b, double r, int steps = 2000) {
  double h = (b - a) / steps, sum = smoothGaussian(a, r) + smoothGaussian(b, r);
  for (int i = 1; i < steps; ++i) sum += smoothGaussian(a + i * h, r) * (i % 2 ? 4 : 2);
  return sum * h / 3;
}

// P(X <= x) for the filter's offset X.
double filterCdf(double x, double r) { return integrate(-r, std::min(std::max(x, -r), r), r) / integrate(-r, r, r); }

scene::SceneDescription edgeScene(int w, int h) {
  // A black slab covering x < 0 in front of a white sky, seen head-on from
  // z = 10: the edge x = 0 projects exactly onto the raster column w / 2.
  auto d = test::emptyScene(w, h);
  d.background = Rgb(1.0f);
  d.camera.position = {0, 0, 10};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = 20;
  d.materials.push_back(test::diffuse(Rgb(0.0f)));
  d.objects.push_back(test::box({20, 40, 0.1f}, {-10, 0, 0}, 0));
  return d;
}

Film renderOn(const scene::SceneDescription& d, const RenderOptions& o, int threads) {
  auto s = Scene::build(d);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  RenderStats st;
  return render(*s, o, Progress{}, st);
}

}  // namespace

TEST_CASE("filter: gaussian offsets follow the filter (chi-square and moments)") {
  for (float r : {1.5f, 2.0f}) {
    CAPTURE(r);
    PixelFilter f(FilterKind::Gaussian, r);
    // 64 bins, each exactly 4 of the table's bins: the expected counts are
    // the smooth filter's integrals over them.
    const int bins = 64, n = 200000;
    std::vector<int> count(bins, 0);
    Rng rng(7, 1);
    double m1 = 0, m2 = 0;
    for (int i = 0; i < n; ++i) {
      float x = f.sample1D(rng.uniform());
      REQUIRE(x >= -r);
      REQUIRE(x < r);
      int b = std::min(bins - 1, int((double(x) + r) / (2.0 * r) * bins));
      ++count[size_t(b)];
      m1 += x;
      m2 += double(x) * x;
    }
    double total = integrate(-r, r, r), chi2 = 0;
    for (int b = 0; b < bins; ++b) {
      double a = -r + 2.0 * r * b / bins, e = n * integrate(a, a + 2.0 * r / bins, r, 200) / total;
      chi2 += (count[size_t(b)] - e) * (count[size_t(b)] - e) / e;
    }
    // 63 degrees of freedom: P(chi2 > 103.4) = 0.001.
    MESSAGE("radius " << r << ": chi-square " << chi2 << " over 64 bins");
    CHECK(chi2 < 103.4);
    // Moments: mean 0, variance from the smooth filter, within 5 standard errors.
    double var = 0, fourth = 0;
    for (int i = 0; i < 4000; ++i) {
      double x = -r + (i + 0.5) * 2.0 * r / 4000, p = smoothGaussian(x, r) / total * (2.0 * r / 4000);
      var += x * x * p;
      fourth += x * x * x * x * p;
    }
    double mean = m1 / n, sampleVar = m2 / n - mean * mean;
    MESSAGE("variance: sampled " << sampleVar << ", filter " << var);
    CHECK(std::fabs(mean) < 5 * std::sqrt(var / n));
    CHECK(std::fabs(sampleVar - var) < 5 * std::sqrt((fourth - var * var) / n));
    // The tabulated density is the filter's within 1% of its peak.
    for (float x = -r + 0.01f; x < r; x += 0.05f)
      CHECK(std::fabs(f.pdf1D(x) - smoothGaussian(x, r) / total) < 0.01 * smoothGaussian(0, r) / total);
  }
}

TEST_CASE("filter: a box of radius 0.5 is the unfiltered sample, wider boxes are uniform") {
  PixelFilter unit;
  Rng rng(3, 5);
  for (int i = 0; i < 1000; ++i) {
    Vec2f u{rng.uniform(), rng.uniform()};
    Vec2f p = unit.sample(u);
    CHECK(p.x == u.x);
    CHECK(p.y == u.y);
  }
  PixelFilter wide(FilterKind::Box, 1.0f);
  CHECK(wide.sample({0.0f, 0.5f}).x == -0.5f);
  CHECK(wide.sample({0.0f, 0.5f}).y == 0.5f);
  CHECK(wide.sample({0.75f, 0.25f}).x == 1.0f);
  CHECK(wide.pdf1D(0.9f) == 0.5f);
  FilterKind k = FilterKind::Box;
  CHECK(parseFilterKind("gaussian", k));
  CHECK(k == FilterKind::Gaussian);
  CHECK_FALSE(parseFilterKind("mitchell", k));
  CHECK(defaultFilterRadius(FilterKind::Gaussian) == 1.5f);
}

TEST_CASE("filter: a rendered edge takes the filter's profile, and the image mean stays") {
  const int w = 16, h = 8;
  auto d = edgeScene(w, h);
  // The path tracer with both samplers, and a progressive photon render (8
  // passes of 8 samples): every pixel loop draws its positions from the filter.
  for (int variant = 0; variant < 3; ++variant) {
    SamplerKind sk = variant == 1 ? SamplerKind::Random : SamplerKind::Sobol;
    RenderOptions o;
    o.method = RenderMethod::PathTrace;
    o.spp = o.maxSpp = 64;
    if (variant == 2) {
      o.method = RenderMethod::Time;
      o.progressive = true;
      o.passes = 8;
      o.spp = o.maxSpp = 8;
    }
    o.sampler = sk;
    o.filter = FilterKind::Gaussian;
    Film g = renderOn(d, o, 2);
    o.filter = FilterKind::Box;
    Film b = renderOn(d, o, 2);
    const int N = 64 * h;  // samples per column
    double meanG = 0, meanB = 0;
    for (int x = 0; x < w; ++x) {
      double col = 0, colBox = 0;
      for (int y = 0; y < h; ++y) {
        col += g.color[size_t(y * w + x)].g;
        colBox += b.color[size_t(y * w + x)].g;
      }
      col /= h;
      colBox /= h;
      meanG += col / w;
      meanB += colBox / w;
      // Pixel centre x + 0.5; the sample is white when centre + X >= w / 2.
      double expected = 1.0 - filterCdf(w / 2.0 - (x + 0.5), 1.5);
      double bound = 4 * std::sqrt(expected * (1 - expected) / N) + 1e-6;
      CAPTURE(samplerName(sk));
      CAPTURE(renderMethodName(o.method));
      CAPTURE(x);
      CHECK(std::fabs(col - expected) <= bound);
      CHECK(colBox == (x < w / 2 ? 0.0 : 1.0));  // the box sees no neighbour
      if (x <= w / 2 - 3 || x >= w / 2 + 2) CHECK(col == expected);  // beyond the radius: exactly 0 or 1
    }
    // The filter is symmetric: what the edge's black side gains, the white side loses.
    CHECK(std::fabs(meanG - 0.5) < 4 * std::sqrt(0.25 / (N * 4)));
    CHECK(meanB == 0.5);
  }
}

TEST_CASE("filter: gaussian renders are bit-identical on 1 and 2 threads and across adaptive batches") {
  auto d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json");
  d.camera.width = 12;
  d.camera.height = 9;
  RenderOptions o;
  o.method = RenderMethod::PathTrace;
  o.filter = FilterKind::Gaussian;
  o.spp = o.maxSpp = 16;
  Film a = renderOn(d, o, 1);
  Film b = renderOn(d, o, 2);
  RenderOptions two = o;
  two.spp = 8;
  two.contrast = 1e-9f;  // never stops: a second batch of 8, indices 8..15
  Film c = renderOn(d, two, 2);
  CHECK(std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Rgb)) == 0);
  CHECK(std::memcmp(a.color.data(), c.color.data(), a.color.size() * sizeof(Rgb)) == 0);
  o.filter = FilterKind::Box;
  Film box = renderOn(d, o, 1);
  CHECK(std::memcmp(a.color.data(), box.color.data(), a.color.size() * sizeof(Rgb)) != 0);
}
