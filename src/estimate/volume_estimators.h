// estimate/volume_estimators.h — radiance estimates over a volume photon
// map (method.md section 11), as a library the photon tracer and the
// integrators call per camera or gather segment:
//
//   point (ray-marched), the oracle   Jensen & Christensen 1998, with time
//     sigma_s L_i(x, w, t) = 1/(V dt) sum p(w, w_p) Phi_p
//     V = (4/3) pi r^3, dt the time window, over the photons nearest x in
//     space and then in time (the two-pass search of estimators.h)
//     L = sum_j ds T(s_j) sigma_s L_i(x(s_j), w, t), s_j jittered strata
//   beam, the default                 Jarosz, Zwicker & Jensen 2008, with time
//     L = sum_i Phi_i p(w, w_i) T(s_i) K_r / (pi r_i^2) K_t / (2 h_i)
//     over the photons whose disc the segment crosses and whose window
//     holds t (photon/volume_beam_map.h)
//   standard forms of both: time ignored, dt the shutter
//   fixed kernels (a progressive pass): every photon within r and the
//     window [t - h, t + h]; the sizes shrink per pass (volumeKernelScale)
//
// ---- Derivation ----
// Along a segment x(s) = o + s d, s in [s0, s1], at time t, the radiance
// scattered towards the viewer (w = -d) is
//     L = int_s0^s1 T(s0, s) sigma_s(x) L_i(x, w, t) ds,
//     L_i(x, w, t) = int p(w, w') L(x, w', t) dw'.
// Photons are stored at scattering events with the energy Phi_p (joules)
// they carried as they arrived (before the albedo or roulette; a tracer
// that stores at every collision stores Phi_p sigma_s / sigma_t instead,
// same mean), their time and w_p, the direction they came from. Scattering
// events happen at rate sigma_s(x) per unit length travelled, so the energy
// of the events in a small volume V and time window dt, weighted by p, is
//     E[sum p Phi_p] = sigma_s(x) V dt int p(w, w') L(x, w', t) dw'
//                    = sigma_s(x) L_i(x, w, t) V dt,
// i.e. L_i = (1/sigma_s) sum p Phi_p / (V dt) (Jensen & Christensen's
// estimate with density in time; joules over m^3 s is W/m^3, per sr from p).
// In the march the sigma_s of the integrand cancels against this 1/sigma_s,
// so the estimates below need sigma_t (transmittance) only; inScattered()
// is L_i itself for a caller that wants it (sigma_s > 0).
//
// Small counts (docs/photon-map.md "Few photons", estimators.h): the k-th
// nearest photon closes the ball, so it lies on its boundary, not inside;
// (k - 1) photons over the volume it defines have the density as their mean
// for Poisson photons (the ball's volume V_k is Gamma(k) distributed,
// E[1/V_k] = lambda/(k - 1)); k / V_k would be k/(k - 1) too high. So the
// boundary photon is left out of the sum and out of the time selection; in
// time, the window closed by the m-th kept photon has its second-order
// correction (timeWindowCorrection); where the minimum count would be every
// candidate, the window is the known one (the shutter, or the bins within
// maxTimeDistance) and nothing is left out.
//
// The beam estimate needs no such factor: each photon's kernel (disc x
// window) integrates to one whatever its size, so for a stationary process
// E[sum_i K_i(x - x_i)] = lambda int E[K_0(z)] dz = lambda (Mecke's
// formula): the sample-point estimate is unbiased for a uniform density
// whatever the k-NN that sized its kernels. Its disc is the 3D kernel
// "disc across the ray times a delta along it", so the integral of T along
// the segment becomes T at the photon's projection s_i. Time windows end at
// the shutter; a photon's window is reflected there (the part beyond the
// end folds back), which keeps each photon's weight one inside the shutter
// and the estimate unbiased for a density uniform in time up to the ends.
// Uniform kernels; a smooth one (Epanechnikov 2(1 - d^2/r^2) in space, 1.5
// (1 - y^2) in time) has the same mean for a uniform density, lower
// variance at the disc and window edges, and its bias is still second order
// in r and h but with a smaller constant (its second moment is smaller).
//
// Interface: the phase function and the transmittance are template
// functors (`float operator()(float cosTheta)` with cosTheta = dot(w, w_p);
// `Rgb operator()(float s)`, T from x(s0) to x(s) at the segment's time):
// homogeneous media use HomogeneousTransmittance (closed form), grids pass
// their own tracker; no virtual call per photon. A VolumeGatherer (point
// estimates) and a BeamQuery (beam) are per thread and allocate nothing per
// query after warm-up.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/rng.h"
#include "estimate/estimators.h"
#include "math/vec.h"
#include "media/phase.h"
#include "photon/kdtree.h"
#include "photon/temporal_select.h"
#include "photon/volume_beam_map.h"

