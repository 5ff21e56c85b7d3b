// tests/test_caustic_variance.cpp — the variance of the fixed-budget
// two-pass `time` estimate on a point-lit caustic that a moving box carries
// through the focus of a glass ball (tests/data/caustic-point-moving-box.json),
// against the frozen-time reference of frozen_time_reference.h (a different
// method). Also a study case, skipped by default, that prints the numbers of
// docs/photon-map.md's section on the estimate's variance.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "frozen_time_reference.h"
#include "image/image.h"
#include "image/pfm.h"
#include "core/rng.h"
#include "render/photon_map.h"
#include "scene/parse.h"

using namespace tdpm;

namespace {

const char* const kScene = "/tests/data/caustic-point-moving-box.json";

scene::SceneDescription causticScene(int width, int height) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + kScene);
  d.camera.width = width;
  d.camera.height = height;
  // STUDY_LIGHT=area: the same scene under a small area light (0.25 x 0.25,
  // same place and power) instead of the point light (studies only).
  const char* light = std::getenv("STUDY_LIGHT");
  if (light && std::string(light) == "area") {
    scene::LightDesc& l = d.lights.at(0);
    l.type = scene::LightDesc::Type::Area;
    l.areaSize = {0.25f, 0.25f};
    l.placement.translate = l.position;
    l.position = {0, 0, 0};
  }
  return d;
}

// Caustic map only: no global map, no final gather, so the images are the
// direct light (the same computation in both methods) plus the caustic.
RenderOptions causticOptions(const std::string& method, size_t photons, int spp, uint64_t seed) {
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.spp = spp;
  o.seed = seed;
  o.causticPhotons = photons;
  o.globalPhotons = 0;
  o.gatherRays = 0;
  return o;
}

std::vector<Rgb> renderColors(const scene::SceneDescription& d, const RenderOptions& o) {
  auto scene = Scene::build(d);
  RenderStats st;
  return render(*scene, o, Progress{}, st).color;
}

// The caustic region: pixels where the reference's caustic (reference minus
// the direct light alone) is above `fraction` of its peak.
std::vector<char> causticMask(const std::vector<Rgb>& ref, const std::vector<Rgb>& direct, double fraction) {
  double peak = 0;
  for (size_t i = 0; i < ref.size(); ++i) peak = std::max(peak, test::luminance(ref[i]) - test::luminance(direct[i]));
  std::vector<char> mask(ref.size());
  for (size_t i = 0; i < ref.size(); ++i)
    mask[i] = test::luminance(ref[i]) - test::luminance(direct[i]) > fraction * peak;
  return mask;
}

int envInt(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : fallback;
}
double envDouble(const char* name, double fallback) {
  const char* v = std::getenv(name);
  return v ? std::atof(v) : fallback;
}

void writeColors(const std::string& path, const std::vector<Rgb>& c, int w, int h) {
  image::ImageRgb img(w, h);
  img.pixels = c;
  image::writePfm(path, img);
}

}  // namespace

