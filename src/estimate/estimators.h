// estimate/estimators.h — the three radiance estimates over a photon map
// (method.md sections 3-4) behind one per-thread object, Gatherer:
//
//   Standard     eq. (3):  L = 1/(pi r^2 ts) sum f_r Q_p K1        (time ignored)
//   TimeTwoPass  eq. (9):  L = 1/(pi r^2 h N) sum f_r Q_p K1 K2     (space-time cylinder)
//   SpaceTime4D  4D k-NN, L = 1/V sum f_r Q_p, V the space-time ellipsoid
//                clipped to the photons' time range (closed form below)
//
// The renderer calls Gatherer::radiance(x, n, wo, t, brdf). Choices:
//  * BRDF: a template parameter, any functor `Rgb operator()(Vec3f wi, Vec3f
//    wo) const` (a lambda, or a material's evaluation bound to a hit). It is
//    inlined into the gather loop: no virtual call per photon. The method
//    and the kernels are dispatched once per query (a switch) into loops
//    instantiated per kernel.
//  * Photons count only when they arrived on the side the normal faces,
//    dot(n, wi) > 0 (wi points back towards where the photon came from), as
//    in Jensen: thin objects do not leak light through. The search radius is
//    still that of the k nearest of either side (the estimate stays
//    consistent; it is the number found inside the known disc).
//  * Photons on the other side of the gather point's own object's surface
//    never count (photon/surface_tag.h): the side test alone lets light
//    through the convex edges and thin parts of closed objects. The query
//    passes its surface tag (kNoSurfaceTag: no such rule); the radius is
//    again that of the k nearest, whatever their tags.
//  * Radius: with k found, r = distance of the k-th; with fewer, every
//    photon within maxRadius was found and r = maxRadius (if maxRadius is
//    infinite, the farthest found). r^2 is at least minRadius2, so
//    coincident photons give a large but finite value, never NaN.
//  * Small counts (docs/photon-map.md, "Few photons"): where a photon's
//    distance defines the radius (the k-th, or the farthest when the map
//    holds fewer than k), that photon lies on the boundary, not inside: it
//    is left out of the sum (and out of the two-pass time selection), so
//    the estimate is (k-1) photons over the volume the k-th defines, whose
//    mean is the density for any k (k / volume has mean k/(k-1) times it).
//    Where the search stopped at maxRadius nothing is left out: the photons
//    of a known disc were all counted. The same holds in time (two-pass)
//    and in space-time (4D).
//  * Time: the 8-bit bins of photon/store.h. Two-pass: the window is the kept
//    bins [lo, hi] (photon/temporal_select.h; ties kept whole), i.e. the
//    interval [lo, hi + 1) in bin units, which lies inside the shutter by
//    construction, so it is already clipped at shutter open and close.
//    h = max(u - lo, hi + 1 - u) is the half-width of the kernel window
//    centred on the query u, [a, b] = ([lo, hi+1] - u) / h its clipped part,
//    N = integral of K2 over [a, b] (= b - a for uniform: the volume is
//    pi r^2 times the window length). See docs/photon-map.md for why the
//    window is whole bins rather than 2 max |t_p - t| with bin centres.
//    The window is defined by the m-th kept photon, so the estimate counts
//    m - 1 photons over the expected window the m-th one closes
//    (timeWindowCorrection); where kMinTimePhotons would be all the
//    candidates, the window is the known one (the bins within
//    maxTimeDistance, or the whole shutter) and the estimate the plain
//    count over it; so it is where maxTimeDistance cut the window short.
//  * Two-pass minimum kernel volume (the eye sample's share of its pixel):
//    radiance(..., minVolume) asks that the space-time kernel pi r^2 h N be
//    at least minVolume (scene units^2 x seconds). Where photons bunch (a
//    focused caustic on a surface moving along its normal) the k_s nearest
//    fill a ball far smaller than the footprint one eye sample stands for,
//    and its window, tied to r by the motion, is a few bins: the estimate
//    resolves structure the eye samples cannot, and the pixel mean becomes
//    heavy-tailed (docs/photon-map.md, "The estimate's variance"). Such a
//    query is redone with k_s grown by minVolume / volume (at most
//    Options::maxGrowth times): the photon count in the kernel grows with its
//    volume, so the kernel reaches about the footprint and averages what the
//    sample's neighbours would have averaged anyway.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "estimate/kernels.h"
#include "math/vec.h"
#include "photon/kdtree.h"
#include "photon/surface_tag.h"
#include "photon/temporal_select.h"

