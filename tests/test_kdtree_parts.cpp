// tests/test_kdtree_parts.cpp — KdTree::buildAppended (photon/kdtree.h): a
// tree of two heaps in one store (a part sorted earlier, copied in its heap
// order, and a small part sorted after it) answers every k-NN and range
// query exactly as one tree over the union: the same photons at the same
// squared distances, the same search radius (3D and 4D).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <vector>

#include "core/rng.h"
#include "photon/kdtree.h"
#include "photon/store.h"

using namespace tdpm;
using namespace tdpm::photon;

namespace {

// Photons on a floor and a wall (the surfaces a shared set covers), random
// energies, directions and time bins, so that each photon is told apart by
// its position.
void addRandom(PhotonStore& s, size_t n, Rng& rng) {
  for (size_t i = 0; i < n; ++i) {
    Vec3f p = rng.uniform() < 0.6f ? Vec3f{rng.uniform() * 4.0f - 2.0f, 0.0f, rng.uniform() * 4.0f - 2.0f}
                                   : Vec3f{rng.uniform() * 4.0f - 2.0f, rng.uniform() * 3.0f, -2.0f};
    s.add(p, Rgb(rng.uniform() + 0.1f), Vec3f{0, 1, 0}, s.t0() + rng.uniform() * s.shutterLength(), uint8_t(i % 7));
  }
}

// `from`'s photons after those already in `to`, encoded as they are (time
// bins and, with keepAxis, split axes).
void copyInto(const PhotonStore& from, PhotonStore& to, bool keepAxis) {
  for (size_t p = 0; p < from.size(); ++p)
    to.addEncoded(from.xs()[p], from.ys()[p], from.zs()[p], from.energies()[p], from.directions()[p], from.flags()[p],
                  from.timeBin(p), keepAxis);
}

// A query's result as (squared distance, position, bin), sorted: the heap
// order of the two trees differs, the set must not.
using Found = std::vector<std::tuple<float, float, float, float, int>>;
Found sortedResult(const PhotonStore& s, const uint32_t* idx, const float* d2, int count) {
  Found f;
  for (int i = 0; i < count; ++i) {
    uint32_t p = idx[i];
    f.emplace_back(d2[i], s.xs()[p], s.ys()[p], s.zs()[p], int(s.timeBin(p)));
  }
  std::sort(f.begin(), f.end());
  return f;
}

struct Pair {
  PhotonStore two{0.0f, 1.0f}, one{0.0f, 1.0f};
  KdTree twoTree, oneTree;
};

// The first part (nA photons) sorted alone and copied in heap order, then
// nB more, sorted after it; and the same photons as one tree.
void makePair(Pair& t, size_t nA, size_t nB, uint64_t seed, const KdBuildOptions& opt) {
  Rng rng(seed);
  PhotonStore a(0.0f, 1.0f), b(0.0f, 1.0f);
  addRandom(a, nA, rng);
  addRandom(b, nB, rng);
  KdTree::build(a, opt);
  copyInto(a, t.two, true);
  copyInto(b, t.two, false);
  t.twoTree = KdTree::buildAppended(t.two, nA, opt);
  copyInto(a, t.one, false);
  copyInto(b, t.one, false);
  t.oneTree = KdTree::build(t.one, opt);
}

}  // namespace

TEST_CASE("two-part kd-tree: k-NN equals one tree over the union, exactly") {
  const float inf = std::numeric_limits<float>::infinity();
  for (bool fourD : {false, true}) {
    KdBuildOptions opt;
    opt.spaceTime = fourD;
    opt.kappa = 2.0f;
    for (auto [nA, nB] : {std::pair<size_t, size_t>{5000, 90}, {5000, 0}, {0, 300}, {1, 1}, {3000, 3000}}) {
      Pair t;
      makePair(t, nA, nB, 11 + nA + nB, opt);
      REQUIRE(t.twoTree.size() == nA + nB);
      CHECK(t.twoTree.firstPart() == nA);
      Rng rng(7);
      KnnQuery q2, q1;
      int differ = 0, queries = 0;
      for (int i = 0; i < 400; ++i) {
        Vec3f p{rng.uniform() * 4.4f - 2.2f, rng.uniform() * 0.3f, rng.uniform() * 4.4f - 2.2f};
        if (i % 2) p = {rng.uniform() * 4.4f - 2.2f, rng.uniform() * 3.0f, -2.0f + rng.uniform() * 0.2f};
        int k = 1 + int(rng.uniform() * 250.0f);
        float maxR2 = i % 3 == 0 ? inf : 0.01f + rng.uniform() * 0.5f;
        float time = rng.uniform();
        int c2 = fourD ? t.twoTree.knn4(p, time, k, maxR2, q2) : t.twoTree.knn(p, k, maxR2, q2);
        int c1 = fourD ? t.oneTree.knn4(p, time, k, maxR2, q1) : t.oneTree.knn(p, k, maxR2, q1);
        ++queries;
        if (c2 != c1 || q2.radius2 != q1.radius2 || q2.maxFound2 != q1.maxFound2 ||
            sortedResult(t.two, q2.index(), q2.dist2(), c2) != sortedResult(t.one, q1.index(), q1.dist2(), c1))
          ++differ;
      }
      CAPTURE(fourD);
      CAPTURE(nA);
      CAPTURE(nB);
      CHECK(queries == 400);
      CHECK(differ == 0);
    }
  }
}

TEST_CASE("two-part kd-tree: range queries equal one tree over the union, exactly") {
  for (auto [nA, nB] : {std::pair<size_t, size_t>{4000, 120}, {0, 500}, {2000, 0}}) {
    Pair t;
    makePair(t, nA, nB, 5 + nA, {});
    Rng rng(3);
    RangeQuery r2, r1;
    int differ = 0, nonEmpty = 0;
    for (int i = 0; i < 300; ++i) {
      Vec3f p{rng.uniform() * 4.0f - 2.0f, rng.uniform() * 0.2f, rng.uniform() * 4.0f - 2.0f};
      float rad2 = 0.001f + rng.uniform() * 0.2f;
      int c2 = t.twoTree.range(p, rad2, r2), c1 = t.oneTree.range(p, rad2, r1);
      nonEmpty += int(c1 > 0);
      if (c2 != c1 || sortedResult(t.two, r2.index(), r2.dist2(), c2) != sortedResult(t.one, r1.index(), r1.dist2(), c1))
        ++differ;
    }
    CAPTURE(nA);
    CHECK(nonEmpty > 100);
    CHECK(differ == 0);
  }
}
