// tests/test_caustic_guide.cpp — the path tracer's caustic guide
// (render/caustic_guide.h, render/guided_sampling.h): the guided mixture
// is unbiased (guided and unguided images agree in mean within their
// statistical error), it removes most of the variance of a small lamp's
// caustic through a glass ball, its density is the one it samples by, and
// guided images are bit-identical for any thread count.
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "core/rng.h"
#include "math/frame.h"
#include "render/caustic_guide.h"
#include "render/guide_occupancy.h"
#include "render/guided_sampling.h"
#include "render/renderer.h"
#include "scene/parse.h"
#include "sampling/warp.h"

using namespace tdpm;

namespace {

scene::SceneDescription cubeCaustic(int w, int h, float lightScale) {
  auto d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json");
  d.camera.width = w;
  d.camera.height = h;
  for (auto& l : d.lights) l.areaSize = Vec2f{l.areaSize.x * lightScale, l.areaSize.y * lightScale};
  return d;
}

struct Region {
  int x0, y0, x1, y1;
};

// Mean luminance of a region and the standard error of that mean (from the
// film's per-pixel variance of the mean).
void regionMean(const Film& f, Region r, double& mean, double& error) {
  double s = 0, v = 0;
  int n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      size_t i = size_t(y) * size_t(f.width) + size_t(x);
      s += f.color[i].luminance();
      v += f.varianceOfMean[i].luminance();
      ++n;
    }
  mean = s / n;
  error = std::sqrt(v) / n;
}

// A guide over scene s with the default mixture weight; subdivision < 0:
// the build's own neighbour-cache subdivision.
CausticGuide guideFor(const Scene& s, size_t photons, uint64_t seed, int subdivision = -1) {
  CausticGuideSettings gs;
  gs.fraction = 0.5f;
  gs.photons = photons;
  gs.seed = seed;
  return subdivision < 0 ? CausticGuide::build(s, gs, Progress{}) : CausticGuide::build(s, gs, Progress{}, subdivision);
}

Film renderCube(const Scene& s, float guiding, int spp, uint64_t seed, int threads = 0) {
  RenderOptions o;
  o.method = RenderMethod::PathTrace;
  o.spp = o.maxSpp = spp;
  o.seed = seed;
  o.causticGuiding = guiding;
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  RenderStats st;
  return render(s, o, Progress{}, st);
}

}  // namespace

TEST_CASE("caustic guide: the mixture samples by the density it reports, and estimates a constant radiance exactly") {
  // A diffuse vertex with two overlapping sub-degree cones and a third
  // apart: every sample's reported density must be the mixture's density
  // of its direction, every guided direction must lie in a cone (the rim
  // test: judged outside, its density would be far too small), and the
  // estimate f cos / p of a constant unit radiance must average to the
  // albedo (the BSDF's integral), which fails if a cone's cap is sampled
  // non-uniformly or the mixture's weights are off.
  Material m;
  m.type = Material::Type::Diffuse;
  ShadingContext ctx = makeShadingContext(m, Rgb(0.5f), Vec3f{0, 1, 0}, normalize(Vec3f{0.3f, 1, 0.1f}));
  GuideCones cones;
  Vec3f axes[3] = {normalize(Vec3f{0.2f, 1, 0}), normalize(Vec3f{0.205f, 1, 0.004f}), normalize(Vec3f{-0.5f, 0.3f, 0.4f})};
  float half = 0.01f;  // 0.57 degrees
  float omc = 2.0f * std::sin(0.5f * half) * std::sin(0.5f * half);
  for (Vec3f a : axes) cones.cone[size_t(cones.count++)] = {a, omc, 2.0f * kPi * omc};
  cones.totalSolidAngle = 3.0f * 2.0f * kPi * omc;
  cones.fraction = 0.5f;

  Rng rng(5);
  const int n = 400000;
  double sum = 0;
  int inOwnCone = 0, guided = 0, densityMismatch = 0;
  for (int i = 0; i < n; ++i) {
    float uLobe = rng.uniform();
    BsdfSample bs;
    if (!guidedBsdfSample(ctx, cones, {rng.uniform(), rng.uniform()}, uLobe, bs)) continue;
    sum += bs.weight.g;
    densityMismatch += std::fabs(bs.pdf - cones.pdf(bsdfPdf(ctx, bs.wi), bs.wi)) > 1e-6f * bs.pdf;
    if (uLobe < cones.fraction) {
      ++guided;
      bool any = false;
      for (int c = 0; c < cones.count; ++c) any = any || cones.cone[size_t(c)].holds(bs.wi);
      inOwnCone += any;
    }
  }
  MESSAGE("mean weight " << sum / n << " (albedo 0.5), guided samples in a cone " << inOwnCone << " of " << guided);
  CHECK(densityMismatch == 0);
  CHECK(inOwnCone == guided);
  CHECK(std::fabs(sum / n - 0.5) < 0.005);  // ~5 standard errors
}