namespace tdpm::estimate {

enum class Method : unsigned char { Standard, TimeTwoPass, SpaceTime4D };

// Largest weight the two-pass slice correction gives a photon (see
// twoPassImpl): photons at |delta| > r sqrt(1 - 1/2) are under-corrected.
constexpr float kMaxSliceWeight = 2.0f;

// Fewest photons the two-pass estimate keeps in time (a "handful"). With m
// kept the m-th defines the window and the estimate is (m-1) / window: its
// upper tail falls as x^-m (P(window < x) ~ x^m), so a floor on m bounds
// the 99.9th percentile; below it the window is the known one (header).
constexpr int kMinTimePhotons = 8;

// Photons an estimate is said to come from "few" of (--stats).
constexpr int kFewPhotons = 8;

// The two-pass small-count factor (docs/photon-map.md, "Few photons"): the
// window [lo, hi] of `kept` photons was closed by the m-th nearest in time;
// `prevBins` / `prevKept`: the bins strictly nearer than the window's outer
// bins and the photons in them (< m). Returns c such that the estimate
// (sum / window) x c = sum / kept x (m - 1) x E[1 / X_m | bin counts], X_m
// the measure (in bins) at which the m-th photon arrives when the window
// grows bin by bin: (m - 1) / X_m is unbiased for a Poisson or binomial
// process, and its mean given the counts is taken to second order.
double timeWindowCorrection(int m, int windowBins, int kept, int prevBins, int prevKept);

struct Options {
  Method method = Method::TimeTwoPass;
  int k = 100;              // Standard and SpaceTime4D: photons in the estimate
  int ks = 200;             // TimeTwoPass: spatial candidates (first pass)
  float fraction = 0.5f;    // TimeTwoPass: f, the part kept in time
  float maxRadius = std::numeric_limits<float>::infinity();        // space (4D: of the metric)
  float maxTimeDistance = std::numeric_limits<float>::infinity();  // seconds, TimeTwoPass
  SpaceKernel spaceKernel = SpaceKernel::Uniform;  // Standard and TimeTwoPass
  float coneK = 1.1f;                              // Jensen's cone filter constant
  TimeKernel timeKernel = TimeKernel::Uniform;     // TimeTwoPass
  float minRadius2 = 1e-12f;  // floor of r^2 (scene units^2), see header
  // TimeTwoPass with a minimum volume (see header): k_s may grow to at most
  // maxGrowth x ks for a query whose kernel is smaller than asked.
  int maxGrowth = 16;
};

// What an estimate used (tests, debugging). Filling `used` allocates, so
// pass a Report only when you want it.
struct Report {
  std::vector<uint32_t> used;  // store indices of the photons summed (front side, in window)
  int candidates = 0;          // photons found by the k-NN
  int kept = 0;                // TimeTwoPass: inside the time window (either side)
  float radius2 = 0.0f;        // r^2 (4D: d^2 of the metric)
  float windowLo = 0.0f, windowHi = 0.0f;  // time window, seconds (Standard: the shutter)
  float volume = 0.0f;         // the denominator: pi r^2 ts, pi r^2 h N / c, or V
  int summed = 0;              // photons the sum ran over (boundary photon left out)
};

// A BRDF that is the same for all directions (Lambertian: albedo / pi).
struct ConstantBrdf {
  Rgb value;
  Rgb operator()(Vec3f /*wi*/, Vec3f /*wo*/) const { return value; }
};

// Volume of the space-time ellipsoid |dx|^2 + kappa s^2 <= d2 of a locally
// flat surface, (u, v, s), restricted to s in [a, b] (derivation in the .cpp).
double clippedEllipsoidVolume(double d2, double kappa, double a, double b);

// One per thread: owns the k-NN scratch, so a query allocates nothing.
class Gatherer {
 public:
  Gatherer(const photon::KdTree& tree, const Options& options);
  const Options& options() const { return opt_; }
  // Photons the last estimate's sum ran over (before the side and surface
  // tests; the boundary photon left out); 0 if none were found.
  int lastSummed() const { return lastSummed_; }

