// estimate/fixed_kernel.h — the fixed-kernel estimates of a progressive
// pass (render/progressive.h): "every photon within r" (and within the time
// window [t - h, t + h]) instead of the k nearest. Each pass uses kernels
// set before it starts, so its estimate is a plain kernel density estimate
// whose bias and variance are known functions of r and h (the derivation
// of how they shrink is in docs/photon-map.md, "Progressive passes").
//
//   spatial     L = 1/(pi r^2 ts) sum f_r Q_p                 (whole shutter)
//   spaceTime   L = 1/(pi r^2 W)  sum f_r Q_p s_p w_p          (disc x window)
//
// with ts the store's shutter length, W the window [t - h, t + h] clipped to
// the shutter (so the estimate stays unbiased for a density constant over
// the clipped window), w_p the part of photon p's 8-bit time bin inside the
// window (a photon's time is known only to its bin, over which it is
// uniform: photon/store.h), and s_p the slice correction of the two-pass
// estimate (estimators.h twoPassImpl: a photon offset by delta along the
// normal stands for a disc of radius^2 r^2 - delta^2, capped at
// kMaxSliceWeight). Same rules as the k-NN estimates: only photons that
// arrived on the side the normal faces (dot(n, wi) > 0) and not on the other
// side of the gather point's own surface (photon/surface_tag.h). Kernels are
// uniform in space and time (the k-NN estimates' default).
//
// One FixedKernelGatherer per thread: it owns the range query's buffers,
// which grow to the largest result and are then reused (no allocation per
// query after warm-up); the BRDF is a template parameter, inlined (no
// virtual call per photon).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "estimate/estimators.h"
#include "math/vec.h"
#include "photon/kdtree.h"
#include "photon/surface_tag.h"

namespace tdpm::estimate {

// Kernel sizes of one photon map for one pass.
struct MapKernel {
  float radius = 0.0f;         // space-time disc radius r_i (scene units)
  float halfWindow = 0.0f;     // space-time half window h_i (seconds)
  float spatialRadius = 0.0f;  // disc radius of the spatial estimate (whole shutter)
};

// What one fixed-kernel estimate used (tests).
struct FixedReport {
  int found = 0;    // photons within r (either side, any time)
  int used = 0;     // of them, summed (front side, tag, some overlap with the window)
  float windowLo = 0.0f, windowHi = 0.0f;  // clipped window, seconds
  float volume = 0.0f;                     // the denominator
};

class FixedKernelGatherer {
 public:
  // Spatial disc of radius r over the pass's whole shutter.
  template <class Brdf>
  Rgb spatial(const photon::KdTree& tree, Vec3f x, Vec3f n, Vec3f wo, float r, const Brdf& brdf,
              uint8_t surfaceTag = photon::kNoSurfaceTag, FixedReport* report = nullptr) {
    const photon::PhotonStore& s = tree.store();
    int found = tree.range(x, r * r, query_);
    const uint32_t* idx = query_.index();
    const uint16_t* dirs = s.directions();
    const uint32_t* energies = s.energies();
    const uint16_t* flags = s.flags();
    Rgb sum(0.0f);
    int used = 0;
    for (int i = 0; i < found; ++i) {
      uint32_t p = idx[i];
      Vec3f wi = photon::decodeDirection(dirs[p]);
      if (!(dot(n, wi) > 0.0f)) continue;
      if (photon::otherSideOfSameSurface(uint8_t(flags[p] >> photon::kUserShift), surfaceTag)) continue;
      sum += brdf(wi, wo) * photon::decodeRgbe(energies[p]);
      ++used;
    }
    float volume = kPi * r * r * s.shutterLength();
    if (report) *report = {found, used, s.t0(), s.t1(), volume};
    return found == 0 ? Rgb(0.0f) : sum * (1.0f / volume);
  }

  // Disc of radius r times the window [t - h, t + h] clipped to the shutter.
  template <class Brdf>
  Rgb spaceTime(const photon::KdTree& tree, Vec3f x, Vec3f n, Vec3f wo, float t, float r, float h,
                const Brdf& brdf, uint8_t surfaceTag = photon::kNoSurfaceTag, FixedReport* report = nullptr) {
    const photon::PhotonStore& s = tree.store();
    const photon::TimeQuantiser& tq = s.time();
    float lo = std::max(t - h, tq.t0), hi = std::min(t + h, tq.t1);
    if (report) *report = {0, 0, lo, hi, 0.0f};
    if (!(hi > lo) || !(r > 0.0f)) return Rgb(0.0f);
    // The window in bin units: bin q spans [q, q + 1).
    float ua = (lo - tq.t0) * tq.invBinWidth, ub = (hi - tq.t0) * tq.invBinWidth;
    int qa = std::max(0, int(std::floor(ua))), qb = std::min(photon::kTimeBins - 1, int(std::floor(ub)));
    // Weight of each bin: the part of it inside the window (exact for a
    // photon uniform over its bin). Bins wholly inside weigh 1.
    float binWeight[photon::kTimeBins];
    for (int q = qa; q <= qb; ++q) binWeight[q] = std::max(0.0f, std::min(float(q + 1), ub) - std::max(float(q), ua));
    const float r2 = r * r;
    int found = tree.range(x, r2, query_);
    const uint32_t* idx = query_.index();
    const uint16_t* dirs = s.directions();
    const uint32_t* energies = s.energies();
    const uint16_t* flags = s.flags();
    const float* px = s.xs();
    const float* py = s.ys();
    const float* pz = s.zs();
    const float minSlice2 = r2 * (1.0f / kMaxSliceWeight);
    const unsigned qa8 = unsigned(qa), width8 = unsigned(qb - qa);
    Rgb sum(0.0f);
    int used = 0;
    for (int i = 0; i < found; ++i) {
      uint32_t p = idx[i];
      unsigned q = flags[p] & photon::kTimeMask;
      if (q - qa8 > width8) continue;  // outside [qa, qb] (unsigned wrap for q < qa)
      float w = binWeight[q];
      if (!(w > 0.0f)) continue;
      Vec3f wi = photon::decodeDirection(dirs[p]);
      if (!(dot(n, wi) > 0.0f)) continue;
      if (photon::otherSideOfSameSurface(uint8_t(flags[p] >> photon::kUserShift), surfaceTag)) continue;
      // Slice correction (see the header): a photon off the tangent plane
      // stands for a smaller disc of the surface as it was at its time.
      float delta = n.x * (px[p] - x.x) + n.y * (py[p] - x.y) + n.z * (pz[p] - x.z);
      float slice2 = std::max(r2 - delta * delta, minSlice2);
      sum += brdf(wi, wo) * photon::decodeRgbe(energies[p]) * (w * (r2 / slice2));
      ++used;
    }
    float volume = kPi * r2 * (hi - lo);
    if (report) *report = {found, used, lo, hi, volume};
    return used == 0 ? Rgb(0.0f) : sum * (1.0f / volume);
  }

  const photon::RangeQuery& query() const { return query_; }

 private:
  photon::RangeQuery query_;
};

}  // namespace tdpm::estimate
