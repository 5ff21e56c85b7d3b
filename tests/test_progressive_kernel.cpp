// tests/test_progressive_kernel.cpp — the fixed-radius range query
// (photon/kdtree.h KdTree::range) against brute force, and the fixed-kernel
// estimates (estimate/fixed_kernel.h) against known densities: uniform
// photon fields, a density linear in time, a clipped window at the shutter
// ends, a plane moving along its normal (slice correction), and the side
// and surface-tag rules.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "estimate/fixed_kernel.h"
#include "photon/kdtree.h"
#include "photon/store.h"

using namespace tdpm;

namespace {

constexpr float kQ = 1e-3f;  // energy per photon (J): exact in RGBE (a power of two times 131/128)

// n photons uniform on the square [-1, 1]^2 of the plane y = yOf(t), arriving
// from above, with times drawn by `timeOf(u)` from a uniform u.
template <class TimeOf, class YOf>
photon::PhotonStore planeField(size_t n, uint64_t seed, TimeOf timeOf, YOf yOf, Vec3f wi = {0, 1, 0},
                               uint8_t tag = 0) {
  photon::PhotonStore s(0.0f, 1.0f);
  Rng rng(seed);
  for (size_t i = 0; i < n; ++i) {
    float x = rng.uniform() * 2 - 1, z = rng.uniform() * 2 - 1, t = timeOf(rng.uniform());
    s.add({x, yOf(t), z}, Rgb(kQ), wi, t, tag);
  }
  return s;
}

float decodedQ() { return photon::decodeRgbe(photon::encodeRgbe(Rgb(kQ))).r; }

}  // namespace

TEST_CASE("range query: exactly the photons within the radius, as brute force finds them") {
  photon::PhotonStore s(0.0f, 1.0f);
  Rng rng(5);
  for (int i = 0; i < 20000; ++i) {
    // a plane, a wall and a tight cluster: duplicate keys and empty regions
    float c = rng.uniform();
    Vec3f p = c < 0.5f ? Vec3f{rng.uniform(), 0.0f, rng.uniform()}
              : c < 0.8f ? Vec3f{rng.uniform(), rng.uniform(), 0.0f}
                         : Vec3f{0.5f + 0.01f * rng.uniform(), 0.0f, 0.5f};
    s.add(p, Rgb(1.0f), {0, 1, 0}, rng.uniform());
  }
  photon::KdTree tree = photon::KdTree::build(s);
  photon::RangeQuery q;
  for (int k = 0; k < 200; ++k) {
    Vec3f p{rng.uniform(), rng.uniform() * 0.2f, rng.uniform()};
    if (k % 10 == 0) p = {0.505f, 0.0f, 0.5f};
    float r2 = k % 3 == 0 ? 0.001f : k % 3 == 1 ? 0.01f : 0.05f;
    int n = tree.range(p, r2, q);
    std::vector<uint32_t> got(q.index(), q.index() + n), want;
    for (size_t i = 0; i < s.size(); ++i)
      if (lengthSquared(s.position(i) - p) <= r2) want.push_back(uint32_t(i));
    std::sort(got.begin(), got.end());
    REQUIRE(got == want);
    for (int i = 0; i < n; ++i) CHECK(q.dist2()[i] == doctest::Approx(lengthSquared(s.position(q.index()[i]) - p)));
  }
  // The buffers grew to the largest result and stay (no allocation per query).
  size_t cap = q.capacity();
  tree.range({0.505f, 0.0f, 0.5f}, 0.05f, q);
  CHECK(q.capacity() == cap);
  CHECK(tree.range({0.5f, 0.0f, 0.5f}, 0.0f, q) == 0);
}