  // minVolume: TimeTwoPass and SpaceTime4D, the smallest space-time kernel
  // volume (scene units^2 x seconds) the query should use; 0: none (see
  // header).
  template <class Brdf>
  Rgb radiance(Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report = nullptr,
              uint8_t surfaceTag = photon::kNoSurfaceTag, float minVolume = 0.0f) {
    switch (opt_.method) {
      case Method::Standard: return standard(x, n, wo, brdf, report, surfaceTag);
      case Method::TimeTwoPass: return timeTwoPass(x, n, wo, t, brdf, report, surfaceTag, minVolume);
      case Method::SpaceTime4D: return spaceTime4D(x, n, wo, t, brdf, report, surfaceTag, minVolume);
    }
    return Rgb(0.0f);
  }

  // ---- Standard, eq. (3): L = 1/(pi r^2) sum f_r(x, w_p, w) Q_p K1 / ts ----
  template <class Brdf>
  Rgb standard(Vec3f x, Vec3f n, Vec3f wo, const Brdf& brdf, Report* report = nullptr,
               uint8_t surfaceTag = photon::kNoSurfaceTag) {
    switch (opt_.spaceKernel) {
      case SpaceKernel::Uniform: return standardImpl(K1Uniform{}, x, n, wo, brdf, report, surfaceTag);
      case SpaceKernel::Epanechnikov: return standardImpl(K1Epanechnikov{}, x, n, wo, brdf, report, surfaceTag);
      case SpaceKernel::Cone: return standardImpl(K1Cone(opt_.coneK), x, n, wo, brdf, report, surfaceTag);
    }
    return Rgb(0.0f);
  }

  // ---- Time-dependent two-pass, eq. (9) with kernels:
  //      L = 1/(pi r^2 h N) sum f_r Q_p K1(|x_p - x|/r) K2((t_p - t)/h) ----
  template <class Brdf>
  Rgb timeTwoPass(Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report = nullptr,
                  uint8_t surfaceTag = photon::kNoSurfaceTag, float minVolume = 0.0f) {
    bool epa = opt_.timeKernel == TimeKernel::Epanechnikov;
    switch (opt_.spaceKernel) {
      case SpaceKernel::Uniform:
        return epa ? twoPassImpl<K2Epanechnikov>(K1Uniform{}, x, n, wo, t, brdf, report, surfaceTag, minVolume)
                   : twoPassImpl<K2Uniform>(K1Uniform{}, x, n, wo, t, brdf, report, surfaceTag, minVolume);
      case SpaceKernel::Epanechnikov:
        return epa ? twoPassImpl<K2Epanechnikov>(K1Epanechnikov{}, x, n, wo, t, brdf, report, surfaceTag, minVolume)
                   : twoPassImpl<K2Uniform>(K1Epanechnikov{}, x, n, wo, t, brdf, report, surfaceTag, minVolume);
      case SpaceKernel::Cone:
        return epa ? twoPassImpl<K2Epanechnikov>(K1Cone(opt_.coneK), x, n, wo, t, brdf, report, surfaceTag, minVolume)
                   : twoPassImpl<K2Uniform>(K1Cone(opt_.coneK), x, n, wo, t, brdf, report, surfaceTag, minVolume);
    }
    return Rgb(0.0f);
  }

  // ---- 4D: L = 1/V sum f_r Q_p over the k nearest in |dx|^2 + kappa dt^2,
  //      V = clippedEllipsoidVolume(d^2, kappa, a, b) ----
  template <class Brdf>
  Rgb spaceTime4D(Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report = nullptr,
                  uint8_t surfaceTag = photon::kNoSurfaceTag, float minVolume = 0.0f);

 private:
  // Radius^2 of the search ball per the rule in the header comment.
  float ballRadius2(int found, int k, float maxR2) const {
    float r2 = found == k ? query_.radius2 : (std::isfinite(maxR2) ? maxR2 : query_.maxFound2);
    return r2 > opt_.minRadius2 ? r2 : opt_.minRadius2;
  }
  // The photon whose distance defines the radius, moved to slot 0: returns
  // 1 (skip slot 0) if there is one, 0 if the search stopped at the maximum
  // radius (every photon of a known ball found). See header.
  int boundaryFirst(int found, int k, float maxR2) {
    if (found == k) return 1;  // full heap: the root is the farthest
    if (std::isfinite(maxR2) || found == 0) return 0;
    photon::moveFarthestFirst(query_, found);
    return 1;
  }
  template <class K1, class Brdf>
  Rgb standardImpl(K1 k1, Vec3f x, Vec3f n, Vec3f wo, const Brdf& brdf, Report* report, uint8_t surfaceTag);
  template <class K2, class K1, class Brdf>
  Rgb twoPassImpl(K1 k1, Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report,
                  uint8_t surfaceTag, float minVolume);

