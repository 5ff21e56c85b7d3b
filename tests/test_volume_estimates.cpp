// tests/test_volume_estimates.cpp — estimate/volume_estimators.h and
// photon/volume_beam_map.h on synthetic volume photons of known density.
//
// Photons of total energy E over the shutter [0, 1], each E / n, are
// scattered in a region at times of density f(t); then the scattered power
// density is sigma_s L_i = pbar E f(t) / volume (pbar the phase function's
// mean over the photons' directions: 1/(4 pi) for isotropic ones, p(w . w0)
// when all came from w0), and along a segment of length D in a homogeneous
// medium L = density (1 - exp(-sigma_t D)) / sigma_t. Sets: uniform in a
// box and in time; uniform in the box with a ramp in time; a ball moving
// through the box during the shutter. Every estimate is checked as the
// ratio of its sum over many segments to the truth's sum (fixed seeds);
// the bounds are 2.5-6%: a few times the spread of these ratios between
// photon sets (measured over 6 seeds: docs/media-estimates.md).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "core/rng.h"
#include "estimate/estimators.h"
#include "estimate/volume_estimators.h"
#include "photon/store.h"
#include "photon/volume_beam_map.h"
#include "render/progressive.h"

using namespace tdpm;
using namespace tdpm::estimate;
using photon::BeamBuildOptions;
using photon::BeamQuery;
using photon::PhotonStore;
using photon::VolumeBeamMap;