namespace tdpm::estimate {

using photon::Segment;

// Henyey-Greenstein (g = 0: isotropic, 1/(4 pi)).
struct HgPhase {
  float g = 0.0f;
  float operator()(float cosTheta) const { return media::henyeyGreenstein(cosTheta, g); }
};

// T(s0, s) = exp(-sigma_t (s - s0)) per channel.
struct HomogeneousTransmittance {
  Rgb sigmaT;
  float s0 = 0.0f;
  Rgb operator()(float s) const {
    float l = s - s0;
    // Grey media (the usual fog): one exp, the same bits as three.
    if (sigmaT.r == sigmaT.g && sigmaT.g == sigmaT.b) return Rgb(std::exp(-sigmaT.r * l));
    return {std::exp(-sigmaT.r * l), std::exp(-sigmaT.g * l), std::exp(-sigmaT.b * l)};
  }
};

struct HomogeneousMedium {
  Rgb sigmaS, sigmaT;
  float g = 0.0f;
};

enum class VolumeMethod : unsigned char { Time, Standard, Fixed };

struct VolumeOptions {
  VolumeMethod method = VolumeMethod::Time;
  int k = 100;            // Standard: photons in the estimate
  int ks = 200;           // Time: spatial candidates
  float fraction = 0.5f;  // Time: part kept in time
  float maxRadius = std::numeric_limits<float>::infinity();
  float maxTimeDistance = std::numeric_limits<float>::infinity();  // Time, seconds
  float minRadius2 = 1e-12f;  // floor of r^2 (coincident photons stay finite)
  float fixedRadius = 0.0f;      // Fixed: sphere radius
  float fixedHalfWindow = 0.0f;  // Fixed: h, seconds
};

struct VolumeReport {
  int candidates = 0, summed = 0;
  float radius2 = 0.0f, windowLo = 0.0f, windowHi = 0.0f;
  float volume = 0.0f;  // V dt / c, the denominator
};

// The two-pass time window of nc candidates' bins around u (bin units), as
// estimators.h's twoPassImpl chooses it: win empty when nothing is kept;
// c the small-count factor (volume divided by c).
struct TwoPassWindow {
  photon::TimeWindow win;
  double c = 1.0;
};
TwoPassWindow twoPassTimeWindow(const uint8_t* bins, int nc, float u, float fraction, float maxDistBins);

class VolumeGatherer {
 public:
  VolumeGatherer(const photon::KdTree& tree, const VolumeOptions& options);
  const VolumeOptions& options() const { return opt_; }

  // sigma_s L_i(x, w, t) = sum p Phi / (V dt), wo = w (towards the viewer).
  template <class Phase>
  Rgb scatterDensity(Vec3f x, Vec3f wo, float t, const Phase& phase, VolumeReport* report = nullptr) {
    switch (opt_.method) {
      case VolumeMethod::Time: return timeImpl(x, wo, t, phase, report);
      case VolumeMethod::Standard: return standardImpl(x, wo, phase, report);
      case VolumeMethod::Fixed: return fixedImpl(x, wo, t, phase, report);
    }
    return Rgb(0.0f);
  }
  // L_i itself (sigma_s > 0 per channel).
  template <class Phase>
  Rgb inScattered(Vec3f x, Vec3f wo, float t, const Phase& phase, Rgb sigmaS) {
    Rgb d = scatterDensity(x, wo, t, phase);
    return {d.r / sigmaS.r, d.g / sigmaS.g, d.b / sigmaS.b};
  }
  // Ray-marched in-scattered radiance along seg at time t: `steps` strata
  // of [s0, s1], one jittered point in each (rng), L = sum ds T(s) density.
  template <class Phase, class Tr>
  Rgb march(const Segment& seg, float t, const Phase& phase, const Tr& tr, int steps, Rng& rng);

