// render/media_transport.cpp — shadow-ray transmittance through media.
#include "render/media_transport.h"

#include <algorithm>
#include <cmath>

#include "media/medium.h"

namespace tdpm {

Rgb skyTransmittance(const Scene& s, const media::Medium& m, Vec3f o, Vec3f d, float time01, Rng& rng) {
  const float exit = s.mediaExit(o, d);
  if (!(exit > 0.0f)) return Rgb(0.0f);  // outside, the world behind or beside: no sky light comes along here
  return media::transmittance(m, o, d, exit, time01, rng);
}

Rgb transmittanceTo(const Scene& s, Vec3f o, Vec3f d, float tMax, float time01, int32_t medium, Rng& rng) {
  Rgb T(1.0f);
  const Vec3f target = o + d * (std::isinf(tMax) ? 0.0f : tMax);
  for (int crossing = 0; crossing < kMaxMediumCrossings; ++crossing) {
    Hit hit;
    bool found = tMax > 0 && s.intersect(o, d, tMax, time01, hit);
    if (medium >= 0) {
      if (!found && std::isinf(tMax)) return T * skyTransmittance(s, s.media[size_t(medium)], o, d, time01, rng);
      T = T * media::transmittance(s.media[size_t(medium)], o, d, found ? hit.t : std::max(tMax, 0.0f), time01, rng);
      if (T.isBlack()) return T;
    }
    if (!found) return T;
    if (hit.isLight() || !s.objects[hit.object].isInterface) return Rgb(0.0f);
    medium = s.objects[hit.object].mediumAfter(hit.n, d, medium);
    o = s.spawnOrigin(hit.p, hit.n, d);
    if (!std::isinf(tMax)) tMax = dot(target - o, d);
  }
  return Rgb(0.0f);
}

}  // namespace tdpm