TEST_CASE("caustic guide: a cleared occupancy bit means fewer than m points within the radius, exactly") {
  // Points as a guide's photons lie: a dense disc on a floor, a sparse
  // scatter over a wall, and a few far away. Queries: random points in the
  // box around them, and points just inside the radius of a point (the
  // rim, where rounding decides). Wherever the grid says "no", counting
  // the points strictly within r, with the k-NN's own float arithmetic,
  // must find fewer than m; and the grid must say "no" for most of the
  // empty space, or it saves nothing.
  Rng rng(17);
  std::vector<Vec3f> pts;
  for (int i = 0; i < 3000; ++i) {
    float a = 2.0f * kPi * rng.uniform(), rr = 0.4f * std::sqrt(rng.uniform());
    pts.push_back({0.3f + rr * std::cos(a), 0.0f, -0.2f + rr * std::sin(a)});
  }
  for (int i = 0; i < 300; ++i) pts.push_back({-3.0f + 6.0f * rng.uniform(), 5.0f * rng.uniform(), -2.5f});
  pts.push_back({4.0f, 3.0f, 4.0f});
  pts.push_back({4.05f, 3.0f, 4.0f});
  const float r = 0.1f;
  auto within = [&](Vec3f q) {
    int n = 0;
    for (Vec3f p : pts) {
      float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
      n += dx * dx + dy * dy + dz * dz < r * r;
    }
    return n;
  };
  for (int m : {1, 2}) {
    GuideOccupancy g = GuideOccupancy::build(pts, r, m);
    REQUIRE(g.built());
    int wrong = 0, no = 0, emptyNo = 0, empty = 0;
    for (int i = 0; i < 20000; ++i) {
      Vec3f q;
      if (i % 2 == 0) {
        q = {-5.0f + 10.0f * rng.uniform(), -0.5f + 6.0f * rng.uniform(), -3.0f + 8.0f * rng.uniform()};
      } else {  // within r of a point, at 0.999-0.99999 of r
        Vec3f p = pts[size_t(rng.uniform() * float(pts.size())) % pts.size()];
        Vec3f d = normalize(Vec3f{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
        q = p + d * (r * (1.0f - std::pow(10.0f, -3.0f - 2.0f * rng.uniform())));
      }
      int n = within(q);
      bool maybe = g.mayHaveNear(q);
      wrong += !maybe && n >= m;
      no += !maybe;
      if (n == 0) {
        ++empty;
        emptyNo += !maybe;
      }
    }
    MESSAGE("m " << m << ": grid says no for " << no << " queries, " << emptyNo << " of " << empty
                 << " with no point near; set cells " << g.setCount() << " of " << g.cellCount());
    CHECK(wrong == 0);
    CHECK(emptyNo > 0.9 * empty);
  }
  // Coarser cells when the bounds would need too many: still exact.
  GuideOccupancy coarse = GuideOccupancy::build(pts, r, 2, 1000);
  CHECK(coarse.cellCount() <= 1000);
  int wrong = 0;
  for (int i = 0; i < 2000; ++i) {
    Vec3f p = pts[size_t(i) % pts.size()];
    wrong += !coarse.mayHaveNear(p + Vec3f{0.03f, 0.0f, 0.02f}) && within(p + Vec3f{0.03f, 0.0f, 0.02f}) >= 2;
  }
  CHECK(wrong == 0);
  // Nothing to build from: always "maybe".
  CHECK(GuideOccupancy::build({}, r, 2).mayHaveNear({0, 0, 0}));
}

// Follows direction w from p through mirrors and glass (always refracting
// unless the reflection is total) and says whether it reaches an area light.
bool reachesLampThroughGlass(const Scene& s, Vec3f p, Vec3f n, Vec3f w, float time01) {
  Vec3f o = s.spawnOrigin(p, n, w), d = w;
  for (int bounce = 0; bounce < 8; ++bounce) {
    Hit hit;
    if (!s.intersect(o, d, std::numeric_limits<float>::infinity(), time01, hit)) return false;
    if (hit.isLight()) return bounce > 0;  // through glass, not seen directly
    const Material& m = s.materials[s.objects[hit.object].material];
    if (!m.isDeltaOnly()) return false;
    ShadingContext ctx = makeShadingContext(m, Rgb(1.0f), hit.n, -d);
    BsdfSample bs;
    if (!bsdfSample(ctx, {0.5f, 0.5f}, 0.99999f, Transport::Radiance, bs)) return false;
    o = s.spawnOrigin(hit.p, hit.n, bs.wi);
    d = bs.wi;
  }
  return false;
}

TEST_CASE("caustic guide: in the ball's faint halo on the floor, the cones hold the directions that reach the lamp") {
  // The guide only pays where its cones cover the lamp's image through the
  // ball: a caustic path outside every cone is found by the BSDF half alone
  // and weighs 1/(1 - c) (the fireflies that made cube-caustic's relMSE).
  // Cones only as wide as the spacing of neighbouring photons' directions
  // left gaps in the ~1-degree image (82-90% covered for guide seeds 1-3);
  // cones as wide as the spread of the vertex's own photons' directions
  // cover it (97-99.5%). Counted over directions near the cones, from
  // floor points around the box, each followed through the glass.
  auto s = Scene::build(cubeCaustic(40, 30, 1.0f));
  CausticGuide guide = guideFor(*s, 50000, 3);
  REQUIRE(guide.enabled());
  Material diffuse;
  diffuse.type = Material::Type::Diffuse;
  Rng rng(3);
  const Vec3f n{0, 1, 0};
  int lamp = 0, covered = 0, guidedPoints = 0, points = 0;
  for (int i = 0; i < 24; ++i) {
    // The floor around the box at time 0.9 (the box low, its shadow small):
    // the ball's faint halo, where the guide's photons are sparse.
    float a = 2.0f * kPi * float(i) / 24.0f;
    Vec3f p{0.9f * std::cos(a), 0.0f, 0.9f * std::sin(a)};
    GuideCones cones;
    guide.conesAt(diffuse, p, n, cones);
    ++points;
    if (!cones.active()) continue;
    ++guidedPoints;
    // Directions uniform within 6 degrees of the cones' mean axis: they
    // hold the lamp's ~1-degree image wherever the cones are roughly right.
    Vec3f mean(0.0f);
    for (int c = 0; c < cones.count; ++c) mean += cones.cone[size_t(c)].axis;
    Frame f(normalize(mean));
    const float capOneMinusCos = 1.0f - std::cos(6.0f * kPi / 180.0f);
    for (int k = 0; k < 4000; ++k) {
      float h = rng.uniform() * capOneMinusCos, phi = 2.0f * kPi * rng.uniform();
      float sinT = std::sqrt(h * (2.0f - h));
      Vec3f w = f.toWorld({sinT * std::cos(phi), sinT * std::sin(phi), 1.0f - h});
      if (!reachesLampThroughGlass(*s, p, n, w, 0.9f)) continue;
      ++lamp;
      bool in = false;
      for (int c = 0; c < cones.count; ++c) in = in || cones.cone[size_t(c)].holds(w);
      covered += in;
    }
  }
  MESSAGE("points with cones " << guidedPoints << " of " << points << "; directions reaching the lamp " << lamp
                               << ", in a cone " << covered);
  CHECK(guidedPoints >= points / 2);
  REQUIRE(lamp > 200);
  CHECK(covered > 0.9 * lamp);
}

TEST_CASE("caustic guide: its compact k-NN returns what the kd-tree's k-NN returns, bit for bit") {
  // CausticGuide::nearest repeats KdTree::knn's traversal over 16-byte
  // nodes; the cones (and images) depend on the order of the result too.
  auto s = Scene::build(cubeCaustic(40, 30, 1.0f));
  CausticGuide guide = guideFor(*s, 30000, 5);
  REQUIRE(guide.enabled());
  photon::KnnQuery q(CausticGuide::kNeighbours);
  Rng rng(11);
  int differ = 0, full = 0, some = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half near stored photons (dense and sparse places), half anywhere.
    Vec3f p = i % 2 == 0 ? guide.tree().store().position(size_t(rng.uniform() * float(guide.photonCount())) %
                                                         guide.photonCount()) +
                               Vec3f{0.05f * (rng.uniform() - 0.5f), 0.01f * rng.uniform(), 0.05f * (rng.uniform() - 0.5f)}
                         : Vec3f{-3.0f + 6.0f * rng.uniform(), 2.5f * rng.uniform(), -2.5f + 5.0f * rng.uniform()};
    uint32_t index[CausticGuide::kNeighbours + 1];
    float d2[CausticGuide::kNeighbours + 1];
    int a = guide.nearest(p, index, d2);
    int b = guide.tree().knn(p, CausticGuide::kNeighbours, guide.radius() * guide.radius(), q);
    bool same = a == b;
    for (int j = 0; same && j < a; ++j)
      same = index[j] == q.index()[j] && std::memcmp(&d2[j], &q.dist2()[j], sizeof(float)) == 0;
    differ += !same;
    full += a == CausticGuide::kNeighbours;
    some += a > 0 && a < CausticGuide::kNeighbours;
  }
  MESSAGE("queries with all 8 found " << full << ", with 1-7 " << some << "; differing " << differ);
  CHECK(differ == 0);
  CHECK(full > 2000);
  CHECK(some > 500);
}

TEST_CASE("caustic guide: the neighbour cache gives a vertex only photons within its radius, from one list per sub-cell") {
  // conesAt takes a vertex's photons from its occupancy sub-cell's cached
  // list (the 8 nearest to the sub-cell's centre), kept when within the
  // radius of the vertex itself. Checked against the per-vertex k-NN of a
  // guide without the cache (same photons): every candidate is within the
  // radius at its true distance, none twice, and where the vertex has fewer
  // than 8 photons within the radius the candidates are a subset of them
  // (most often all of them); and two points of one sub-cell draw on one
  // list: each one's candidates within the other's radius are the same, in
  // the same order (a cache filled by whichever vertex came first fails it).
  auto s = Scene::build(cubeCaustic(40, 30, 1.0f));
  CausticGuide cached = guideFor(*s, 30000, 5);
  CausticGuide plain = guideFor(*s, 30000, 5, 0);
  REQUIRE(cached.enabled());
  REQUIRE(cached.cacheSubdivision() >= 1);
  REQUIRE(plain.cacheSubdivision() == 0);
  REQUIRE(cached.photonCount() == plain.photonCount());
  const float r2 = cached.radius() * cached.radius();
  const float step = cached.occupancy().cellSize() / float(cached.cacheSubdivision());
  auto positionOf = [&](uint32_t i) { return cached.tree().store().position(i); };
  auto subCell = [&](Vec3f p, size_t& rank, int& sub) {
    Vec3f local;
    if (!cached.occupancy().locate(p, rank, local)) return false;
    int n = cached.cacheSubdivision();
    sub = (std::min(n - 1, int(local.z * float(n))) * n + std::min(n - 1, int(local.y * float(n)))) * n +
          std::min(n - 1, int(local.x * float(n)));
    return true;
  };
  Rng rng(13);
  int bad = 0, notSubset = 0, sparse = 0, sparseEqual = 0, pairs = 0, pairsDiffer = 0, nonEmpty = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3f p = i % 2 == 0 ? positionOf(uint32_t(size_t(rng.uniform() * float(cached.photonCount())) % cached.photonCount())) +
                               Vec3f{0.05f * (rng.uniform() - 0.5f), 0.01f * rng.uniform(), 0.05f * (rng.uniform() - 0.5f)}
                         : Vec3f{-3.0f + 6.0f * rng.uniform(), 2.5f * rng.uniform(), -2.5f + 5.0f * rng.uniform()};
    uint32_t a[CausticGuide::kNeighbours + 1], b[CausticGuide::kNeighbours + 1];
    float da[CausticGuide::kNeighbours + 1], db[CausticGuide::kNeighbours + 1];
    int na = cached.candidates(p, a, da);
    for (int j = 0; j < na; ++j) a[j] = cached.treeIndexOfRecord(a[j]);
    nonEmpty += na > 0;
    for (int j = 0; j < na; ++j) {
      Vec3f d = positionOf(a[j]) - p;
      bool ok = da[j] < r2 && std::fabs(da[j] - lengthSquared(d)) <= 1e-6f * r2;
      for (int k = 0; k < j; ++k) ok = ok && a[k] != a[j];
      bad += !ok;
    }
    int nb = plain.nearest(p, b, db);
    if (nb < CausticGuide::kNeighbours) {  // b holds every photon within the radius
      ++sparse;
      bool subset = true;
      for (int j = 0; j < na; ++j) {
        bool in = false;
        for (int k = 0; k < nb; ++k) in = in || a[j] == b[k];
        subset = subset && in;
      }
      notSubset += !subset;
      sparseEqual += subset && na == nb;
    }
    // A second point of the same sub-cell.
    Vec3f q = p + Vec3f{0.3f * step * (rng.uniform() - 0.5f), 0.3f * step * (rng.uniform() - 0.5f),
                        0.3f * step * (rng.uniform() - 0.5f)};
    size_t rp, rq;
    int sp, sq;
    if (!subCell(p, rp, sp) || !subCell(q, rq, sq) || rp != rq || sp != sq) continue;
    int nq = cached.candidates(q, b, db);
    for (int j = 0; j < nq; ++j) b[j] = cached.treeIndexOfRecord(b[j]);
    std::vector<uint32_t> fromP, fromQ;
    for (int j = 0; j < na; ++j)
      if (lengthSquared(positionOf(a[j]) - q) < r2) fromP.push_back(a[j]);
    for (int j = 0; j < nq; ++j)
      if (lengthSquared(positionOf(b[j]) - p) < r2) fromQ.push_back(b[j]);
    ++pairs;
    pairsDiffer += fromP != fromQ;
  }
  MESSAGE("cache: " << cached.cacheEntries() << " sub-cells, " << cached.cacheBytes() << " bytes; points with candidates "
                    << nonEmpty << ", with < 8 within the radius " << sparse << " (candidates all of them: " << sparseEqual
                    << "), same-sub-cell pairs " << pairs);
  CHECK(bad == 0);
  CHECK(notSubset == 0);
  CHECK(nonEmpty > 5000);
  CHECK(sparse > 500);
  CHECK(sparseEqual > sparse / 2);
  CHECK(pairs > 5000);
  CHECK(pairsDiffer == 0);
}

