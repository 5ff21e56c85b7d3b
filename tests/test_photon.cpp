// tests/test_photon.cpp — photon/store.h and photon/kdtree.h: encodings,
// batch concatenation, memory bound, tree invariants, k-NN against brute
// force (3D and 4D), degenerate inputs.
#include <doctest/doctest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "photon/kdtree.h"
#include "photon/store.h"

using namespace tdpm;
using namespace tdpm::photon;

namespace {

Vec3f randomDirection(Rng& rng) {
  float z = 1.0f - 2.0f * rng.uniform();
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Surface-like photons: a floor, a wall and a tight caustic, plus exact
// duplicates (photons stored twice at one point happen on corners).
PhotonStore makePhotons(size_t n, uint64_t seed, float t0 = 0.0f, float t1 = 1.0f) {
  PhotonStore s(t0, t1);
  s.reserve(n);
  Rng rng(seed);
  for (size_t i = 0; i < n; ++i) {
    float c = rng.uniform();
    Vec3f p;
    if (c < 0.5f)
      p = {rng.uniform() * 4.0f - 2.0f, 0.0f, rng.uniform() * 4.0f - 2.0f};
    else if (c < 0.8f)
      p = {rng.uniform() * 4.0f - 2.0f, rng.uniform() * 3.0f, -2.0f};
    else if (c < 0.98f || i == 0)
      p = {0.3f + 0.05f * (rng.uniform() - 0.5f), 0.0f, 0.2f + 0.05f * (rng.uniform() - 0.5f)};
    else
      p = s.position(rng.below(uint32_t(s.size())));
    s.add(p, Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-4f, randomDirection(rng),
          t0 + (t1 - t0) * rng.uniform(), uint8_t(i & 0x3F));
  }
  return s;
}

}  // namespace

TEST_CASE("photon store: RGBE energy rounds to nearest, error <= 1/255 of the largest channel") {
  Rng rng(1);
  double meanRel = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    float scale = std::ldexp(1.0f, int(rng.below(120)) - 80);
    Rgb c(rng.uniform() * scale, rng.uniform() * scale, rng.uniform() * scale);
    Rgb d = decodeRgbe(encodeRgbe(c));
    float m = c.maxComponent();
    for (int k = 0; k < 3; ++k) CHECK(std::fabs(d[k] - c[k]) <= m / 255.0f + 1e-38f);  // 1/256, or a hair more after rounding up to 256
    meanRel += (d.r + d.g + d.b - c.r - c.g - c.b) / (3.0 * m);
  }
  // Rounding to nearest: the mean error is ~0 (truncation would be ~ -1/512).
  CHECK(std::fabs(meanRel / n) < 2e-4);
  CHECK(decodeRgbe(encodeRgbe(Rgb(0.0f))).isBlack());
  CHECK(decodeRgbe(encodeRgbe(Rgb(-1.0f, std::nanf(""), 0.0f))).isBlack());
  Rgb big = decodeRgbe(encodeRgbe(Rgb(255.9f, 1.0f, 0.0f)));  // rounds up to 256: exponent moves
  CHECK(big.r == doctest::Approx(256.0f));
}

TEST_CASE("photon store: octahedral directions within 1.5 degrees, time bins and flags") {
  Rng rng(2);
  float worst = 1.0f;
  for (int i = 0; i < 20000; ++i) {
    Vec3f d = randomDirection(rng);
    worst = std::min(worst, dot(d, decodeDirection(encodeDirection(d))));
  }
  CHECK(worst > std::cos(1.5f * kPi / 180.0f));
  for (Vec3f d : {Vec3f(0, 0, 1), Vec3f(0, 0, -1), Vec3f(1, 0, 0), Vec3f(0, -1, 0)})
    CHECK(dot(d, decodeDirection(encodeDirection(d))) > 0.9999f);

  TimeQuantiser tq(1.0f, 3.0f);
  CHECK(tq.quantise(1.0f) == 0);
  CHECK(tq.quantise(3.0f) == 255);
  CHECK(tq.quantise(-5.0f) == 0);
  CHECK(tq.quantise(1e30f) == 255);
  CHECK(tq.quantise(std::nanf("")) == 0);
  CHECK(tq.quantise(1.0f + 2.0f / 256.0f * 10.5f) == 10);
  CHECK(tq.binCentre(10) == doctest::Approx(1.0f + 2.0f / 256.0f * 10.5f));
  // The quantisation error is at most half a bin, ts / 512.
  for (int i = 0; i < 1000; ++i) {
    float t = 1.0f + 2.0f * rng.uniform();
    CHECK(std::fabs(tq.binCentre(tq.quantise(t)) - t) <= 2.0f / 512.0f + 1e-6f);
  }

  PhotonStore s(0.0f, 1.0f);
  s.add({1, 2, 3}, Rgb(1, 2, 3), {0, 1, 0}, 0.75f, 0x2A);
  CHECK(s.timeBin(0) == 192);
  CHECK(s.userFlags(0) == 0x2A);
  s.setSplitAxis(0, 3);
  CHECK(s.splitAxis(0) == 3);
  CHECK(s.timeBin(0) == 192);
  CHECK(s.userFlags(0) == 0x2A);
}

