// photon/volume_beam_map.h — the volume photon map of the beam radiance
// estimate (Jarosz, Zwicker & Jensen 2008, with time; method.md section 11;
// the estimate itself is in estimate/volume_estimators.h). It owns:
//
//  * the left-balanced kd-tree over the volume photons' PhotonStore
//    (photon/kdtree.h: reorders the store, costs no memory of its own);
//  * per photon, in heap order, three bytes:
//      radius code     its disc radius r_i, log-quantised and rounded up:
//                      r(c) = base 2^(c/16), base = r_max 2^(-255/16), so
//                      the largest radius is exact and every other one at
//                      most 4.4% larger than asked (a larger kernel of the
//                      same normalisation: still unbiased where the density
//                      is uniform; never smaller, so the disc still holds
//                      the photons that defined it);
//      window code     its time half-width in bins, w in [0, 127]: the
//                      window is the 2w + 1 bins centred on its own bin,
//                      reflected at the shutter ends (estimate header);
//                      kWholeShutter: the whole shutter, weight 1/256 a bin
//                      (the standard map, the minimum-count rule, and any
//                      window of 128 bins or more);
//      subtree bound   the largest radius code in the subtree below the
//                      node (the node included): a segment farther than
//                      r(bound) from a subtree's cell crosses none of its
//                      discs, which prunes the walk without a float a node.
//    So a volume photon costs 20 + 3 = 23 bytes with its tree, radius and
//    time width (bytesPerPhoton; the target is 24).
//
// Kernel sizes at build (BeamBuildOptions):
//  * time (default): the two-pass search around the photon itself, as the
//    surface estimate does (estimators.h): its k_s nearest in space (itself
//    included) give r_i = distance of the k_s-th; of the k_s - 1 strictly
//    inside, the fraction f nearest in time (at least kMinTimePhotons; if
//    that is all of them, the whole shutter) give w, with the shutter ends
//    as mirrors (each neighbour counted at its reflected times too, as the
//    estimate reflects the windows): w is the distance in whole bins of the
//    keep-th nearest. A window cut at the shutter end and widened on the
//    other side (the surface two-pass window) would not do here: the photon
//    spreads its energy over its own window, and photons near an end with
//    such wide windows moved light from the ends to the middle (measured:
//    0.70 of the truth at t = 0.01, 1.20 at t = 0.5 on a uniform set).
//  * standard: k nearest in space, every photon the whole shutter.
//  * progressive passes: time or standard as above, each photon's r and w
//    then scaled by the pass's schedule (radiusScale, windowScale);
//  * fixed: every photon the same r and w.
//
// Queries: crossing() walks the tree depth-first with an explicit stack of
// (node, cell) on a per-thread BeamQuery (no allocation, no virtual call per
// node): a child is entered if the segment comes within its subtree bound
// of the child's cell's bounding sphere (segmentNearCell, made before it is
// pushed; the first child entered goes on without a push), and each photon is tested exactly
// (distance from the line < r_i, projection in [s0, s1]). The children of
// the last inner level are leaves: their photons are tested at once with no
// box test (measured on fog-glass-ball, docs/media.md "The beam query's
// cost": leaves were half the nodes walked). The visitor, a template
// parameter, is inlined.
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "math/vec.h"
#include "photon/kdtree.h"
#include "photon/store.h"

