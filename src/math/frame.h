// math/frame.h — orthonormal frames around a normal (shading frames, cone
// and hemisphere sampling). Duff et al. 2017, "Building an orthonormal basis,
// revisited": branch-free and continuous except at n.z = -1.
#pragma once
#include <cmath>

#include "math/vec.h"

namespace tdpm {

struct Frame {
  Vec3f s, t, n;

  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  explicit Frame(Vec3f normal) : n(normal) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    s = Vec3f(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3f(b, sign + n.y * n.y * a, -n.y);
  }
  Vec3f toLocal(Vec3f v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  Vec3f toWorld(Vec3f v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace tdpm
