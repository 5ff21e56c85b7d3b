// tests/test_sampler.cpp — sampling/sobol.h and sampling/sampler.h: the
// plain Sobol points against published values, net properties of the plain
// and the scrambled points, uniformity of the scramble, determinism, the
// dimension layout, sample indices that continue across adaptive batches,
// and adaptive sampling that stays unbiased on a caustic through glass.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <vector>

#include "render/renderer.h"
#include "sampling/sampler.h"
#include "sampling/sobol.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

double toDouble(uint32_t v) { return double(v) * 0x1p-32; }

// (t,m,2)-net: every elementary interval
// [a/2^k, (a+1)/2^k) x [b/2^(m-t-k), (b+1)/2^(m-t-k)) holds exactly 2^t of
// the 2^m points.
bool isNet(const std::vector<Vec2f>& pts, int m, int t = 0) {
  size_t n = size_t(1) << m;
  if (pts.size() != n) return false;
  int q = m - t;
  for (int k = 0; k <= q; ++k) {
    std::vector<int> count(size_t(1) << q, 0);
    for (const Vec2f& p : pts) {
      size_t a = size_t(double(p.x) * double(1u << k));
      size_t b = size_t(double(p.y) * double(1u << (q - k)));
      if (a >= (size_t(1) << k) || b >= (size_t(1) << (q - k))) return false;
      ++count[a * (size_t(1) << (q - k)) + b];
    }
    for (int c : count)
      if (c != (1 << t)) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("sobol: the first points are the published unscrambled sequence") {
  // Joe-Kuo's sequence in the Gray-code order of their generator (and of
  // scipy.stats.qmc.Sobol(d=3, scramble=False)): point g(i) = i ^ (i >> 1).
  const double expected[8][3] = {{0, 0, 0},         {0.5, 0.5, 0.5},     {0.75, 0.25, 0.25},   {0.25, 0.75, 0.75},
                                 {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125}, {0.625, 0.125, 0.875}, {0.125, 0.625, 0.375}};
  for (uint32_t i = 0; i < 8; ++i)
    for (int d = 0; d < 3; ++d) {
      CAPTURE(i);
      CAPTURE(d);
      CHECK(toDouble(sobolBits(i ^ (i >> 1), d)) == expected[i][d]);
    }
  // Direction numbers: v_k of dimension 1 (x + 1) are the rows of Pascal's
  // triangle mod 2: 1, 11, 101, 1111 as binary fractions.
  CHECK(sobolMatrix(1)[0] == 0x80000000u);
  CHECK(sobolMatrix(1)[1] == 0xC0000000u);
  CHECK(sobolMatrix(1)[2] == 0xA0000000u);
  CHECK(sobolMatrix(1)[3] == 0xF0000000u);
  // Column k (index bit k) reaches down to digit k + 1 exactly (the
  // generator matrix is upper triangular with a unit diagonal).
  for (int d = 0; d < kSobolDims; ++d)
    for (int k = 0; k < 32; ++k) CHECK((sobolMatrix(d)[k] << k) == 0x80000000u);
}

TEST_CASE("sobol: the first 2^m points of every pair of dimensions form a (0,m,2)-net") {
  // Dimensions 0 and 1 are a (0,2)-sequence; dimension 2 makes a t = 1
  // pair with either (x^2 + x + 1 against x and x + 1).
  for (int d0 = 0; d0 < kSobolDims; ++d0)
    for (int d1 = d0 + 1; d1 < kSobolDims; ++d1)
      for (int m = 1; m <= 10; ++m) {
        int t = d1 == 2 ? 1 : 0;
        for (uint32_t block = 0; block < 2; ++block) {
          std::vector<Vec2f> pts;
          for (uint32_t i = block << m; i < (block + 1) << m; ++i)
            pts.push_back({float(toDouble(sobolBits(i, d0))), float(toDouble(sobolBits(i, d1)))});
          CAPTURE(d0);
          CAPTURE(d1);
          CAPTURE(m);
          CHECK(isNet(pts, m, t));
        }
      }
}

TEST_CASE("sobol: scrambled and shuffled points stay nets, in the first block and the ones after it") {
  // What the padded sampler hands out: every group's 2D points over sample
  // indices [j 2^m, (j+1) 2^m) are a (0,m,2)-net, so a pixel that takes
  // more batches keeps extending a stratified set.
  for (uint64_t pixel : {0ull, 7ull, 12345ull})
    for (uint64_t group : {uint64_t(dims::kCameraGroup), dims::vertexGroup(0, dims::kBsdf), dims::vertexGroup(5, dims::kLightPosition, 2)})
      for (int m : {4, 8}) {
        for (uint32_t block = 0; block < 3; ++block) {
          std::vector<Vec2f> pts, pts3xz;
          for (uint32_t i = 0; i < (1u << m); ++i) {
            SobolStream s{hashCombine(99, pixel), block * (1u << m) + i};
            pts.push_back(s.get2D(group));
            Vec3f p3 = s.get3D(group);
            pts3xz.push_back({p3.x, p3.z});
          }
          CAPTURE(pixel);
          CAPTURE(group);
          CAPTURE(m);
          CAPTURE(block);
          CHECK(isNet(pts, m));
          CHECK(isNet(pts3xz, m, 1));
        }
      }
}

TEST_CASE("sobol: the scramble makes one sample uniform over pixels, and groups independent") {
  // Sample 0 of a plain Sobol sequence is the origin; scrambled, its value
  // over 8192 pixels must be uniform (chi-square over 32 bins) and two
  // groups' values uncorrelated.
  const int n = 8192, bins = 32;
  std::vector<int> hist(bins, 0);
  double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
  for (int p = 0; p < n; ++p) {
    SobolStream s{hashCombine(5, uint64_t(p)), 0};
    float a = s.get1D(dims::vertexGroup(1, dims::kRoulette));
    float b = s.get1D(dims::vertexGroup(2, dims::kRoulette));
    CHECK(a >= 0.0f);
    CHECK(a < 1.0f);
    ++hist[size_t(a * bins)];
    sx += a; sy += b; sxx += a * a; syy += b * b; sxy += a * b;
  }
  double chi2 = 0, e = double(n) / bins;
  for (int h : hist) chi2 += (h - e) * (h - e) / e;
  // 31 degrees of freedom: P(chi2 > 61) ~ 1e-3.
  CHECK(chi2 < 61.0);
  double cov = sxy / n - (sx / n) * (sy / n);
  double corr = cov / std::sqrt((sxx / n - (sx / n) * (sx / n)) * (syy / n - (sy / n) * (sy / n)));
  // Independent: corr ~ N(0, 1/sqrt(n)) = 0.011; 4 sigma.
  CHECK(std::fabs(corr) < 0.045);
}

TEST_CASE("sampler: deterministic, and the dimension layout gives every draw its own group") {
  SobolStream a{hashCombine(1, 42), 17}, b{hashCombine(1, 42), 17};
  CHECK(a.get2D(dims::vertexGroup(3, dims::kBsdf)).x == b.get2D(dims::vertexGroup(3, dims::kBsdf)).x);
  CHECK(a.get3D(dims::kCameraGroup).z == b.get3D(dims::kCameraGroup).z);
  std::set<uint64_t> ids;
  size_t count = 0;
  for (uint64_t g : {dims::kCameraGroup, dims::kPhotonLight, dims::kPhotonPosition, dims::kPhotonDirection, dims::kPhotonTime}) {
    ids.insert(g);
    ++count;
  }
  for (int v = 0; v < 1024; ++v)
    for (uint32_t slot = 0; slot < dims::kSlotsPerVertex; ++slot)
      for (uint32_t sub = 0; sub < 4; ++sub) {
        uint64_t g = dims::vertexGroup(v, dims::Slot(slot), sub);
        CHECK(uint32_t(g) >= dims::kFirstVertexGroup);
        ids.insert(g);
        ++count;
      }
  CHECK(ids.size() == count);
  // The random kind at sample 0 is the old per-pixel stream: a Latin
  // hypercube batch from Rng(hashCombine(seed, pixel)), so --sampler random
  // renders the images it always did.
  RandomPixelSampler rp(3, 77);
  rp.startBatch(0, 8);
  Rng old(hashCombine(3, 77), 0);
  std::vector<CameraSample> cs(8);
  std::vector<uint32_t> scratch;
  stratifiedCameraSamples(8, old, cs.data(), scratch);
  for (uint32_t i = 0; i < 8; ++i) {
    CHECK(rp.camera(i).pixelOffset.x == cs[i].pixelOffset.x);
    CHECK(rp.camera(i).time01 == cs[i].time01);
  }
  CHECK(rp.stream(0).get1D(0) == old.uniform());
  std::string name = "sobol";
  SamplerKind k = SamplerKind::Random;
  CHECK(parseSamplerKind(name, k));
  CHECK(k == SamplerKind::Sobol);
  CHECK_FALSE(parseSamplerKind("halton", k));
}

namespace {

scene::SceneDescription cubeCaustic(int w, int h, float lightScale = 1.0f) {
  auto d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json");
  d.camera.width = w;
  d.camera.height = h;
  d.lights[0].areaSize = {d.lights[0].areaSize.x * lightScale, d.lights[0].areaSize.y * lightScale};
  return d;
}

double imageMean(const Film& f) {
  double s = 0;
  for (const Rgb& c : f.color) s += c.luminance();
  return s / double(f.color.size());
}

// Standard error of the image mean from the per-pixel variance layer.
double imageMeanError(const Film& f) {
  double v = 0;
  for (const Rgb& c : f.varianceOfMean) v += c.luminance();  // luminance weights are >= 0; a bound
  return std::sqrt(v) / double(f.color.size());
}

}  // namespace

TEST_CASE("sampler: a pixel's sample indices continue across adaptive batches") {
  // Two batches of 8 take Sobol indices 0..15, the same samples as one
  // batch of 16, added in the same order: bit-identical images.
  auto s = Scene::build(cubeCaustic(12, 9));
  RenderOptions one, two;
  one.method = two.method = RenderMethod::PathTrace;
  one.spp = 16;
  one.maxSpp = 16;
  two.spp = 8;
  two.maxSpp = 16;
  two.contrast = 1e-9f;
  RenderStats st;
  Film a = render(*s, one, Progress{}, st);
  Film b = render(*s, two, Progress{}, st);
  CHECK(std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Rgb)) == 0);
}