namespace {

constexpr float kSigmaT = 0.8f;  // per unit length, grey
const HomogeneousMedium kFog{Rgb(0.5f), Rgb(kSigmaT), 0.0f};

Vec3f uniformSphere(Rng& rng) {
  float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
  float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Time of density 1 + a (2t - 1) on [0, 1] (inverse CDF).
float rampTime(float a, float xi) {
  if (std::fabs(a) < 1e-6f) return xi;
  return (-(1.0f - a) + std::sqrt((1.0f - a) * (1.0f - a) + 4.0f * a * xi)) / (2.0f * a);
}

// n photons uniform in [0, 1]^3, energy E = 1 in all, directions isotropic
// or all `wi` (when non-zero), times from `timeOf(rng)`.
PhotonStore boxPhotons(int n, uint64_t seed, Vec3f wi, const std::function<float(Rng&)>& timeOf) {
  Rng rng(seed);
  PhotonStore s(0.0f, 1.0f);
  s.reserve(size_t(n));
  const bool iso = wi.x == 0.0f && wi.y == 0.0f && wi.z == 0.0f;
  for (int i = 0; i < n; ++i) {
    Vec3f p(rng.uniform(), rng.uniform(), rng.uniform());
    Vec3f d = iso ? uniformSphere(rng) : wi;
    s.add(p, Rgb(1.0f / float(n)), d, timeOf(rng));
  }
  s.shrinkToFit();
  return s;
}

// Blob: a ball of radius kBlobR centred at (0.25 + 0.5 t, 0.5, 0.5).
constexpr float kBlobR = 0.2f;
Vec3f blobCentre(float t) { return {0.25f + 0.5f * t, 0.5f, 0.5f}; }
PhotonStore blobPhotons(int n, uint64_t seed) {
  Rng rng(seed);
  PhotonStore s(0.0f, 1.0f);
  s.reserve(size_t(n));
  for (int i = 0; i < n; ++i) {
    float t = rng.uniform();
    Vec3f q;
    do q = Vec3f(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1);
    while (dot(q, q) > 1.0f);
    s.add(blobCentre(t) + q * kBlobR, Rgb(1.0f / float(n)), uniformSphere(rng), t);
  }
  s.shrinkToFit();
  return s;
}

// Random segments between points of [0.2, 0.8]^3 (kernels stay inside the box).
std::vector<Segment> innerSegments(int count, uint64_t seed) {
  Rng rng(seed);
  std::vector<Segment> out;
  while (int(out.size()) < count) {
    Vec3f a(0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform());
    Vec3f b(0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform());
    float len = std::sqrt(dot(b - a, b - a));
    if (len < 0.2f) continue;
    out.push_back({a, (b - a) * (1.0f / len), 0.0f, len});
  }
  return out;
}

float transmittedLength(float len) { return (1.0f - std::exp(-kSigmaT * len)) / kSigmaT; }

// Sums over segments of the truth, the march, the beam and the standard forms.
struct Sums {
  double truth = 0, march = 0, beam = 0, marchStd = 0, beamStd = 0;
};

struct Estimators {
  VolumeBeamMap beam, beamStd;
  PhotonStore storeStd;  // a copy for the standard beam map (builds reorder)
  VolumeOptions time, standard;
  Estimators(PhotonStore& s, int beamK, float beamF, int ks, float f) : storeStd(s) {
    BeamBuildOptions bo;
    bo.ks = beamK;
    bo.fraction = beamF;
    beam = VolumeBeamMap::build(s, bo);
    bo.kind = BeamBuildOptions::Kind::Standard;
    bo.ks = 64;  // the whole shutter's photons: k = 64 is plenty, and cheaper
    beamStd = VolumeBeamMap::build(storeStd, bo);
    time.ks = ks;
    time.fraction = f;
    standard.method = VolumeMethod::Standard;
    standard.k = ks / 2;
  }
  // truthDensity(seg): the truth of the segment's L.
  Sums run(const std::vector<Segment>& segs, float t, const HgPhase& phase,
           const std::function<double(const Segment&)>& truthOf, int steps = 24) {
    VolumeGatherer g(beam.tree(), time), gs(beamStd.tree(), standard);
    BeamQuery q;
    Rng rng(77);
    Sums out;
    for (const Segment& seg : segs) {
      HomogeneousTransmittance tr{Rgb(kSigmaT), seg.s0};
      out.truth += truthOf(seg);
      out.march += g.march(seg, t, phase, tr, steps, rng).g;
      out.marchStd += gs.march(seg, t, phase, tr, steps, rng).g;
      out.beam += beamRadiance(beam, q, seg, t, phase, tr).g;
      out.beamStd += beamRadiance(beamStd, q, seg, t, phase, tr).g;
    }
    return out;
  }
};

}  // namespace

TEST_CASE("volume beam map: the walk finds exactly the discs a brute-force scan finds") {
  PhotonStore s = boxPhotons(20000, 3, Vec3f(0.0f), [](Rng& r) { return r.uniform(); });
  VolumeBeamMap m = VolumeBeamMap::build(s, {});
  BeamQuery q;
  Rng rng(5);
  int total = 0;
  for (int k = 0; k < 40; ++k) {
    Vec3f a(rng.uniform(), rng.uniform(), rng.uniform()), b(rng.uniform(), rng.uniform(), rng.uniform());
    if (k % 8 == 0) b = Vec3f(a.x, b.y, a.z);  // axis-parallel: the slab test's d = 0 path
    float len = std::sqrt(dot(b - a, b - a));
    Segment seg{a, (b - a) * (1.0f / len), 0.05f, len};
    std::vector<uint32_t> got, want;
    m.crossing(seg, q, [&](uint32_t i, float, float) { got.push_back(i); });
    for (uint32_t i = 0; i < m.size(); ++i) {
      Vec3f v = s.position(i) - seg.o;
      float sp = dot(v, seg.d);
      Vec3f c(v.y * seg.d.z - v.z * seg.d.y, v.z * seg.d.x - v.x * seg.d.z, v.x * seg.d.y - v.y * seg.d.x);
      float r = m.radius(i);
      if (dot(c, c) < r * r && sp >= seg.s0 && sp <= seg.s1) want.push_back(i);
    }
    std::sort(got.begin(), got.end());
    CHECK(got == want);
    total += int(want.size());
  }
  CHECK(total > 1000);  // the segments do cross discs
}

TEST_CASE("volume beam map: <= 24 bytes a photon with its tree, radius and time width; codes round up") {
  PhotonStore s = boxPhotons(50000, 4, Vec3f(0.0f), [](Rng& r) { return r.uniform(); });
  PhotonStore copy = s;
  VolumeBeamMap m = VolumeBeamMap::build(s, {});
  MESSAGE("bytes per volume photon: " << m.bytesPerPhoton());
  CHECK(m.bytesPerPhoton() <= 24.0);
  CHECK(m.bytesPerPhoton() >= 23.0);  // 20 B store + 3 code bytes, nothing hidden
  // The disc of every photon is at least its k-NN radius (brute force on a few).
  photon::KdTree plain = photon::KdTree::build(copy);
  photon::KnnQuery kq(64);
  int wholeShutter = 0;
  for (size_t i = 0; i < m.size(); i += 997) {
    plain.knn(s.position(i), 64, std::numeric_limits<float>::infinity(), kq);
    float r = std::sqrt(kq.radius2);
    CHECK(m.radius(i) >= r * 0.99999f);
    CHECK(m.radius(i) <= r * 1.0445f);
    wholeShutter += int(m.windowCode(i) == photon::kWholeShutter);
  }
  CHECK(wholeShutter == 0);  // 32 of 63 kept in time: never the whole shutter here
  CHECK(BeamBuildOptions{}.minTimePhotons == kMinTimePhotons);
  // Pass 0's kernel for progressive passes: the medians of the photons'
  // radii (rounded up by at most 4.4%) and half-widths. Against the median
  // k-NN radius of a sample (photons near the box's faces have larger balls,
  // so it is ~5% above the Poisson median of the 64th nearest, (63.67 /
  // (4/3 pi n))^(1/3)); the window holds 32 of the 63 others, about half
  // the shutter: h ~ 0.25.
  VolumeKernel pilot = pilotKernel(m);
  std::vector<float> sample;
  for (size_t i = 0; i < m.size(); i += 97) {
    plain.knn(s.position(i), 64, std::numeric_limits<float>::infinity(), kq);
    sample.push_back(std::sqrt(kq.radius2));
  }
  std::nth_element(sample.begin(), sample.begin() + sample.size() / 2, sample.end());
  const double rMedian = sample[sample.size() / 2];
  MESSAGE("pilot r " << pilot.radius << " (sample median " << rMedian << "), h " << pilot.halfWindow);
  CHECK(pilot.radius / rMedian > 0.99);
  CHECK(pilot.radius / rMedian < 1.05);
  CHECK(pilot.halfWindow > 0.2f);
  CHECK(pilot.halfWindow < 0.3f);
}

// A progressive pass's shrink (BeamBuildOptions::radiusScale/windowScale,
// render/progressive.cpp volumePassBeam): every photon's own disc x window
// volume r^2 (2w + 1) is the k-NN map's times rs^2 ws, up to the radius
// codes' rounding (each r rounds up by at most 4.45%, so r^2 within 1.0445^2),
// and the windows really narrow; the Standard map's whole-shutter photons
// take r x rs. This is what tells the passes' shrink from none (the render
// test in test_media_progressive.cpp cannot at 8 passes).
TEST_CASE("volume beam map: a pass's scale shrinks every photon's own disc x window volume by rs^2 ws") {
  const float rs = 0.7f, ws = 0.6f;
  for (auto kind : {BeamBuildOptions::Kind::Time, BeamBuildOptions::Kind::Standard}) {
    PhotonStore a = boxPhotons(20000, 6, Vec3f(0.0f), [](Rng& r) { return r.uniform(); }), b = a;
    BeamBuildOptions bo;
    bo.kind = kind;
    VolumeBeamMap m1 = VolumeBeamMap::build(a, bo);
    bo.radiusScale = rs;
    bo.windowScale = kind == BeamBuildOptions::Kind::Time ? ws : 1.0f;
    VolumeBeamMap m2 = VolumeBeamMap::build(b, bo);
    REQUIRE(m1.size() == m2.size());
    const double want = kind == BeamBuildOptions::Kind::Time ? double(rs) * rs * ws : double(rs) * rs;
    double sumRatio = 0.0, w1 = 0.0, w2 = 0.0;
    int off = 0;
    for (size_t i = 0; i < m1.size(); ++i) {
      REQUIRE(a.position(i).x == b.position(i).x);  // the same photon order
      auto vol = [](const VolumeBeamMap& m, size_t j) {
        const double r = m.radius(j);
        return m.windowCode(j) == photon::kWholeShutter ? r * r : r * r * (2.0 * m.windowCode(j) + 1.0);
      };
      const double ratio = vol(m2, i) / vol(m1, i) / want;
      sumRatio += ratio;
      off += int(ratio < 1.0 / (1.0445 * 1.0445) || ratio > 1.0445 * 1.0445);
      if (kind == BeamBuildOptions::Kind::Time) {
        CHECK(m1.windowCode(i) != photon::kWholeShutter);
        w1 += m1.windowCode(i) + 0.5;
        w2 += m2.windowCode(i) + 0.5;
      } else {
        CHECK(m2.windowCode(i) == photon::kWholeShutter);
      }
    }
    MESSAGE("mean volume ratio over the wanted " << sumRatio / double(m1.size()) << ", mean half-width bins " << w1 / m1.size()
                                                 << " -> " << w2 / m2.size());
    CHECK(off == 0);
    CHECK(std::fabs(sumRatio / double(m1.size()) - 1.0) < 0.03);
    if (kind == BeamBuildOptions::Kind::Time) CHECK(w2 < 0.7 * w1);  // ws = 0.6 of the half-widths, rounded
  }
}

TEST_CASE("beam estimate: a photon's window is 2w + 1 whole bins, half-open, reflected at the shutter ends") {
  // One photon per map, all with w = 2 (bins [q - 2, q + 2]); a segment
  // through it; the estimate is E p T / (pi r^2) x weight / binWidth.
  auto one = [](float time, int w, float tq) {
    PhotonStore s(0.0f, 1.0f);
    s.add(Vec3f(0.5f), Rgb(1.0f), Vec3f(0, 0, 1), time);
    BeamBuildOptions bo;
    bo.kind = BeamBuildOptions::Kind::Fixed;
    bo.fixedRadius = 0.1f;
    bo.fixedWindowCode = w;
    VolumeBeamMap m = VolumeBeamMap::build(s, bo);
    BeamQuery q;
    Segment seg{Vec3f(0.5f, 0.0f, 0.5f), Vec3f(0, 1, 0), 0.0f, 1.0f};
    Rgb L = beamRadiance(m, q, seg, tq, HgPhase{0.0f}, [](float) { return Rgb(1.0f); });
    return double(L.g) * m.radius(0) * m.radius(0) * kPi / media::kInv4Pi / 256.0;  // the weight
  };
  const float bin = 1.0f / 256.0f;
  // Bin 100, w = 2: [98, 103) in bin units, weight 1/5.
  CHECK(one(100.5f * bin, 2, 98.0f * bin) == doctest::Approx(0.2).epsilon(1e-5));
  CHECK(one(100.5f * bin, 2, 102.99f * bin) == doctest::Approx(0.2).epsilon(1e-5));
  CHECK(one(100.5f * bin, 2, 103.0f * bin) == 0.0);
  CHECK(one(100.5f * bin, 2, 97.99f * bin) == 0.0);
  // Bin 1, w = 3: [-2, 5) folds [-2, 0) onto [0, 2): weight 2/7 there, 1/7 on [2, 5).
  CHECK(one(1.5f * bin, 3, 0.0f) == doctest::Approx(2.0 / 7.0).epsilon(1e-5));
  CHECK(one(1.5f * bin, 3, 1.99f * bin) == doctest::Approx(2.0 / 7.0).epsilon(1e-5));
  CHECK(one(1.5f * bin, 3, 2.0f * bin) == doctest::Approx(1.0 / 7.0).epsilon(1e-5));
  // Bin 254, w = 3: [251, 258) folds [256, 258) onto [254, 256].
  CHECK(one(254.5f * bin, 3, 1.0f) == doctest::Approx(2.0 / 7.0).epsilon(1e-5));
  CHECK(one(254.5f * bin, 3, 253.99f * bin) == doctest::Approx(1.0 / 7.0).epsilon(1e-5));
  // Whole shutter: 1/256 a bin anywhere.
  CHECK(one(0.3f, photon::kWholeShutter, 0.9f) == doctest::Approx(1.0 / 256.0).epsilon(1e-5));
}

TEST_CASE("volume estimates: uniform box and shutter, isotropic phase: march, beam and standard at the truth") {
  for (int n : {30000, 100000}) {
    PhotonStore s = boxPhotons(n, 11 + uint64_t(n), Vec3f(0.0f), [](Rng& r) { return r.uniform(); });
    Estimators e(s, 200, 0.5f, 200, 0.5f);
    auto segs = innerSegments(150, 21);
    const HgPhase iso{0.0f};
    for (float t : {0.01f, 0.3f, 0.5f, 0.99f}) {
      Sums r = e.run(segs, t, iso, [](const Segment& g) { return media::kInv4Pi * transmittedLength(g.s1 - g.s0); });
      MESSAGE("n " << n << " t " << t << ": march " << r.march / r.truth << " beam " << r.beam / r.truth
                   << " standard march " << r.marchStd / r.truth << " beam " << r.beamStd / r.truth);
      CHECK(std::fabs(r.march / r.truth - 1.0) < 0.025);
      // The beam on one photon set: about 1.5% noise inside the shutter
      // (6 seeds at n = 60000: spread 1.4%), and about twice that at its
      // ends, where reflected windows give half as many distinct photons
      // twice the weight.
      const double bound = (t < 0.05f || t > 0.95f) ? 0.06 : 0.035;
      CHECK(std::fabs(r.beam / r.truth - 1.0) < bound);
      CHECK(std::fabs(r.beam / r.march - 1.0) < bound);
      CHECK(std::fabs(r.marchStd / r.truth - 1.0) < 0.025);
      CHECK(std::fabs(r.beamStd / r.truth - 1.0) < 0.025);
    }
  }
}

TEST_CASE("volume estimates: Henyey-Greenstein g = 0.6, photons all from one direction") {
  const Vec3f w0 = normalize(Vec3f(0.3f, -0.2f, 1.0f));
  PhotonStore s = boxPhotons(60000, 12, w0, [](Rng& r) { return r.uniform(); });
  Estimators e(s, 200, 0.5f, 200, 0.5f);
  auto segs = innerSegments(150, 22);
  const HgPhase hg{0.6f};
  Sums r = e.run(segs, 0.4f, hg, [&](const Segment& g) {
    return media::henyeyGreenstein(dot(-g.d, w0), 0.6f) * transmittedLength(g.s1 - g.s0);
  });
  MESSAGE("HG: march " << r.march / r.truth << " beam " << r.beam / r.truth);
  CHECK(std::fabs(r.march / r.truth - 1.0) < 0.025);
  CHECK(std::fabs(r.beam / r.truth - 1.0) < 0.025);
  CHECK(std::fabs(r.marchStd / r.truth - 1.0) < 0.025);
  CHECK(std::fabs(r.beamStd / r.truth - 1.0) < 0.025);
}

TEST_CASE("volume estimates: a ramp in time; the standard forms off by 1/f(t) as predicted") {
  const float a = 0.8f;  // f(t) = 1 + a (2t - 1): 0.2 at shutter open, 1.8 at close
  PhotonStore s = boxPhotons(100000, 13, Vec3f(0.0f), [&](Rng& r) { return rampTime(a, r.uniform()); });
  // f = 0.2: windows of about +-0.1 stay clear of the shutter ends at these
  // times, so they are symmetric and a linear ramp gives no bias (a window
  // cut at an end is biased to first order in the slope: docs).
  Estimators e(s, 200, 0.15f, 200, 0.2f);
  auto segs = innerSegments(150, 23);
  for (float t : {0.25f, 0.5f, 0.75f}) {
    const double f = 1.0 + a * (2.0 * t - 1.0);
    Sums r = e.run(segs, t, HgPhase{0.0f},
                   [&](const Segment& g) { return f * media::kInv4Pi * transmittedLength(g.s1 - g.s0); });
    MESSAGE("ramp t " << t << ": march " << r.march / r.truth << " beam " << r.beam / r.truth << " standard "
                      << r.marchStd / r.truth << " (predicted " << 1.0 / f << ")");
    CHECK(std::fabs(r.march / r.truth - 1.0) < 0.025);
    // The beam's short windows (30 of 199 neighbours) hold few photons at
    // any one time: its noise on these fixed photons is a few percent.
    CHECK(std::fabs(r.beam / r.truth - 1.0) < 0.05);
    CHECK(std::fabs(r.beam / r.march - 1.0) < 0.06);
    CHECK(std::fabs(r.marchStd / r.truth * f - 1.0) < 0.025);
    CHECK(std::fabs(r.beamStd / r.truth * f - 1.0) < 0.025);
  }
}

TEST_CASE("volume estimates: a ball moving through the medium; standard smears it by the predicted amount") {
  PhotonStore s = blobPhotons(150000, 14);
  // A short time window (f = 0.15): the two-pass window's own bias is
  // second order in how far the ball moves inside it.
  Estimators e(s, 200, 0.1f, 400, 0.15f);
  const double rho = 1.0 / ((4.0 / 3.0) * kPi * kBlobR * kBlobR * kBlobR);  // E / (volume ts)
  for (float t : {0.5f, 0.3f}) {
    // Segments along y past the ball's centre at time t, offset by (dx, dz)
    // (uniform in a disc of radius 0.12), each through different photons.
    std::vector<Segment> segs;
    Rng rng(uint64_t(100 * t));
    while (segs.size() < 80) {
      float dx = 0.24f * rng.uniform() - 0.12f, dz = 0.24f * rng.uniform() - 0.12f;
      if (dx * dx + dz * dz > 0.12f * 0.12f) continue;
      segs.push_back({Vec3f(blobCentre(t).x + dx, 0.2f, 0.5f + dz), Vec3f(0, 1, 0), 0.0f, 0.6f});
    }
    const double cx = blobCentre(t).x;
    // Truth: the chord through the ball at t (centre at s = 0.3); standard:
    // the shutter average of the density at each point (quadrature): the
    // ball holds p = (cx + dx, y, z) at t' iff (dx - 0.5 (t' - t))^2 <
    // R^2 - dy^2 - dz^2 =: r2, i.e. t' - t in 2 (dx -+ sqrt(r2)).
    auto truthOf = [&](const Segment& g) {
      double dx = g.o.x - cx, dz = g.o.z - 0.5;
      double half = std::sqrt(std::max(0.0, double(kBlobR) * kBlobR - dx * dx - dz * dz));
      double a = 0.3 - half, b = 0.3 + half;
      return rho * media::kInv4Pi * (std::exp(-kSigmaT * a) - std::exp(-kSigmaT * b)) / kSigmaT;
    };
    double predictedStd = 0.0, truth = 0.0;
    for (const Segment& g : segs) {
      truth += truthOf(g);
      const int m = 2000;
      const double dx = g.o.x - cx, dz = g.o.z - 0.5;
      for (int j = 0; j < m; ++j) {
        double sp = (j + 0.5) * 0.6 / m, dy = g.o.y + sp - 0.5;
        double r2 = double(kBlobR) * kBlobR - dy * dy - dz * dz;
        if (r2 <= 0) continue;
        double lo = 2.0 * (dx - std::sqrt(r2)), hi = 2.0 * (dx + std::sqrt(r2));
        double cover = std::max(0.0, std::min(1.0 - t, hi) - std::max(-double(t), lo));
        predictedStd += rho * media::kInv4Pi * cover * std::exp(-kSigmaT * sp) * (0.6 / m);
      }
    }
    Sums r = e.run(segs, t, HgPhase{0.0f}, truthOf, 48);
    MESSAGE("blob t " << t << ": march " << r.march / r.truth << " beam " << r.beam / r.truth << " standard march "
                      << r.marchStd / r.truth << " beam " << r.beamStd / r.truth << " (predicted "
                      << predictedStd / truth << ")");
    CHECK(std::fabs(r.march / r.truth - 1.0) < 0.03);
    CHECK(std::fabs(r.beam / r.truth - 1.0) < 0.05);  // short windows: see the ramp
    CHECK(std::fabs(r.beam / r.march - 1.0) < 0.06);
    CHECK(predictedStd / truth < 0.8);  // the smear is large ...
    CHECK(std::fabs(r.marchStd / predictedStd - 1.0) < 0.03);  // ... and the standard forms show it
    CHECK(std::fabs(r.beamStd / predictedStd - 1.0) < 0.03);
  }
}

TEST_CASE("volume progressive: the kernel schedule is the surface one; pass kernels keep the volume") {
  for (int pass : {0, 1, 5, 40})
    for (double alpha : {0.5, 4.0 / 7.0})
      for (int dims : {3, 4}) CHECK(volumeKernelScale(pass, alpha, dims) == kernelScale(pass, alpha, dims));
  const float bw = 1.0f / 256.0f;
  const VolumeKernel first{0.05f, 0.1f};
  for (int pass : {0, 3, 30, 3000}) {
    BeamPassKernel b = beamKernelForPass(first, pass, bw);
    double s = volumeKernelScale(pass, kAlphaBeam, 3);
    double want = double(first.radius) * first.radius * first.halfWindow * s * s * s;
    CHECK(double(b.radius) * b.radius * b.halfWindow == doctest::Approx(want).epsilon(1e-5));
    CHECK(b.halfWindow == doctest::Approx((2 * b.windowCode + 1) * 0.5 * bw).epsilon(1e-6));
    VolumeKernel p = pointKernelForPass(first, pass, bw);
    double s4 = volumeKernelScale(pass, kAlphaVolumePoint, 4);
    double want4 = std::pow(double(first.radius) * s4, 3) * first.halfWindow * s4;
    CHECK(std::pow(double(p.radius), 3) * p.halfWindow == doctest::Approx(want4).epsilon(1e-5));
    CHECK(p.halfWindow >= bw * 0.9999f);
  }
}

TEST_CASE("volume progressive: the mean of passes converges (beam and point), error falls as a power of passes") {
  // Time density f(t) = ((t - 1/2)^2 + c) / (1/12 + c): curved at t = 1/2,
  // where every fixed window overestimates by h^2/3 / c in relative terms.
  const double c = 0.02, fmax = (0.25 + c) / (1.0 / 12.0 + c);
  auto timeOf = [&](Rng& r) {
    for (;;) {
      float t = r.uniform();
      if (r.uniform() * fmax <= ((t - 0.5) * (t - 0.5) + c) / (1.0 / 12.0 + c)) return t;
    }
  };
  const double f05 = c / (1.0 / 12.0 + c);
  const float bw = 1.0f / 256.0f;
  auto segs = innerSegments(150, 31);
  double truth = 0.0;
  for (const Segment& g : segs) truth += f05 * media::kInv4Pi * transmittedLength(g.s1 - g.s0);
  const VolumeKernel first{0.08f, 0.15f};
  const int passes = 32;
  double sumBeam = 0.0, sumPoint = 0.0;
  std::vector<double> x, errBeam, errPoint;
  Rng rng(9);
  BeamQuery q;
  for (int pass = 0; pass < passes; ++pass) {
    PhotonStore s = boxPhotons(20000, 1000 + uint64_t(pass), Vec3f(0.0f), timeOf);
    BeamPassKernel bk = beamKernelForPass(first, pass, bw);
    BeamBuildOptions bo;
    bo.kind = BeamBuildOptions::Kind::Fixed;
    bo.fixedRadius = bk.radius;
    bo.fixedWindowCode = bk.windowCode;
    VolumeBeamMap m = VolumeBeamMap::build(s, bo);
    VolumeOptions po;
    po.method = VolumeMethod::Fixed;
    VolumeKernel pk = pointKernelForPass(first, pass, bw);
    po.fixedRadius = pk.radius;
    po.fixedHalfWindow = pk.halfWindow;
    VolumeGatherer g(m.tree(), po);
    for (const Segment& seg : segs) {
      HomogeneousTransmittance tr{Rgb(kSigmaT), seg.s0};
      sumBeam += beamRadiance(m, q, seg, 0.5f, HgPhase{0.0f}, tr).g;
      sumPoint += g.march(seg, 0.5f, HgPhase{0.0f}, tr, 8, rng).g;
    }
    const int n = pass + 1;
    if ((n & (n - 1)) == 0) {  // 1, 2, 4, ..., 32 passes
      x.push_back(std::log(double(n)));
      errBeam.push_back(std::log(std::fabs(sumBeam / n / truth - 1.0)));
      errPoint.push_back(std::log(std::fabs(sumPoint / n / truth - 1.0)));
      MESSAGE("passes " << n << ": beam " << sumBeam / n / truth << " point " << sumPoint / n / truth);
    }
  }
  auto slope = [](const std::vector<double>& xs, const std::vector<double>& ys) {
    double mx = 0, my = 0;
    for (size_t i = 0; i < xs.size(); ++i) mx += xs[i], my += ys[i];
    mx /= double(xs.size()), my /= double(xs.size());
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < xs.size(); ++i) sxy += (xs[i] - mx) * (ys[i] - my), sxx += (xs[i] - mx) * (xs[i] - mx);
    return sxy / sxx;
  };
  // Bias of the mean of N passes ~ N^(2(alpha - 1)/d): beam -2/7, point -1/4.
  MESSAGE("log-log slopes: beam " << slope(x, errBeam) << " point " << slope(x, errPoint));
  CHECK(slope(x, errBeam) < -0.15);
  CHECK(slope(x, errPoint) < -0.12);
  CHECK(std::exp(errBeam.back()) < 0.5 * std::exp(errBeam.front()));
  CHECK(std::exp(errPoint.back()) < 0.6 * std::exp(errPoint.front()));
}

