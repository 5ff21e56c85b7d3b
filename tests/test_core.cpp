// tests/test_core.cpp — core/ and math/: RNG statistics, transforms.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include "core/rng.h"
#include "math/frame.h"
#include "math/transform.h"

using namespace tdpm;

TEST_CASE("rng: uniform in [0,1) with the right mean and variance") {
  Rng rng(42, 7);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    float u = rng.uniform();
    REQUIRE(u >= 0.0f);
    REQUIRE(u < 1.0f);
    sum += u;
    sum2 += double(u) * u;
  }
  double mean = sum / n, var = sum2 / n - mean * mean;
  // Standard error of the mean is sqrt(1/12/n) = 6.5e-4: 5 sigma bounds.
  CHECK(mean == doctest::Approx(0.5).epsilon(0.0065));
  CHECK(var == doctest::Approx(1.0 / 12.0).epsilon(0.01));
}

TEST_CASE("rng: same seed and stream replay, different streams differ") {
  Rng a(1, 2), b(1, 2), c(1, 3);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    uint32_t x = a.nextU32();
    CHECK(x == b.nextU32());
    differs |= (x != c.nextU32());
  }
  CHECK(differs);
}

TEST_CASE("transform: inverse, normals and TRS order") {
  Affine3f m = Affine3f::fromTRS({1, 2, 3}, Quaternion::fromAxisAngle({0, 1, 0}, kPi / 2), {2, 2, 2});
  Vec3f p{1, 0, 0};
  Vec3f q = m.point(p);  // scale to (2,0,0), rotate 90 deg about y to (0,0,-2), translate
  CHECK(q.x == doctest::Approx(1.0f));
  CHECK(q.y == doctest::Approx(2.0f));
  CHECK(q.z == doctest::Approx(1.0f));
  Vec3f back = m.inverse().point(q);
  CHECK(back.x == doctest::Approx(1.0f));
  CHECK(std::fabs(back.y) < 1e-5f);
  CHECK(std::fabs(back.z) < 1e-5f);
  // A non-uniform scale: the transformed normal stays perpendicular to the surface.
  Affine3f s = Affine3f::scale({1, 4, 1});
  Vec3f tangent = s.vector(normalize(Vec3f{1, -1, 0}));
  Vec3f n = s.normal(normalize(Vec3f{1, 1, 0}));
  CHECK(std::fabs(dot(tangent, n)) < 1e-5f);
}

TEST_CASE("frame: orthonormal for many normals") {
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    Vec3f n = normalize(Vec3f{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
    Frame f(n);
    CHECK(std::fabs(dot(f.s, f.t)) < 1e-5f);
    CHECK(std::fabs(dot(f.s, f.n)) < 1e-5f);
    CHECK(std::fabs(length(f.s) - 1.0f) < 1e-5f);
    Vec3f v{0.3f, -0.2f, 0.9f};
    Vec3f r = f.toLocal(f.toWorld(v));
    CHECK(r.x == doctest::Approx(v.x).epsilon(1e-4));
  }
}