  const photon::KdTree* tree_;
  Options opt_;
  photon::KnnQuery query_;
  std::vector<uint8_t> bins_;  // candidates' time bins, padded for SIMD
  std::vector<int> kept_;      // positions of the kept candidates
  int lastSummed_ = 0;
};

// ---------------------------------------------------------------------------

template <class K1, class Brdf>
Rgb Gatherer::standardImpl(K1 k1, Vec3f x, Vec3f n, Vec3f wo, const Brdf& brdf, Report* report,
                           uint8_t surfaceTag) {
  const photon::PhotonStore& s = tree_->store();
  float maxR2 = opt_.maxRadius * opt_.maxRadius;
  lastSummed_ = 0;
  int found = tree_->knn(x, opt_.k, maxR2, query_);
  if (report) {
    *report = Report{};
    report->candidates = found;
    report->windowLo = s.t0();
    report->windowHi = s.t1();
  }
  if (found == 0) return Rgb(0.0f);
  float r2 = ballRadius2(found, opt_.k, maxR2);
  float invR2 = 1.0f / r2;
  const int first = boundaryFirst(found, opt_.k, maxR2);  // the k-th is on the boundary
  lastSummed_ = found - first;
  const uint32_t* idx = query_.index();
  const float* d2 = query_.dist2();
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  const uint16_t* flags = s.flags();
  Rgb sum(0.0f);
  for (int i = first; i < found; ++i) {
    uint32_t p = idx[i];
    Vec3f wi = photon::decodeDirection(dirs[p]);
    if (!(dot(n, wi) > 0.0f)) continue;
    if (photon::otherSideOfSameSurface(uint8_t(flags[p] >> photon::kUserShift), surfaceTag)) continue;
    sum += brdf(wi, wo) * photon::decodeRgbe(energies[p]) * k1(std::min(d2[i] * invR2, 1.0f));
    if (report) report->used.push_back(p);
  }
  float volume = kPi * r2 * s.shutterLength();
  if (report) {
    report->radius2 = r2;
    report->volume = volume;
    report->kept = found;
    report->summed = found - first;
  }
  return sum * (1.0f / volume);
}

template <class K2, class K1, class Brdf>
Rgb Gatherer::twoPassImpl(K1 k1, Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report,
                          uint8_t surfaceTag, float minVolume) {
  const photon::PhotonStore& s = tree_->store();
  const photon::TimeQuantiser& tq = s.time();
  const float maxR2 = opt_.maxRadius * opt_.maxRadius;
  const uint16_t* flags = s.flags();
  const float u = tq.binUnits(t);
  if (report) *report = Report{};
  lastSummed_ = 0;
  int ks = opt_.ks, found = 0, nc = 0;
  float r2 = 0.0f, h = 0.0f, invH = 0.0f, volume = 0.0f;
  uint8_t* bins = nullptr;
  const uint32_t* idx = nullptr;
  const float* d2 = nullptr;
  photon::TimeWindow win;
  const float maxDistBins = opt_.maxTimeDistance * tq.invBinWidth;
  // At most twice: the k_s nearest, then (if the kernel is smaller than
  // minVolume and the search was not stopped by the maximum radius) again
  // with k_s grown by the missing volume ratio (see the header comment).
  for (int attempt = 0;; ++attempt) {
    // ---- pass 1: k_s nearest in space; the k_s-th closes the disc ----
    found = tree_->knn(x, ks, maxR2, query_);
    if (report) report->candidates = found;
    if (found == 0) return Rgb(0.0f);
    r2 = ballRadius2(found, ks, maxR2);
    const int first = boundaryFirst(found, ks, maxR2);
    nc = found - first;  // candidates strictly inside the disc
    if (nc == 0) return Rgb(0.0f);
    idx = query_.index() + first;
    d2 = query_.dist2() + first;
    if (bins_.size() < size_t(nc) + photon::kSelectPadding) bins_.resize(size_t(nc) + photon::kSelectPadding);
    if (kept_.size() < size_t(nc)) kept_.resize(size_t(nc));
    bins = bins_.data();
    for (int i = 0; i < nc; ++i) bins[i] = uint8_t(flags[idx[i]] & photon::kTimeMask);
    // ---- pass 2: the fraction f nearest in time (whole bins) ----
    // At least kMinTimePhotons; if that is all of them, the window is the
    // known one (the shutter, or the bins within maxTimeDistance) and the
    // estimate is the plain count over it (header: "Few photons").
    const int keep = std::max(photon::keptCount(opt_.fraction, nc), kMinTimePhotons);
    double c = 1.0;  // small-count factor of a photon-defined window
    if (keep >= nc) {
      win = photon::binsWithinKey(u, std::isfinite(maxDistBins) ? 2.0f * maxDistBins : maxDistBins);
      if (win.empty()) return Rgb(0.0f);
      win.kept = 0;
      for (int i = 0; i < nc; ++i) win.kept += int(win.contains(bins[i]));
    } else {
      win = photon::selectTimeWindow(bins, nc, u, keep, maxDistBins);
      if (win.empty()) return Rgb(0.0f);
      if (win.kept >= keep) {
        // The keep-th photon closed the window: the bins strictly nearer
        // than its outer bins, and the photons in them.
        float outer = std::max(photon::timeKey(win.lo, u), photon::timeKey(win.hi, u));
        photon::TimeWindow prev = photon::binsWithinKey(u, std::nextafter(outer, 0.0f));
        int prevKept = 0;
        if (!prev.empty())
          for (int i = 0; i < nc; ++i) prevKept += int(prev.contains(bins[i]));
        c = timeWindowCorrection(keep, win.hi - win.lo + 1, win.kept, prev.empty() ? 0 : prev.hi - prev.lo + 1,
                                 prevKept);
      }  // else: cut by maxTimeDistance, a known window
    }
    if (report) report->kept = win.kept;
    // ---- the cylinder: disc pi r^2 times the clipped window ----
    float lo = float(win.lo), hi1 = float(win.hi + 1);
    h = std::max(u - lo, hi1 - u);  // >= 0.5: u lies in [lo, hi + 1]
    invH = 1.0f / h;
    float norm = K2::integral((lo - u) * invH, (hi1 - u) * invH);
    volume = float(double(kPi * r2 * (h * tq.binWidth) * norm) / c);
    if (attempt > 0 || !(volume < minVolume) || found < ks) break;
    const int maxKs = opt_.ks * std::max(1, opt_.maxGrowth);
    const double grown = std::ceil(double(ks) * double(minVolume) / double(volume));
    int next = grown < double(maxKs) ? int(grown) : maxKs;
    if (next <= ks) break;
    ks = next;
  }
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  // Compact the kept candidates without a branch (about half are kept, in
  // no order a predictor could learn), then sum over them.
  int* kept = kept_.data();
  int m = 0;
  const unsigned lo8 = unsigned(win.lo), width8 = unsigned(win.hi - win.lo);
  for (int i = 0; i < nc; ++i) {
    kept[m] = i;
    m += int(unsigned(bins[i]) - lo8 <= width8);
  }
  lastSummed_ = m;
  // ---- slice correction ----
  // A photon of time t_p lies on the surface as it was at t_p. If the
  // surface moved along its normal, that copy is offset by
  // delta = n . (x_p - x), and the ball of radius r cut it in a disc of
  // radius^2 r^2 - delta^2, not r^2: the photon stands for that smaller
  // area. So its kernel is taken over its slice (rho^2 = d^2 - delta^2 over
  // r^2 - delta^2) and it is weighted by r^2 / (r^2 - delta^2). On a
  // static flat surface delta = 0 and this is the plain cylinder estimate;
  // without it a plane moving along its normal is underestimated by
  // 1 - a^2/3 (a = kept time half-width in units of r / v: ~4% at f = 0.5,
  // measured in tests/test_photon_render.cpp). The factor is capped at
  // kMaxSliceWeight so that photons on a perpendicular static face (a
  // concave corner, delta ~ r) cannot inflate the estimate.
  const float* px = s.xs();
  const float* py = s.ys();
  const float* pz = s.zs();
  const float minSlice2 = r2 * (1.0f / kMaxSliceWeight);
  Rgb sum(0.0f);
  for (int j = 0; j < m; ++j) {
    int i = kept[j];
    uint32_t p = idx[i];
    Vec3f wi = photon::decodeDirection(dirs[p]);
    if (!(dot(n, wi) > 0.0f)) continue;
    if (photon::otherSideOfSameSurface(uint8_t(flags[p] >> photon::kUserShift), surfaceTag)) continue;
    float delta = n.x * (px[p] - x.x) + n.y * (py[p] - x.y) + n.z * (pz[p] - x.z);
    float slice2 = std::max(r2 - delta * delta, minSlice2);
    float rho2 = std::max(d2[i] - delta * delta, 0.0f);
    float y0 = (float(bins[i]) - u) * invH;
    float w = k1(std::min(rho2 / slice2, 1.0f)) * (r2 / slice2) * K2::binMean(y0, y0 + invH);
    sum += brdf(wi, wo) * photon::decodeRgbe(energies[p]) * w;
    if (report) report->used.push_back(p);
  }
  if (report) {
    report->radius2 = r2;
    report->volume = volume;
    report->windowLo = tq.binStart(win.lo);
    report->windowHi = tq.binStart(win.hi + 1);
    report->summed = m;
  }
  return sum * (1.0f / volume);
}

template <class Brdf>
Rgb Gatherer::spaceTime4D(Vec3f x, Vec3f n, Vec3f wo, float t, const Brdf& brdf, Report* report,
                          uint8_t surfaceTag, float minVolume) {
  const photon::PhotonStore& s = tree_->store();
  const photon::TimeQuantiser& tq = s.time();
  t = std::min(std::max(t, tq.t0), tq.t1);
  lastSummed_ = 0;
  float maxD2 = opt_.maxRadius * opt_.maxRadius;
  const uint16_t* flags = s.flags();
  const double kappa = tree_->kappa();
  int k = opt_.k, found = 0;
  float D2 = 0.0f;
  double a = 0.0, b = 0.0, volume = 0.0;
  // At most twice, as the two-pass estimate: the k nearest, then (if their
  // ellipsoid is smaller than minVolume and the search was not stopped by
  // the maximum radius) again with k grown by the missing volume ratio.
  for (int attempt = 0;; ++attempt) {
    found = tree_->knn4(x, t, k, maxD2, query_);
    if (found == 0) {
      if (report) *report = Report{};
      return Rgb(0.0f);
    }
    D2 = ballRadius2(found, k, maxD2);
    // Time extent of the ellipsoid, clipped to the shutter: s in [a, b]
    // relative to t. Not to the photons' own time range: that range is
    // defined by the photons found, and dividing by it inflates the
    // estimate where they are few (x2.8 on a sparse global map).
    double half = std::sqrt(double(D2) / kappa);
    a = std::max(-half, double(tq.t0) - t);
    b = std::min(half, double(tq.t1) - t);
    volume = clippedEllipsoidVolume(D2, kappa, a, b);
    if (attempt > 0 || !(volume < double(minVolume)) || !(volume > 0.0) || found < k) break;
    const int maxK = opt_.k * std::max(1, opt_.maxGrowth);
    const double grown = std::ceil(double(k) * double(minVolume) / volume);
    int next = grown < double(maxK) ? int(grown) : maxK;
    if (next <= k) break;
    k = next;
  }
  // The k-th photon closes the ellipsoid: (k-1) inside it (header).
  const int first = boundaryFirst(found, k, maxD2);
  lastSummed_ = found - first;
  if (report) {
    *report = Report{};
    report->candidates = found;
    report->kept = found;
    report->summed = found - first;
  }
  const uint32_t* idx = query_.index();
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  Rgb sum(0.0f);
  for (int i = first; i < found; ++i) {
    uint32_t p = idx[i];
    Vec3f wi = photon::decodeDirection(dirs[p]);
    if (!(dot(n, wi) > 0.0f)) continue;
    if (photon::otherSideOfSameSurface(uint8_t(flags[p] >> photon::kUserShift), surfaceTag)) continue;
    sum += brdf(wi, wo) * photon::decodeRgbe(energies[p]);
    if (report) report->used.push_back(p);
  }
  if (report) {
    report->radius2 = D2;
    report->volume = float(volume);
    report->windowLo = float(t + a);
    report->windowHi = float(t + b);
  }
  if (!(volume > 0.0)) return Rgb(0.0f);
  return sum * float(1.0 / volume);
}

}  // namespace tdpm::estimate