TEST_CASE("caustic guide: the neighbour cache's lists, filled at first use, do not depend on who asks first") {
  // A sub-cell's list is filled by the first vertex that lands in it, from
  // the sub-cell's centre: two identical guides asked at the same points in
  // opposite orders (so different vertices fill each list) give every point
  // the same candidates, and the cache fills only the sub-cells asked for.
  auto s = Scene::build(cubeCaustic(40, 30, 1.0f));
  CausticGuide a = guideFor(*s, 30000, 9);
  CausticGuide b = guideFor(*s, 30000, 9);
  REQUIRE(a.enabled());
  REQUIRE(a.cacheEntries() > 0);
  CHECK(a.cacheFilled() == 0);
  Rng rng(21);
  std::vector<Vec3f> points(20000);
  for (Vec3f& p : points)
    p = a.tree().store().position(size_t(rng.uniform() * float(a.photonCount())) % a.photonCount()) +
        Vec3f{0.2f * (rng.uniform() - 0.5f), 0.02f * rng.uniform(), 0.2f * (rng.uniform() - 0.5f)};
  constexpr int K = CausticGuide::kNeighbours;
  std::vector<uint32_t> fromA(points.size() * K, ~0u), fromB(points.size() * K, ~0u);
  std::vector<int> countA(points.size()), countB(points.size());
  float d2[K + 1];
  for (size_t i = 0; i < points.size(); ++i) countA[i] = a.candidates(points[i], &fromA[i * K], d2);
  for (size_t i = points.size(); i-- > 0;) countB[i] = b.candidates(points[i], &fromB[i * K], d2);
  int differ = 0, withCandidates = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    withCandidates += countA[i] > 0;
    differ += countA[i] != countB[i] ||
              !std::equal(fromA.begin() + long(i * K), fromA.begin() + long(i * K + size_t(countA[i])), fromB.begin() + long(i * K));
  }
  MESSAGE("points with candidates " << withCandidates << " of " << points.size() << "; sub-cells filled " << a.cacheFilled()
                                    << " of " << a.cacheEntries());
  CHECK(differ == 0);
  CHECK(withCandidates > 5000);
  CHECK(a.cacheFilled() == b.cacheFilled());
  CHECK(a.cacheFilled() > 0);
  CHECK(a.cacheFilled() <= points.size());
}