TEST_CASE("photon store: per-thread batches concatenate in batch order, independent of thread timing") {
  const int nb = 8, per = 5000;
  PhotonStore serial(0.0f, 2.0f);
  std::vector<PhotonStore> batches(nb, PhotonStore(0.0f, 2.0f));
  auto fill = [](PhotonStore& s, int b) {
    Rng rng(77, uint64_t(b));
    for (int i = 0; i < per; ++i)
      s.add({rng.uniform(), rng.uniform(), rng.uniform()}, Rgb(rng.uniform()), {0, 0, 1}, 2.0f * rng.uniform());
  };
  for (int b = 0; b < nb; ++b) fill(serial, b);
  tbb::parallel_for(0, nb, [&](int b) { fill(batches[b], b); });
  PhotonStore merged(0.0f, 2.0f);
  merged.add({9, 9, 9}, Rgb(1.0f), {0, 0, 1}, 0.5f);  // appends after existing photons
  merged.appendBatches(batches);
  REQUIRE(merged.size() == serial.size() + 1);
  bool same = true;
  for (size_t i = 0; i < serial.size(); ++i) {
    same &= merged.xs()[i + 1] == serial.xs()[i] && merged.energies()[i + 1] == serial.energies()[i] &&
            merged.flags()[i + 1] == serial.flags()[i] && merged.directions()[i + 1] == serial.directions()[i];
  }
  CHECK(same);
}

TEST_CASE("photon store + kd-tree: at most 20 bytes per photon at 1M photons") {
  const size_t n = 1000000;
  PhotonStore s = makePhotons(n, 3);
  KdTree tree = KdTree::build(s);
  CHECK(s.bytesAllocated() == n * 20);
  CHECK(tree.bytesPerPhoton() <= 20.0);
  MESSAGE("bytes per photon incl. kd-tree: " << tree.bytesPerPhoton());
  // Growth by push_back without reserve leaves slack: shrinkToFit removes it.
  PhotonStore g(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) g.add({0, 0, 0}, Rgb(1.0f), {0, 0, 1}, 0.5f);
  g.shrinkToFit();
  CHECK(g.bytesPerPhoton() == 20.0);
}

namespace {
// Every node splits its subtree: left keys <= node key <= right keys.
bool checkHeapInvariant(const KdTree& tree) {
  const PhotonStore& s = tree.store();
  size_t n = s.size();
  auto key = [&](size_t i, int a) {
    if (a == 3) return std::sqrt(tree.kappa()) * s.time(i);
    return s.position(i)[a];
  };
  for (size_t i = 0; i < n; ++i) {
    int a = s.splitAxis(i);
    float k = key(i, a);
    // walk both subtrees level by level (contiguous ranges in heap layout)
    for (int side = 0; side < 2; ++side) {
      size_t first = 2 * i + 1 + side, count = 1;
      while (first < n) {
        for (size_t j = first; j < std::min(n, first + count); ++j) {
          float v = key(j, a);
          if (side == 0 ? v > k : v < k) return false;
        }
        first = 2 * first + 1;
        count *= 2;
      }
    }
  }
  return true;
}

void checkKnn(const KdTree& tree, Vec3f p, float t, int k, float maxR2, KnnQuery& q, bool fourD) {
  const PhotonStore& s = tree.store();
  std::vector<float> all;
  float sk = std::sqrt(tree.kappa()) , kt = sk * t;
  for (size_t i = 0; i < s.size(); ++i) {
    float dx = s.xs()[i] - p.x, dy = s.ys()[i] - p.y, dz = s.zs()[i] - p.z;
    float d = dx * dx + dy * dy + dz * dz;
    if (fourD) {
      float dt = sk * s.time(i) - kt;
      d += dt * dt;
    }
    if (d < maxR2) all.push_back(d);
  }
  std::sort(all.begin(), all.end());
  int expect = std::min<int>(k, int(all.size()));
  int found = fourD ? tree.knn4(p, t, k, maxR2, q) : tree.knn(p, k, maxR2, q);
  REQUIRE(found == expect);
  std::vector<float> got(q.dist2(), q.dist2() + found);
  std::sort(got.begin(), got.end());
  for (int i = 0; i < found; ++i) {
    // the reported distance is the photon's
    uint32_t id = q.index()[i];
    float dx = s.xs()[id] - p.x, dy = s.ys()[id] - p.y, dz = s.zs()[id] - p.z;
    float d = dx * dx + dy * dy + dz * dz;
    if (fourD) {
      float dt = tree.kappa() > 0 ? sk * s.time(id) - kt : 0.0f;
      d += dt * dt;
    }
    CHECK(std::fabs(d - q.dist2()[i]) <= 1e-5f * (1.0f + d));
  }
  bool same = true;
  for (int i = 0; i < found; ++i) same &= std::fabs(got[i] - all[size_t(i)]) <= 1e-6f * (1.0f + all[size_t(i)]);
  CHECK(same);
  if (found == k)
    CHECK(q.radius2 == doctest::Approx(got.back()));
  else
    CHECK(q.radius2 == maxR2);
}
}  // namespace