TEST_CASE("fixed kernels: a uniform photon field gives its irradiance, in space and in space-time") {
  const size_t n = 400000;
  photon::PhotonStore s = planeField(n, 7, [](float u) { return u; }, [](float) { return 0.0f; });
  photon::KdTree tree = photon::KdTree::build(s);
  // E = n Q / (area 4 * shutter 1); with brdf 1 the estimate is E.
  const double want = double(n) * decodedQ() / 4.0;
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf one{Rgb(1.0f)};
  Vec3f up{0, 1, 0};
  Rng rng(9);
  double sumS = 0, sumT = 0, sumClip = 0;
  const int m = 64;
  for (int i = 0; i < m; ++i) {
    Vec3f x{rng.uniform() - 0.5f, 0.0f, rng.uniform() - 0.5f};
    sumS += g.spatial(tree, x, up, up, 0.05f, one).r;
    estimate::FixedReport rep;
    sumT += g.spaceTime(tree, x, up, up, 0.5f, 0.1f, 0.1f, one, photon::kNoSurfaceTag, &rep).r;
    CHECK(rep.windowLo == doctest::Approx(0.4f));
    CHECK(rep.windowHi == doctest::Approx(0.6f));
    // At the shutter's open the window [-0.07, 0.13] is clipped to [0, 0.13]
    // and normalised by the clipped length: still unbiased.
    sumClip += g.spaceTime(tree, x, up, up, 0.03f, 0.1f, 0.1f, one, photon::kNoSurfaceTag, &rep).r;
    CHECK(rep.windowLo == 0.0f);
    CHECK(rep.windowHi == doctest::Approx(0.13f));
  }
  // Photons per estimate: spatial n pi 0.05^2 / 4 = 785 (sd 3.6%), over 64
  // points 0.45%; space-time 0.2 of 3140 = 628 (0.5% over 64), clipped 0.13: 408.
  MESSAGE("spatial " << sumS / m / want << ", space-time " << sumT / m / want << ", clipped " << sumClip / m / want);
  CHECK(sumS / m / want == doctest::Approx(1.0).epsilon(0.025));
  CHECK(sumT / m / want == doctest::Approx(1.0).epsilon(0.03));
  CHECK(sumClip / m / want == doctest::Approx(1.0).epsilon(0.035));
}

TEST_CASE("fixed kernels: a density linear in time is recovered by the symmetric window") {
  // Times with pdf 2t: the irradiance at time t is 2t times the shutter mean.
  const size_t n = 400000;
  photon::PhotonStore s = planeField(n, 11, [](float u) { return std::sqrt(u); }, [](float) { return 0.0f; });
  photon::KdTree tree = photon::KdTree::build(s);
  const double mean = double(n) * decodedQ() / 4.0;
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf one{Rgb(1.0f)};
  Vec3f up{0, 1, 0};
  for (float t : {0.25f, 0.75f}) {
    double sum = 0;
    Rng rng(13);
    for (int i = 0; i < 64; ++i) {
      Vec3f x{rng.uniform() - 0.5f, 0.0f, rng.uniform() - 0.5f};
      sum += g.spaceTime(tree, x, up, up, t, 0.1f, 0.1f, one).r;
    }
    MESSAGE("t = " << t << ": " << sum / 64 / (2 * t * mean));
    CHECK(sum / 64 / (2 * t * mean) == doctest::Approx(1.0).epsilon(0.04));
  }
  // The spatial estimate averages the whole shutter: the mean, whatever t.
  Rng rng(17);
  double sum = 0;
  for (int i = 0; i < 64; ++i) sum += g.spatial(tree, {rng.uniform() - 0.5f, 0, rng.uniform() - 0.5f}, up, up, 0.05f, one).r;
  CHECK(sum / 64 / mean == doctest::Approx(1.0).epsilon(0.025));
}