TEST_CASE("caustic guide: guided and unguided path tracing agree in mean, on the image and on the caustic") {
  // The cube scene with its lamp 5x wider, so that the unguided image's
  // mean is precise to about 1% (the box region's to about 4%) at 512 spp.
  // A guide that missed part of the caustic, or counted it twice, would
  // show on the box (or, at the second diffuse vertex, on the wall); the
  // vertex-level test above checks exactness to 1%.
  auto s = Scene::build(cubeCaustic(40, 30, 5.0f));
  Film plain = renderCube(*s, 0.0f, 512, 11);
  Film guided = renderCube(*s, 0.5f, 512, 12);
  // The back wall (top rows) is lit by the caustic on the box top: its
  // caustic paths are guided at their second diffuse vertex.
  for (Region r : {Region{0, 0, 40, 30}, Region{15, 12, 25, 23}, Region{0, 0, 40, 8}}) {
    double m0, e0, m1, e1;
    regionMean(plain, r, m0, e0);
    regionMean(guided, r, m1, e1);
    double sigma = std::hypot(e0, e1);
    MESSAGE("region " << r.x0 << "," << r.y0 << ".." << r.x1 << "," << r.y1 << ": unguided " << m0 << " +- " << e0
                      << ", guided " << m1 << " +- " << e1 << " (" << (m1 / m0 - 1) * 100 << "%)");
    CHECK(std::fabs(m1 - m0) < 4 * sigma);
    CHECK(sigma < 0.06 * m0);  // the bound means something: 4 sigma is under a quarter of the value
  }
}

