// math/bounds.h — axis-aligned bounding boxes (swept bounds of moving
// objects, scene extent for directional-light emission, kd-tree cells).
#pragma once
#include <limits>

#include "math/vec.h"

namespace tdpm {

struct Bounds3f {
  Vec3f lo{std::numeric_limits<float>::infinity()};
  Vec3f hi{-std::numeric_limits<float>::infinity()};

  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void extend(Vec3f p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  void extend(const Bounds3f& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  Vec3f center() const { return (lo + hi) * 0.5f; }
  Vec3f diagonal() const { return hi - lo; }
  bool contains(Vec3f p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  // Slab test of the segment o + s d, s in [s0, s1]. invD = 1/d per axis.
  bool intersectsSegment(Vec3f o, Vec3f invD, float s0, float s1) const {
    for (int a = 0; a < 3; ++a) {
      float tn = (lo[a] - o[a]) * invD[a];
      float tf = (hi[a] - o[a]) * invD[a];
      if (tn > tf) std::swap(tn, tf);
      // NaN (0 * inf when the origin lies on a slab plane) must not reject.
      if (tn == tn) s0 = tn > s0 ? tn : s0;
      if (tf == tf) s1 = tf < s1 ? tf : s1;
      if (s0 > s1) return false;
    }
    return true;
  }
};

}  // namespace tdpm