namespace tdpm::photon {

constexpr uint8_t kWholeShutter = 255;
constexpr int kMaxWindowCode = 127;  // larger windows are the whole shutter

struct BeamBuildOptions {
  enum class Kind : unsigned char { Time, Standard, Fixed };
  Kind kind = Kind::Time;
  int ks = 64;            // Time: spatial candidates; Standard: k
  float fraction = 0.5f;  // Time: part kept in time
  float maxTimeDistance = std::numeric_limits<float>::infinity();  // Time, seconds
  // Time: fewest photons kept in time (estimate::kMinTimePhotons; photon/
  // does not include estimate/, a test checks they agree).
  int minTimePhotons = 8;
  // Time, Standard (progressive passes): each photon's own k-NN kernel
  // shrunk by the pass's schedule: r *= radiusScale, the window's half-width
  // (w + 1/2 bins) *= windowScale, rounded to whole bins with r corrected so
  // that r^2 (2w + 1) keeps the scaled product; a whole-shutter photon takes
  // all of it in r (r *= radiusScale sqrt(windowScale)). 1, 1: the k-NN map.
  float radiusScale = 1.0f, windowScale = 1.0f;
  float fixedRadius = 0.0f;     // Fixed: r of every photon
  int fixedWindowCode = 0;      // Fixed: w of every photon (or kWholeShutter)
};

// One segment o + s d, s in [s0, s1], d a unit vector.
struct Segment {
  Vec3f o, d;
  float s0 = 0.0f, s1 = 0.0f;
};

class VolumeBeamMap;

// Per-thread traversal stack of a beam query.
class BeamQuery {
 public:
  BeamQuery() { stack_.resize(128); }

 private:
  friend class VolumeBeamMap;
  struct Entry {
    uint32_t node;
    float lo[3], hi[3];
  };
  std::vector<Entry> stack_;  // depth-first: at most ~2 log2 n deep
};

class VolumeBeamMap {
 public:
  VolumeBeamMap() = default;
  // Builds the kd-tree over `store` (reordering it) and every photon's
  // kernel. `store` must outlive the map and not change. Parallel (TBB).
  static VolumeBeamMap build(PhotonStore& store, const BeamBuildOptions& options = {});

  const KdTree& tree() const { return tree_; }
  const PhotonStore& store() const { return tree_.store(); }
  size_t size() const { return radiusCode_.size(); }
  float radius(size_t i) const { return radiusOf_[radiusCode_[i]]; }
  float invDiscArea(size_t i) const { return invArea_[radiusCode_[i]]; }
  uint8_t windowCode(size_t i) const { return windowCode_[i]; }
  const uint8_t* radiusCodes() const { return radiusCode_.data(); }
  const uint8_t* windowCodes() const { return windowCode_.data(); }
  const float* invAreaTable() const { return invArea_; }
  // Heap bytes per photon of the store, the tree and the three code arrays.
  double bytesPerPhoton() const;

  // Calls visit(i, s, dist2) for every photon i whose disc the segment
  // crosses: |(x_i - o) x d|^2 < r_i^2 and s = (x_i - o) . d in [s0, s1].
  template <class Visit>
  void crossing(const Segment& seg, BeamQuery& q, Visit&& visit) const;

 private:
  static bool segmentNearCell(const Segment& seg, const float* lo, const float* hi, float grow);
  void setRadii(const std::vector<float>& r);
  void scaleKernels(std::vector<float>& r, float radiusScale, float windowScale);
  void setBounds();

  KdTree tree_;
  std::vector<uint8_t> radiusCode_, windowCode_, bound_;
  float radiusOf_[256] = {};
  float radius2Of_[256] = {};
  float invArea_[256] = {};
  float lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};  // bounds of all photons
};

// ---------------------------------------------------------------------------

inline bool VolumeBeamMap::segmentNearCell(const Segment& seg, const float* lo, const float* hi, float grow) {
  // The cell's bounding sphere (centre c, half-diagonal h): a photon p of
  // the cell whose disc the segment crosses is within grow of the segment
  // (the foot of its perpendicular lies on it), so c is within grow + h.
  // Where the cell is small against grow (the deep levels, most of the
  // walk) this is tighter than the cell grown by grow on every side (a
  // slab test, which it replaced: 27% fewer photons tested on the bench's
  // uniform set at k = 200, bench/README.md) and costs no division or branch per axis.
  // 1e-5: float rounding stays on the safe side.
  const float cx = 0.5f * (lo[0] + hi[0]) - seg.o.x, cy = 0.5f * (lo[1] + hi[1]) - seg.o.y,
              cz = 0.5f * (lo[2] + hi[2]) - seg.o.z;
  const float ex = hi[0] - lo[0], ey = hi[1] - lo[1], ez = hi[2] - lo[2];
  float sp = cx * seg.d.x + cy * seg.d.y + cz * seg.d.z;
  sp = sp < seg.s0 ? seg.s0 : (sp > seg.s1 ? seg.s1 : sp);
  const float wx = cx - sp * seg.d.x, wy = cy - sp * seg.d.y, wz = cz - sp * seg.d.z;
  const float reach = (grow + 0.5f * std::sqrt(ex * ex + ey * ey + ez * ez)) * 1.00001f;
  return wx * wx + wy * wy + wz * wz <= reach * reach;
}