 private:
  template <class Phase>
  Rgb timeImpl(Vec3f x, Vec3f wo, float t, const Phase& phase, VolumeReport* report);
  template <class Phase>
  Rgb standardImpl(Vec3f x, Vec3f wo, const Phase& phase, VolumeReport* report);
  template <class Phase>
  Rgb fixedImpl(Vec3f x, Vec3f wo, float t, const Phase& phase, VolumeReport* report);
  // Runs the k-NN; r^2 by estimators.h's rule; the boundary photon (if
  // any) moved to slot 0. Returns the first slot to sum from (0 or 1), -1
  // if nothing was found.
  int nearest(Vec3f x, int k, float& r2);
  template <class Phase>
  Rgb sumOver(const uint32_t* idx, int count, Vec3f wo, const Phase& phase) const;

  const photon::KdTree* tree_;
  VolumeOptions opt_;
  photon::KnnQuery knn_;
  photon::RangeQuery range_;
  std::vector<uint8_t> bins_;
  std::vector<uint32_t> kept_;
};

struct BeamReport {
  int crossed = 0;  // discs the segment crossed (any time)
  int summed = 0;   // of them, with the query time in their window
};

// The beam estimate along seg at time t (header). Standard maps (every
// window the whole shutter) ignore t. kTimeless: the standard form on
// any map, every photon's window the whole shutter (the eye side's skip
// rule on a Time map: the same discs, the time average; unbiased by the
// same Mecke argument, as each photon's kernel still integrates to one).
template <bool kTimeless = false, class Phase, class Tr>
Rgb beamRadiance(const photon::VolumeBeamMap& map, photon::BeamQuery& q, const Segment& seg, float t,
                 const Phase& phase, const Tr& tr, BeamReport* report = nullptr) {
  const photon::PhotonStore& s = map.store();
  const photon::TimeQuantiser& tq = s.time();
  const float u = tq.binUnits(t);
  const uint16_t* flags = s.flags();
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  const uint8_t* wc = map.windowCodes();
  const uint8_t* rc = map.radiusCodes();
  const float* invArea = map.invAreaTable();
  const Vec3f wo = -seg.d;
  Rgb sum(0.0f);
  int crossed = 0, summed = 0;
  map.crossing(seg, q, [&](uint32_t i, float sp, float /*d2*/) {
    ++crossed;
    float wt = 1.0f / float(photon::kTimeBins);
    const uint8_t code = wc[i];
    if (!kTimeless && code != photon::kWholeShutter) {
      // Bins [q - w, q + w], i.e. [lo, hi1) in bin units (half-open: a
      // query on a bin boundary sees 2w + 1 bins, not 2w).
      const int w = code, qb = flags[i] & photon::kTimeMask;
      const float lo = float(qb - w), hi1 = float(qb + w + 1);
      if (!(u >= lo && u < hi1)) return;
      // The reflected parts of the window (header), inside the direct one:
      // [0, -lo) below shutter open, [512 - hi1, 256] above close.
      float images = 1.0f + float(u < -lo) + float(u >= 512.0f - hi1);
      wt = images / float(2 * w + 1);
    }
    ++summed;
    float p = phase(dot(wo, photon::decodeDirection(dirs[i])));
    sum += photon::decodeRgbe(energies[i]) * tr(sp) * (p * invArea[rc[i]] * wt);
  });
  if (report) *report = {crossed, summed};
  return sum * tq.invBinWidth;
}

// The same with a homogeneous medium's closed-form transmittance and HG g.
inline Rgb beamRadiance(const photon::VolumeBeamMap& map, photon::BeamQuery& q, const Segment& seg, float t,
                        const HomogeneousMedium& m, BeamReport* report = nullptr) {
  return beamRadiance(map, q, seg, t, HgPhase{m.g}, HomogeneousTransmittance{m.sigmaT, seg.s0}, report);
}

// ---- Progressive passes (Knaus & Zwicker; docs/photon-map.md) ----
// The kernel volume of pass j (1-based) shrinks as V_{j+1} = V_j (j + a)/(j + 1);
// alpha = 4/(d + 4) for a d-dimensional kernel: the beam's disc x window is
// d = 3 (alpha 4/7, as the surface space-time kernel), the point estimate's
// ball x window d = 4 (alpha 1/2). Both sizes scale alike (the split that
// minimises the second-order bias at a given volume, docs/photon-map.md).
constexpr float kAlphaBeam = 4.0f / 7.0f;
constexpr float kAlphaVolumePoint = 0.5f;
// (V_{pass+1} / V_1)^(1/dims), pass 0-based: render/progressive.cpp's
// kernelScale (a test checks they agree; not included from render/ so that
// this library stands alone).
double volumeKernelScale(int pass, double alpha, int dims);

struct VolumeKernel {
  float radius = 0.0f;
  float halfWindow = 0.0f;  // seconds
};
// Pass 0's kernel from a Time beam map of pass 0's photons: the medians of
// the photons' radii and half-widths ((w + 1/2) bins; whole shutter: half of it).
VolumeKernel pilotKernel(const photon::VolumeBeamMap& map);

// A pass's beam kernel in the map's codes: h scaled and rounded to whole
// bins (2w + 1 of them, w >= 0; past 127 the whole shutter), r scaled and
// then corrected so that r^2 h follows the schedule exactly.
struct BeamPassKernel {
  float radius = 0.0f;
  int windowCode = 0;
  float halfWindow = 0.0f;  // what the code means, seconds
};
BeamPassKernel beamKernelForPass(VolumeKernel first, int pass, float binWidth, float alpha = kAlphaBeam);
// A pass's point kernel: both scaled; h floored at one bin with r^3 h kept.
VolumeKernel pointKernelForPass(VolumeKernel first, int pass, float binWidth, float alpha = kAlphaVolumePoint);

// ---------------------------------------------------------------------------

template <class Phase>
Rgb VolumeGatherer::sumOver(const uint32_t* idx, int count, Vec3f wo, const Phase& phase) const {
  const photon::PhotonStore& s = tree_->store();
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  Rgb sum(0.0f);
  for (int j = 0; j < count; ++j) {
    uint32_t p = idx[j];
    sum += photon::decodeRgbe(energies[p]) * phase(dot(wo, photon::decodeDirection(dirs[p])));
  }
  return sum;
}

template <class Phase>
Rgb VolumeGatherer::standardImpl(Vec3f x, Vec3f wo, const Phase& phase, VolumeReport* report) {
  float r2 = 0.0f;
  const int first = nearest(x, opt_.k, r2);
  if (report) *report = VolumeReport{};
  if (first < 0) return Rgb(0.0f);
  const int summed = knn_.count - first;
  const photon::PhotonStore& s = tree_->store();
  float volume = (4.0f / 3.0f) * kPi * r2 * std::sqrt(r2) * s.shutterLength();
  if (report) *report = {knn_.count, summed, r2, s.t0(), s.t1(), volume};
  return sumOver(knn_.index() + first, summed, wo, phase) * (1.0f / volume);
}

template <class Phase>
Rgb VolumeGatherer::timeImpl(Vec3f x, Vec3f wo, float t, const Phase& phase, VolumeReport* report) {
  const photon::PhotonStore& s = tree_->store();
  const photon::TimeQuantiser& tq = s.time();
  if (report) *report = VolumeReport{};
  float r2 = 0.0f;
  const int first = nearest(x, opt_.ks, r2);
  if (first < 0) return Rgb(0.0f);
  const int nc = knn_.count - first;  // strictly inside the ball
  if (nc == 0) return Rgb(0.0f);
  const uint32_t* idx = knn_.index() + first;
  const uint16_t* flags = s.flags();
  if (bins_.size() < size_t(nc) + photon::kSelectPadding) bins_.resize(size_t(nc) + photon::kSelectPadding);
  if (kept_.size() < size_t(nc)) kept_.resize(size_t(nc));
  for (int i = 0; i < nc; ++i) bins_[size_t(i)] = uint8_t(flags[idx[i]] & photon::kTimeMask);
  const float u = tq.binUnits(t);
  TwoPassWindow tw = twoPassTimeWindow(bins_.data(), nc, u, opt_.fraction, opt_.maxTimeDistance * tq.invBinWidth);
  if (tw.win.empty()) return Rgb(0.0f);
  int m = 0;
  const unsigned lo8 = unsigned(tw.win.lo), width8 = unsigned(tw.win.hi - tw.win.lo);
  for (int i = 0; i < nc; ++i) {  // branch-free compaction, as twoPassImpl
    kept_[size_t(m)] = idx[i];
    m += int(unsigned(bins_[size_t(i)]) - lo8 <= width8);
  }
  const float window = float(tw.win.hi + 1 - tw.win.lo) * tq.binWidth;
  const float volume = float(double((4.0f / 3.0f) * kPi * r2 * std::sqrt(r2) * window) / tw.c);
  if (report)
    *report = {knn_.count, m, r2, tq.binStart(tw.win.lo), tq.binStart(tw.win.hi + 1), volume};
  return sumOver(kept_.data(), m, wo, phase) * (1.0f / volume);
}

template <class Phase>
Rgb VolumeGatherer::fixedImpl(Vec3f x, Vec3f wo, float t, const Phase& phase, VolumeReport* report) {
  const photon::PhotonStore& s = tree_->store();
  const photon::TimeQuantiser& tq = s.time();
  const float r = opt_.fixedRadius, h = opt_.fixedHalfWindow;
  const float lo = std::max(t - h, tq.t0), hi = std::min(t + h, tq.t1);
  if (report) *report = VolumeReport{};
  if (!(hi > lo) || !(r > 0.0f)) return Rgb(0.0f);
  // Each photon weighs the part of its bin inside the window (fixed_kernel.h).
  const float ua = (lo - tq.t0) * tq.invBinWidth, ub = (hi - tq.t0) * tq.invBinWidth;
  const int qa = std::max(0, int(std::floor(ua))), qb = std::min(photon::kTimeBins - 1, int(std::floor(ub)));
  float binWeight[photon::kTimeBins];
  for (int q = qa; q <= qb; ++q) binWeight[q] = std::max(0.0f, std::min(float(q + 1), ub) - std::max(float(q), ua));
  const int found = tree_->range(x, r * r, range_);
  const uint32_t* idx = range_.index();
  const uint16_t* flags = s.flags();
  const uint16_t* dirs = s.directions();
  const uint32_t* energies = s.energies();
  const unsigned qa8 = unsigned(qa), width8 = unsigned(qb - qa);
  Rgb sum(0.0f);
  int used = 0;
  for (int i = 0; i < found; ++i) {
    uint32_t p = idx[i];
    unsigned q = flags[p] & photon::kTimeMask;
    if (q - qa8 > width8) continue;
    sum += photon::decodeRgbe(energies[p]) * (phase(dot(wo, photon::decodeDirection(dirs[p]))) * binWeight[q]);
    ++used;
  }
  const float volume = (4.0f / 3.0f) * kPi * r * r * r * (hi - lo);
  if (report) *report = {found, used, r * r, lo, hi, volume};
  return sum * (1.0f / volume);
}

template <class Phase, class Tr>
Rgb VolumeGatherer::march(const Segment& seg, float t, const Phase& phase, const Tr& tr, int steps, Rng& rng) {
  if (steps <= 0 || !(seg.s1 > seg.s0)) return Rgb(0.0f);
  const float ds = (seg.s1 - seg.s0) / float(steps);
  const Vec3f wo = -seg.d;
  Rgb sum(0.0f);
  for (int j = 0; j < steps; ++j) {
    float sp = seg.s0 + (float(j) + rng.uniform()) * ds;
    sum += tr(sp) * scatterDensity(seg.o + seg.d * sp, wo, t, phase);
  }
  return sum * ds;
}

}  // namespace tdpm::estimate