TEST_CASE("sampler: sobol and random agree in mean, and sobol's error is smaller on the cube caustic") {
  auto s = Scene::build(cubeCaustic(40, 30));
  RenderOptions o;
  o.method = RenderMethod::PathTrace;
  o.spp = o.maxSpp = 256;
  RenderStats st;
  o.sampler = SamplerKind::Sobol;
  Film sobol = render(*s, o, Progress{}, st);
  o.sampler = SamplerKind::Random;
  o.seed = 2;
  Film random = render(*s, o, Progress{}, st);
  double ms = imageMean(sobol), mr = imageMean(random);
  double sigma = std::hypot(imageMeanError(sobol), imageMeanError(random));
  MESSAGE("image mean sobol " << ms << ", random " << mr << ", sigma of the difference " << sigma);
  CHECK(std::fabs(ms - mr) < 4 * sigma);
}

TEST_CASE("adaptive sampling: unbiased on a caustic through glass, and cheaper on smooth regions") {
  // The cube-caustic scene (glass ball, area light) at 40x30, with the
  // light 5x wider (0.75 m) so that 512 spp give an image mean precise to
  // a fraction of 1%: the caustic on the box is still carried by rare
  // paths (floor -> ball -> light). The old rule (stop when a
  // pixel's own luminance contrast is low) left pixels that had not met
  // them dark: the image mean was 8% low. Adaptive must agree with the
  // non-adaptive image within 1% and within 4 sigma of their difference.
  auto s = Scene::build(cubeCaustic(40, 30, 5.0f));
  RenderOptions full;
  full.method = RenderMethod::PathTrace;
  full.spp = full.maxSpp = 512;
  full.seed = 11;
  RenderStats stFull, stAd;
  Film ref = render(*s, full, Progress{}, stFull);
  RenderOptions ad = full;
  ad.spp = 16;
  ad.maxSpp = 1024;
  ad.contrast = 0.1f;
  ad.seed = full.seed;  // shared first samples: the difference is what adaptive changed
  Film img = render(*s, ad, Progress{}, stAd);
  double mRef = imageMean(ref), mAd = imageMean(img);
  double sigma = std::hypot(imageMeanError(ref), imageMeanError(img));
  MESSAGE("image mean non-adaptive " << mRef << ", adaptive " << mAd << " (" << (mAd / mRef - 1) * 100
                                     << "%), sigma " << sigma << "; samples " << stFull.cameraSamples << " vs "
                                     << stAd.cameraSamples << " (" << stAd.minSpp << ".." << stAd.maxSpp << " spp)");
  CHECK(std::fabs(mAd - mRef) < 0.01 * mRef);
  CHECK(std::fabs(mAd - mRef) < 4 * sigma);
  CHECK(stAd.cameraSamples < stFull.cameraSamples);
  CHECK(stAd.minSpp == kAdaptiveMinSamples);
  CHECK(stAd.maxSpp > 512);
}