template <class Visit>
void VolumeBeamMap::crossing(const Segment& seg, BeamQuery& q, Visit&& visit) const {
  const uint32_t n = uint32_t(size());
  if (n == 0 || !(seg.s1 >= seg.s0)) return;
  const PhotonStore& s = store();
  const float* px = s.xs();
  const float* py = s.ys();
  const float* pz = s.zs();
  const uint16_t* flags = s.flags();
  // The exact test of photon i's disc.
  auto test = [&](uint32_t i) {
    const float vx = px[i] - seg.o.x, vy = py[i] - seg.o.y, vz = pz[i] - seg.o.z;
    const float sp = vx * seg.d.x + vy * seg.d.y + vz * seg.d.z;
    const float cx = vy * seg.d.z - vz * seg.d.y, cy = vz * seg.d.x - vx * seg.d.z, cz = vx * seg.d.y - vy * seg.d.x;
    const float d2 = cx * cx + cy * cy + cz * cz;
    if (d2 < radius2Of_[radiusCode_[i]] && sp >= seg.s0 && sp <= seg.s1) visit(i, sp, d2);
  };
  // Nodes from here on have only leaves below them (a left-balanced heap:
  // if the left child is a leaf, so is the right one).
  const uint32_t lastInner = n / 2;  // nodes i < n/2 have a child
  auto* stack = q.stack_.data();
  int top = 0;
  BeamQuery::Entry e;
  e.node = 0;
  for (int k = 0; k < 3; ++k) e.lo[k] = lo_[k], e.hi[k] = hi_[k];
  if (!segmentNearCell(seg, e.lo, e.hi, radiusOf_[bound_[0]])) return;
  // Every entry on the stack (and e) has passed its box test.
  for (;;) {
    const uint32_t i = e.node;
    test(i);
    const uint32_t left = 2 * i + 1;
    if (left < n) {
      if (left >= lastInner) {
        // Both children are leaves: their discs' exact tests replace the
        // box tests (a leaf prunes nothing below it). Half the nodes are
        // leaves, and this is where most of the walk's time went.
        test(left);
        if (left + 1 < n) test(left + 1);
      } else {
        // Its children: left holds <= split, right >= split on the node's
        // axis; each is entered only if the segment meets its cell grown by
        // its subtree's largest radius; the one entered first goes on in e.
        const int axis = (flags[i] & kAxisMask) >> kAxisShift;
        const float split = axis == 0 ? px[i] : (axis == 1 ? py[i] : pz[i]);
        const float saved = e.hi[axis];
        e.hi[axis] = split;
        const bool goLeft = segmentNearCell(seg, e.lo, e.hi, radiusOf_[bound_[left]]);
        e.hi[axis] = saved;
        const float savedLo = e.lo[axis];
        e.lo[axis] = split;
        const bool goRight = left + 1 < n && segmentNearCell(seg, e.lo, e.hi, radiusOf_[bound_[left + 1]]);
        if (goRight && goLeft) {
          if (top + 1 > int(q.stack_.size())) {  // cannot happen for a balanced tree; stay safe
            q.stack_.resize(q.stack_.size() * 2);
            stack = q.stack_.data();
          }
          auto& r = stack[top++];
          r = e;
          r.node = left + 1;
        }
        if (goLeft) {
          e.lo[axis] = savedLo;
          e.hi[axis] = split;
          e.node = left;
          continue;
        }
        if (goRight) {
          e.node = left + 1;
          continue;
        }
      }
    }
    if (top == 0) break;
    e = stack[--top];
  }
}

}  // namespace tdpm::photon
