// photon/volume_beam_map.cpp — building the beam map: the kd-tree, every
// photon's kernel (radius and time window codes) and the subtree bounds.
#include "photon/volume_beam_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "photon/temporal_select.h"  // keptCount

namespace tdpm::photon {

namespace {

// The photon's own window (header): the nearest fraction in time of its
// nc spatial neighbours (bins), with the shutter ends as mirrors: every
// neighbour also stands at its images -1 - b and 511 - b, so the window is
// symmetric about the photon's bin q by construction and sees as many
// photons near an end as in the middle (the images of a process uniform over
// the shutter are uniform on the line). w = the keep-th smallest distance in
// whole bins; ties are inside. Returns w, or kWholeShutter.
uint8_t windowCodeOf(const uint8_t* bins, int nc, int q, const BeamBuildOptions& opt, float maxDistBins,
                     std::vector<int>& dist) {
  const int keep = std::max(keptCount(opt.fraction, nc), opt.minTimePhotons);
  if (keep >= nc) {
    if (!std::isfinite(maxDistBins)) return kWholeShutter;  // the known window: all of it
    return uint8_t(std::min(int(maxDistBins), kMaxWindowCode));
  }
  dist.clear();
  for (int j = 0; j < nc; ++j) {
    const int b = bins[j];
    dist.push_back(std::abs(b - q));
    dist.push_back(b + q + 1);    // image below shutter open
    dist.push_back(511 - b - q);  // image above shutter close
  }
  std::nth_element(dist.begin(), dist.begin() + (keep - 1), dist.end());
  int w = dist[size_t(keep - 1)];
  if (std::isfinite(maxDistBins)) w = std::min(w, std::max(0, int(maxDistBins)));
  return w > kMaxWindowCode ? kWholeShutter : uint8_t(w);
}

}  // namespace

VolumeBeamMap VolumeBeamMap::build(PhotonStore& store, const BeamBuildOptions& opt) {
  VolumeBeamMap m;
  m.tree_ = KdTree::build(store);
  const size_t n = store.size();
  m.radiusCode_.assign(n, 0);
  m.windowCode_.assign(n, kWholeShutter);
  m.bound_.assign(n, 0);
  if (n == 0) return m;
  m.setBounds();
  std::vector<float> radius(n, opt.fixedRadius);
  if (opt.kind == BeamBuildOptions::Kind::Fixed) {
    std::fill(m.windowCode_.begin(), m.windowCode_.end(), uint8_t(opt.fixedWindowCode));
  } else {
    const bool time = opt.kind == BeamBuildOptions::Kind::Time;
    const int k = std::max(2, opt.ks);
    const float maxDistBins = opt.maxTimeDistance * store.time().invBinWidth;
    const uint16_t* flags = store.flags();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& range) {
      KnnQuery q(k);
      std::vector<uint8_t> bins(static_cast<size_t>(k));
      std::vector<int> dist;
      dist.reserve(3 * size_t(k));
      for (size_t i = range.begin(); i != range.end(); ++i) {
        int found = m.tree_.knn(store.position(i), k, std::numeric_limits<float>::infinity(), q);
        // The k-th (heap root when full; else the farthest) closes the ball.
        const uint32_t* idx = q.index();
        const float* d2 = q.dist2();
        int far = 0;
        for (int j = 1; j < found; ++j)
          if (d2[j] > d2[far]) far = j;
        radius[i] = std::sqrt(d2[far]);
        if (!time) continue;
        int nc = 0;
        for (int j = 0; j < found; ++j)
          if (j != far) bins[size_t(nc++)] = uint8_t(flags[idx[j]] & kTimeMask);
        m.windowCode_[i] = nc == 0 ? kWholeShutter : windowCodeOf(bins.data(), nc, store.timeBin(i), opt, maxDistBins, dist);
      }
    });
  }
  if (opt.kind != BeamBuildOptions::Kind::Fixed && (opt.radiusScale != 1.0f || opt.windowScale != 1.0f))
    m.scaleKernels(radius, opt.radiusScale, opt.windowScale);
  m.setRadii(radius);
  return m;
}

// A progressive pass's shrink of every photon's own kernel (header,
// BeamBuildOptions::radiusScale): the disc-window volume r^2 (2w + 1) is
// scaled by rs^2 ws exactly, whatever the rounding of w to whole bins.
void VolumeBeamMap::scaleKernels(std::vector<float>& r, float rs, float ws) {
  const float wholeShutter = rs * std::sqrt(ws);
  for (size_t i = 0; i < r.size(); ++i) {
    if (windowCode_[i] == kWholeShutter) {
      r[i] *= wholeShutter;
      continue;
    }
    const double hb = (double(windowCode_[i]) + 0.5) * double(ws);  // half-width in bins
    const long w = std::min(long(kMaxWindowCode), std::max(0L, std::lround(hb - 0.5)));
    windowCode_[i] = uint8_t(w);
    r[i] = float(double(r[i]) * rs * std::sqrt(2.0 * hb / (2.0 * double(w) + 1.0)));
  }
}

// Radius codes (rounded up; header), their tables, and the subtree bounds.
void VolumeBeamMap::setRadii(const std::vector<float>& r) {
  const size_t n = r.size();
  float rMax = 0.0f;
  for (float v : r) rMax = std::max(rMax, v);
  if (!(rMax > 0.0f)) rMax = 1e-6f;  // all coincident: a tiny but finite disc
  const double base = double(rMax) * std::exp2(-255.0 / 16.0);
  for (int c = 0; c < 256; ++c) {
    double rc = c == 255 ? double(rMax) : base * std::exp2(double(c) / 16.0);
    radiusOf_[c] = float(rc);
    radius2Of_[c] = float(rc * rc);
    invArea_[c] = float(1.0 / (3.14159265358979323846 * rc * rc));
  }
  for (size_t i = 0; i < n; ++i) {
    double x = r[i] > 0.0f ? 16.0 * std::log2(double(r[i]) / base) : 0.0;
    int c = std::clamp(int(std::ceil(x)), 0, 255);
    while (c < 255 && radiusOf_[c] < r[i]) ++c;  // never smaller than asked
    radiusCode_[i] = uint8_t(c);
  }
  // Children 2i+1, 2i+2 come after i: one backward sweep.
  for (size_t i = n; i-- > 0;) {
    uint8_t b = radiusCode_[i];
    size_t l = 2 * i + 1;
    if (l < n) b = std::max(b, bound_[l]);
    if (l + 1 < n) b = std::max(b, bound_[l + 1]);
    bound_[i] = b;
  }
}

void VolumeBeamMap::setBounds() {
  const PhotonStore& s = store();
  const float* p[3] = {s.xs(), s.ys(), s.zs()};
  for (int k = 0; k < 3; ++k) {
    lo_[k] = *std::min_element(p[k], p[k] + s.size());
    hi_[k] = *std::max_element(p[k], p[k] + s.size());
  }
}

double VolumeBeamMap::bytesPerPhoton() const {
  if (size() == 0) return 0.0;
  size_t codes = radiusCode_.capacity() + windowCode_.capacity() + bound_.capacity();
  return tree_.bytesPerPhoton() + double(codes) / double(size());
}

}  // namespace tdpm::photon