// Measurement, not a check: `tdpm_tests -tc='study: caustic*' --no-skip`,
// parameters from the environment (defaults in brackets): STUDY_W/H [96x64],
// REF_PHOTONS [400000] REF_INSTANTS [32] REF_SPP [16], STUDY_PHOTONS
// [200000] STUDY_SPP [16] STUDY_SEEDS [3] STUDY_K [100] STUDY_FRACTION
// [0.5] STUDY_METHOD [time], STUDY_OUT (a directory for PFMs of the
// reference, its halves and the renders). The reference is cached in
// STUDY_OUT/ref*.pfm when STUDY_OUT is set.
TEST_CASE("study: caustic variance of the time estimate against the frozen-time reference" * doctest::skip()) {
  const int w = envInt("STUDY_W", 96), h = envInt("STUDY_H", 64);
  const char* out = std::getenv("STUDY_OUT");
  scene::SceneDescription d = causticScene(w, h);
  test::FrozenReference ref;
  std::vector<Rgb> direct;
  const std::string dir = out ? out : "";
  bool cached = false;
  if (out) {
    FILE* f = std::fopen((dir + "/ref.pfm").c_str(), "rb");
    if (f) {
      std::fclose(f);
      ref.width = w;
      ref.height = h;
      ref.mean = image::readPfm(dir + "/ref.pfm").pixels;
      ref.halfA = image::readPfm(dir + "/refA.pfm").pixels;
      ref.halfB = image::readPfm(dir + "/refB.pfm").pixels;
      direct = image::readPfm(dir + "/direct.pfm").pixels;
      cached = true;
    }
  }
  if (!cached) {
    const int instants = envInt("REF_INSTANTS", 32);
    ref = test::frozenTimeReference(
        d, causticOptions("standard", size_t(envInt("REF_PHOTONS", 400000)), envInt("REF_SPP", 16), 1000), instants);
    direct = renderColors(d, causticOptions("time", 0, 64, 7));
    if (out) {
      writeColors(dir + "/ref.pfm", ref.mean, w, h);
      writeColors(dir + "/refA.pfm", ref.halfA, w, h);
      writeColors(dir + "/refB.pfm", ref.halfB, w, h);
      writeColors(dir + "/direct.pfm", direct, w, h);
    }
  }
  std::vector<char> mask = causticMask(ref.mean, direct, envDouble("STUDY_MASK", 0.05));
  size_t regionPixels = 0;
  for (char m : mask) regionPixels += m;
  test::RegionError halves = test::regionError(ref.halfA, ref.halfB, mask);
  MESSAGE("reference: " << regionPixels << " caustic pixels, peak " << halves.maxReference
                        << "; half A vs half B: caustic region " << halves.regionRelative * 100 << "%, relMSE "
                        << halves.relMse);
  const int seeds = envInt("STUDY_SEEDS", 3);
  const char* method = std::getenv("STUDY_METHOD");
  double sum = 0, sum2 = 0;
  for (int s = 0; s < seeds; ++s) {
    RenderOptions o = causticOptions(method ? method : "time", size_t(envInt("STUDY_PHOTONS", 200000)),
                                     envInt("STUDY_SPP", 16), uint64_t(1 + s));
    o.estimate.k = o.estimate.ks = envInt("STUDY_K", o.estimate.k);
    o.estimate.fraction = float(envDouble("STUDY_FRACTION", o.estimate.fraction));
    o.kernelFootprint = float(envDouble("STUDY_FOOTPRINT", o.kernelFootprint));
    o.estimate.maxGrowth = envInt("STUDY_GROWTH", o.estimate.maxGrowth);
    std::vector<Rgb> img = renderColors(d, o);
    if (out) writeColors(dir + "/render" + std::to_string(s) + ".pfm", img, w, h);
    test::RegionError e = test::regionError(img, ref.mean, mask);
    sum += e.regionRelative;
    sum2 += e.regionRelative * e.regionRelative;
    MESSAGE("seed " << (1 + s) << ": caustic region " << e.regionRelative * 100 << "%, brightest " << e.maxTest
                    << " (reference " << e.maxReference << "), relMSE " << e.relMse);
  }
  double mean = sum / seeds, sd = std::sqrt(std::max(0.0, sum2 / seeds - mean * mean) * seeds / std::max(1, seeds - 1));
  MESSAGE("caustic region over " << seeds << " seeds: mean " << mean * 100 << "%, sd " << sd * 100 << "%");
  CHECK(std::abs(halves.regionRelative) < 0.05);  // the reference's own noise is small
}