TEST_CASE("kd-tree: left-balanced heap invariant, 3D and 4D, serial and parallel builds agree") {
  for (size_t n : {size_t(1), size_t(2), size_t(3), size_t(7), size_t(100), size_t(20000)}) {
    PhotonStore a = makePhotons(n, 10 + n), b = makePhotons(n, 10 + n);
    KdBuildOptions serial;
    serial.parallelCutoff = size_t(1) << 40;
    KdBuildOptions parallel;
    parallel.parallelCutoff = 64;
    KdTree ta = KdTree::build(a, serial);
    KdTree::build(b, parallel);
    CHECK(checkHeapInvariant(ta));
    bool same = true;
    for (size_t i = 0; i < n; ++i) same &= a.xs()[i] == b.xs()[i] && a.flags()[i] == b.flags()[i];
    CHECK(same);
    PhotonStore c = makePhotons(n, 10 + n, 2.0f, 3.0f);
    KdBuildOptions st;
    st.spaceTime = true;
    st.kappa = 4.0f;
    KdTree tc = KdTree::build(c, st);
    CHECK(checkHeapInvariant(tc));
  }
}

TEST_CASE("kd-tree: the order output maps heap positions to the original photons") {
  PhotonStore s = makePhotons(5000, 4);
  std::vector<float> xs(s.xs(), s.xs() + s.size());
  std::vector<uint16_t> fl(s.flags(), s.flags() + s.size());
  std::vector<uint32_t> order;
  KdBuildOptions o;
  o.order = &order;
  KdTree::build(s, o);
  bool ok = true;
  for (size_t i = 0; i < s.size(); ++i) {
    ok &= s.xs()[i] == xs[order[i]];
    ok &= (s.flags()[i] & ~kAxisMask) == (fl[order[i]] & ~kAxisMask);
  }
  CHECK(ok);
}

TEST_CASE("kd-tree: k-NN equals brute force (3D and 4D, with and without max radius)") {
  PhotonStore s = makePhotons(30000, 5);
  KdTree tree = KdTree::build(s);
  KnnQuery q(8);  // grows on demand, once
  Rng rng(6);
  for (int i = 0; i < 60; ++i) {
    Vec3f p = i % 3 == 0 ? s.position(rng.below(uint32_t(s.size())))
                         : Vec3f(rng.uniform() * 5 - 2.5f, rng.uniform() * 3, rng.uniform() * 5 - 2.5f);
    const int ks[5] = {1, 7, 100, 200, 700};
    int k = ks[i % 5];
    float maxR2 = i % 2 ? 0.01f : std::numeric_limits<float>::infinity();
    checkKnn(tree, p, 0.0f, k, maxR2, q, false);
  }
  PhotonStore s4 = makePhotons(30000, 7);
  KdBuildOptions st;
  st.spaceTime = true;
  st.kappa = 2.5f;
  KdTree t4 = KdTree::build(s4, st);
  for (int i = 0; i < 40; ++i) {
    Vec3f p(rng.uniform() * 5 - 2.5f, rng.uniform() * 3, rng.uniform() * 5 - 2.5f);
    const int ks[4] = {1, 50, 200, 400};
    int k = ks[i % 4];
    float maxR2 = i % 2 ? 0.05f : std::numeric_limits<float>::infinity();
    checkKnn(t4, p, rng.uniform(), k, maxR2, q, true);
  }
}

TEST_CASE("kd-tree: degenerate inputs (empty, all at one point, fewer than k, none in range)") {
  KnnQuery q(16);
  PhotonStore empty(0.0f, 1.0f);
  KdTree te = KdTree::build(empty);
  CHECK(te.knn({0, 0, 0}, 10, 1.0f, q) == 0);

  PhotonStore same(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) same.add({1, 1, 1}, Rgb(1.0f), {0, 1, 0}, 0.5f);
  KdTree ts = KdTree::build(same);
  CHECK(ts.knn({1, 1, 1}, 50, 1.0f, q) == 50);
  CHECK(q.radius2 == 0.0f);
  CHECK(ts.knn({1, 1, 2}, 50, 4.0f, q) == 50);
  CHECK(q.radius2 == doctest::Approx(1.0f));
  CHECK(ts.knn({1, 1, 3}, 50, 1.0f, q) == 0);  // none within the maximum radius
  CHECK(q.radius2 == 1.0f);

  PhotonStore few = makePhotons(30, 8);
  KdTree tf = KdTree::build(few);
  CHECK(tf.knn({0, 0, 0}, 100, std::numeric_limits<float>::infinity(), q) == 30);
  CHECK(std::isinf(q.radius2));
  CHECK(std::isfinite(q.maxFound2));
}