TEST_CASE("caustic guide: a small lamp's caustic through the ball loses most of its variance") {
  // The scene's own 0.15 m lamp: seen from the box top through the ball it
  // is an image about a degree across, which cosine sampling rarely hits.
  auto s = Scene::build(cubeCaustic(80, 60, 1.0f));
  Film plain = renderCube(*s, 0.0f, 64, 21);
  Film guided = renderCube(*s, 0.5f, 64, 21);
  Region box{30, 24, 50, 46};  // the box under the ball (its lit top and front)
  double m0, e0, m1, e1;
  regionMean(plain, box, m0, e0);
  regionMean(guided, box, m1, e1);
  MESSAGE("box region: unguided " << m0 << " +- " << e0 << ", guided " << m1 << " +- " << e1);
  CHECK(e1 < 0.5 * e0);
  CHECK(std::fabs(m1 - m0) < 4 * std::hypot(e0, e1));
}

TEST_CASE("caustic guide: guided images are bit-identical on 1 and 2 threads") {
  auto s = Scene::build(cubeCaustic(24, 18, 1.0f));
  Film a = renderCube(*s, 0.5f, 8, 3, 1);
  Film b = renderCube(*s, 0.5f, 8, 3, 2);
  REQUIRE(a.color.size() == b.color.size());
  CHECK(std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Rgb)) == 0);
}