// Diagnosis, not a check: `tdpm_tests -tc='study: where*' --no-skip`. Builds
// STUDY_MAPS [16] independent caustic maps of STUDY_PHOTONS [200000] and
// evaluates the two-pass estimate at the same space-time points of the box
// top (a grid around the ball's axis, at several times) in each map: an
// estimate far above the same point's mean over the maps is noise of the
// photon map, not of the eye samples. Prints the distribution of
// value / point mean and, for the largest, what the estimate used.
TEST_CASE("study: where the outliers of the two-pass estimate come from" * doctest::skip()) {
  scene::SceneDescription d = causticScene(96, 64);
  auto scene = Scene::build(d);
  const int maps = envInt("STUDY_MAPS", 16);
  estimate::Options eo;
  eo.method = estimate::Method::TimeTwoPass;
  eo.k = eo.ks = envInt("STUDY_K", 100);
  eo.fraction = float(envDouble("STUDY_FRACTION", 0.5));
  eo.maxRadius = 0.02f * scene->extent();
  eo.maxTimeDistance = float(envDouble("STUDY_MAXDT", 0.1));
  struct Query { Vec3f x; float t; };
  std::vector<Query> queries;
  for (int it = 0; it < 16; ++it) {
    float t = (it + 0.37f) / 16.0f;
    for (int iz = -6; iz <= 6; ++iz)
      for (int ix = -6; ix <= 6; ++ix)
        queries.push_back({Vec3f{ix * 0.01f + 0.0013f, 0.9f - t, iz * 0.01f - 0.0021f}, t});
  }
  struct Sample { double value, r, window, kept, meanW, maxW; };
  std::vector<std::vector<Sample>> values(queries.size());
  const Vec3f n{0, 1, 0};
  const uint8_t tag = photon::surfaceTag(1, false);  // the box, front side
  estimate::ConstantBrdf brdf{Rgb(0.8f / kPi)};
  for (int m = 0; m < maps; ++m) {
    PhotonMapSettings ms;
    ms.trace.seed = uint64_t(100 + m);
    ms.trace.storedWanted = size_t(envInt("STUDY_PHOTONS", 200000));
    ms.trace.kind = photon::MapKind::Caustic;
    auto map = buildPhotonMap(*scene, ms, Progress{});
    estimate::Gatherer g(map->tree, eo);
    const photon::PhotonStore& s = map->store;
    estimate::Report rep;
    for (size_t q = 0; q < queries.size(); ++q) {
      Rgb v = g.radiance(queries[q].x, n, n, queries[q].t, brdf, &rep, tag);
      double ws = 0, wmax = 0;
      for (uint32_t p : rep.used) {
        float delta = s.ys()[p] - queries[q].x.y;
        double w = rep.radius2 / std::max(rep.radius2 - delta * delta, rep.radius2 / 2);
        ws += w;
        wmax = std::max(wmax, w);
      }
      double win = (rep.windowHi - rep.windowLo) * 256.0;
      values[q].push_back({test::luminance(v), std::sqrt(rep.radius2), win, double(rep.kept),
                           rep.used.empty() ? 0.0 : ws / rep.used.size(), wmax});
    }
  }
  // value / mean of the same point over the maps
  struct Out { double ratio; Sample s; double mean; size_t q; };
  std::vector<Out> all;
  for (size_t q = 0; q < queries.size(); ++q) {
    double mean = 0;
    for (const Sample& s : values[q]) mean += s.value;
    mean /= maps;
    if (mean <= 0) continue;
    for (const Sample& s : values[q]) all.push_back({s.value / mean, s, mean, q});
  }
  std::sort(all.begin(), all.end(), [](const Out& a, const Out& b) { return a.ratio > b.ratio; });
  double sum2 = 0;
  for (const Out& o : all) sum2 += (o.ratio - 1) * (o.ratio - 1);
  MESSAGE(all.size() << " estimates; relative sd over maps " << std::sqrt(sum2 / all.size()) << "; ratio quantiles: 50% "
                     << all[all.size() / 2].ratio << ", 90% " << all[all.size() / 10].ratio << ", 99% "
                     << all[all.size() / 100].ratio << ", 99.9% " << all[all.size() / 1000].ratio << ", max "
                     << all[0].ratio);
  for (size_t i = 0; i < std::min<size_t>(all.size(), size_t(envInt("STUDY_TOP", 20))); ++i) {
    const Out& o = all[i];
    MESSAGE("ratio " << o.ratio << " value " << o.s.value << " (point mean " << o.mean << ") r " << o.s.r
                     << " window " << o.s.window << " bins, kept " << o.s.kept << ", slice weight mean " << o.s.meanW
                     << " max " << o.s.maxW << "; x " << queries[o.q].x.x << "," << queries[o.q].x.z << " t "
                     << queries[o.q].t);
  }
  // Typical estimates at the same points, for comparison.
  double rs = 0, ws = 0, ks = 0;
  for (const Out& o : all) { rs += o.s.r; ws += o.s.window; ks += o.s.kept; }
  MESSAGE("all: mean r " << rs / all.size() << ", mean window " << ws / all.size() << " bins, mean kept " << ks / all.size());
  CHECK(all.size() > 0);
}