TEST_CASE("fixed kernels: the slice correction makes a plane moving along its normal exact") {
  // y = -t: at time t the query point lies on the plane; photons of time
  // t + s lie s below it, in a disc of radius^2 r^2 - s^2 of the ball.
  const size_t n = 400000;
  photon::PhotonStore s = planeField(n, 19, [](float u) { return u; }, [](float t) { return -t; });
  photon::KdTree tree = photon::KdTree::build(s);
  const double want = double(n) * decodedQ() / 4.0;
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf one{Rgb(1.0f)};
  Vec3f up{0, 1, 0};
  Rng rng(23);
  double sum = 0, uncorrected = 0;
  const float r = 0.1f, h = 0.06f;  // h < r sqrt(1/2): inside the slice-weight cap
  for (int i = 0; i < 64; ++i) {
    float t = 0.2f + 0.6f * rng.uniform();
    Vec3f x{rng.uniform() - 0.5f, -t, rng.uniform() - 0.5f};
    sum += g.spaceTime(tree, x, up, up, t, r, h, one).r;
  }
  // Without the correction the ball holds int (r^2 - s^2) ds / (2 h r^2) =
  // 1 - h^2 / (3 r^2) = 0.88 of the photons a flat disc would.
  uncorrected = 1.0 - double(h * h) / (3.0 * double(r * r));
  MESSAGE("moving plane: " << sum / 64 / want << " (uncorrected would be " << uncorrected << ")");
  CHECK(sum / 64 / want == doctest::Approx(1.0).epsilon(0.03));
}

TEST_CASE("fixed kernels: photons from behind and from the other side of the same surface do not count") {
  const size_t n = 100000;
  auto t = [](float u) { return u; };
  auto y0 = [](float) { return 0.0f; };
  photon::PhotonStore front = planeField(n, 29, t, y0, {0, 1, 0}, photon::surfaceTag(3, false));
  photon::PhotonStore behind = planeField(n, 29, t, y0, {0, -1, 0}, photon::surfaceTag(3, false));
  photon::PhotonStore otherSide = planeField(n, 29, t, y0, {0, 1, 0}, photon::surfaceTag(3, true));
  photon::KdTree a = photon::KdTree::build(front), b = photon::KdTree::build(behind),
                 c = photon::KdTree::build(otherSide);
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf one{Rgb(1.0f)};
  Vec3f up{0, 1, 0}, x{0.1f, 0.0f, 0.2f};
  uint8_t tag = photon::surfaceTag(3, false);
  CHECK(g.spatial(a, x, up, up, 0.1f, one, tag).r > 0.0f);
  CHECK(g.spaceTime(a, x, up, up, 0.5f, 0.1f, 0.1f, one, tag).r > 0.0f);
  CHECK(g.spatial(b, x, up, up, 0.1f, one, tag).r == 0.0f);
  CHECK(g.spaceTime(b, x, up, up, 0.5f, 0.1f, 0.1f, one, tag).r == 0.0f);
  CHECK(g.spatial(c, x, up, up, 0.1f, one, tag).r == 0.0f);
  CHECK(g.spaceTime(c, x, up, up, 0.5f, 0.1f, 0.1f, one, tag).r == 0.0f);
  // Untagged queries accept either side of the surface.
  CHECK(g.spatial(c, x, up, up, 0.1f, one).r > 0.0f);
}

TEST_CASE("fixed kernels: a window narrower than a time bin weighs each photon by its bin's overlap") {
  // One bin is 1/256 s. Photons uniform in time: a half window of a
  // quarter bin, anywhere in a bin, still estimates the irradiance.
  const size_t n = 400000;
  photon::PhotonStore s = planeField(n, 31, [](float u) { return u; }, [](float) { return 0.0f; });
  photon::KdTree tree = photon::KdTree::build(s);
  const double want = double(n) * decodedQ() / 4.0;
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf one{Rgb(1.0f)};
  Vec3f up{0, 1, 0};
  Rng rng(37);
  double sum = 0;
  const int m = 256;
  for (int i = 0; i < m; ++i) {
    Vec3f x{rng.uniform() - 0.5f, 0.0f, rng.uniform() - 0.5f};
    sum += g.spaceTime(tree, x, up, up, 0.1f + 0.8f * rng.uniform(), 0.3f, 0.25f / 256.0f, one).r;
  }
  // n pi 0.09 / 4 = 28k photons in the disc, 1/512 of them in the window: ~55 per query.
  MESSAGE("sub-bin window: " << sum / m / want);
  CHECK(sum / m / want == doctest::Approx(1.0).epsilon(0.04));
}