namespace {

struct TailStats {
  double mean = 0;      // mean estimate over the samples
  double topShare = 0;  // share of the sum carried by the largest 1% of the estimates
  double maxRatio = 0;  // largest estimate / mean
};

// Eye-sample-like two-pass estimates on the box top of the caustic scene:
// x uniform over a 0.12 x 0.12 patch around the ball's axis (about 4 x 4
// pixels of the scene's 96 x 64 camera), t stratified over the shutter,
// with the kernel-volume minimum the renderer would ask for at 16 spp and
// scale `footprint` (0: pure k-NN).
TailStats causticTail(const Scene& scene, const PhotonMap& map, float footprint, int samples,
                      estimate::Method method = estimate::Method::TimeTwoPass) {
  estimate::Options eo;
  eo.method = method;
  eo.maxRadius = 0.02f * scene.extent();
  eo.maxTimeDistance = 0.1f;
  estimate::Gatherer g(map.tree, eo);
  Vec3f o, d0, d1;
  scene.camera.generateRay({48.0f, 32.0f}, 0.5f, o, d0);
  scene.camera.generateRay({49.0f, 32.0f}, 0.5f, o, d1);
  const float pixelAngle = length(cross(d0, d1)) / (length(d0) * length(d1));
  const Vec3f n{0, 1, 0};
  const uint8_t tag = photon::surfaceTag(1, false);  // the box (object 1), front side
  estimate::ConstantBrdf brdf{Rgb(0.8f / kPi)};
  Rng rng(7);
  std::vector<double> v;
  double sum = 0;
  for (int i = 0; i < samples; ++i) {
    float t = (float(i) + rng.uniform()) / float(samples);
    Vec3f x{(rng.uniform() - 0.5f) * 0.12f, 0.9f - t, (rng.uniform() - 0.5f) * 0.12f};
    float L = length(x - o);
    float minVolume = footprint * pixelAngle * pixelAngle * L * L / 16.0f;  // shutter 1 s, 16 spp
    v.push_back(test::luminance(g.radiance(x, n, n, t, brdf, nullptr, tag, minVolume)));
    sum += v.back();
  }
  std::sort(v.begin(), v.end(), std::greater<double>());
  TailStats s;
  s.mean = sum / samples;
  double top = 0;
  for (int i = 0; i < samples / 100; ++i) top += v[size_t(i)];
  s.topShare = top / sum;
  s.maxRatio = v[0] / s.mean;
  return s;
}

}  // namespace

namespace {

// The caustic scene's focused caustic, estimated by `method` (the 4D search
// on a 4D tree, kappa 1 as the renderer's default) with the pure k-NN and
// with footprint 1: the first pair of checks shows the heavy tail the
// minimum removes (so the test fails without the minimum), the second that
// it is gone, the last that the mean moves only by the k-NN's own overshoot
// in the focus (docs: +6% against the frozen-time reference in the streak's
// core), not by a collapse.
void checkFootprintBoundsTail(estimate::Method method) {
  auto scene = Scene::build(causticScene(96, 64));
  PhotonMapSettings ms;
  ms.trace.seed = 5;
  ms.trace.storedWanted = 100000;
  ms.trace.kind = photon::MapKind::Caustic;
  ms.spaceTime = method == estimate::Method::SpaceTime4D;
  ms.kappa = 1.0f;
  auto map = buildPhotonMap(*scene, ms, Progress{});
  TailStats knn = causticTail(*scene, *map, 0.0f, 6000, method);
  TailStats fp = causticTail(*scene, *map, 1.0f, 6000, method);
  MESSAGE("pure k-NN: mean " << knn.mean << ", top 1% carry " << knn.topShare << ", max/mean " << knn.maxRatio);
  MESSAGE("footprint 1: mean " << fp.mean << ", top 1% carry " << fp.topShare << ", max/mean " << fp.maxRatio);
  CHECK(knn.topShare > 0.09);
  CHECK(knn.maxRatio > 15.0);
  // Light-tailed: a Gaussian-like spread would put ~3% in the top 1%.
  CHECK(fp.topShare < 0.07);
  CHECK(fp.maxRatio < 10.0);
  CHECK(fp.mean > 0.8 * knn.mean);
  CHECK(fp.mean < knn.mean);
}

}  // namespace

// The root cause (docs/photon-map.md, "The estimate's variance"): where the
// photons bunch, the k_s nearest fill a kernel far smaller than one eye
// sample's share of its pixel, so the eye samples, not the photons, decide
// the value, and rare samples that land in the focus carry the pixel. The
// minimum kernel volume bounds that: measured on 3 photon maps (seeds 5-7),
// the largest 1% of the estimates carry 12.2-12.7% of the sum with the pure
// k-NN and 4.9-5.1% with footprint 1; max/mean 27 -> 6.
TEST_CASE("caustic variance: a focused caustic on a box moving along its normal is not carried by rare huge estimates") {
  checkFootprintBoundsTail(estimate::Method::TimeTwoPass);
}

// The same for the 4D search (`--search 4d`): its k nearest in space-time
// bunch in the focus as the two-pass estimate's do, and the same minimum
// volume (the clipped ellipsoid's, k grown) bounds the tail. Seed 5: top 1%
// 13.0% -> 6.2%, max/mean 31.4 -> 7.7, mean -11%.
TEST_CASE("caustic variance: the 4D search's tail is bounded by the same minimum kernel volume") {
  checkFootprintBoundsTail(estimate::Method::SpaceTime4D);
}

// Measurement: `tdpm_tests -tc='study: footprint*' --no-skip` — the tail and
// the mean of causticTail for footprint scales 0.03-10 on photon maps of
// seeds 5, 6, 7.
TEST_CASE("study: footprint scale against the tail and the mean of the two-pass estimate" * doctest::skip()) {
  auto scene = Scene::build(causticScene(96, 64));
  for (int seed : {5, 6, 7}) {
    PhotonMapSettings ms;
    ms.trace.seed = uint64_t(seed);
    ms.trace.storedWanted = 100000;
    ms.trace.kind = photon::MapKind::Caustic;
    auto map = buildPhotonMap(*scene, ms, Progress{});
    TailStats a = causticTail(*scene, *map, 0.0f, 6000);
    for (float f : {0.03f, 0.1f, 0.3f, 1.0f, 3.0f, 10.0f}) {
      TailStats b = causticTail(*scene, *map, f, 6000);
      MESSAGE("footprint " << f << " seed " << seed << ": mean " << b.mean / a.mean << " of the k-NN's, top 1% carry "
                           << a.topShare << " -> " << b.topShare << ", max/mean " << a.maxRatio << " -> " << b.maxRatio);
      CHECK(b.topShare <= a.topShare * 1.01);  // a larger kernel never makes the tail heavier here
    }
  }
}
