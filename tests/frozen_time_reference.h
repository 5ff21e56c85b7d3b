// tests/frozen_time_reference.h — a reference for motion-blurred photon
// renders made by a different method: the shutter average of many renders
// at frozen instants (an instant shutter, every moving object placed at its
// pose of that instant, rendered with the time-ignoring `standard` photon
// map), plus the error measures the caustic-variance tests and study use.
//
// Why this is independent of the time-dependent estimate: a frozen instant
// has no motion, so its photon map needs no time at all; the time integral
// of the pixel, (1/ts) ∫ L dt, is taken by the midpoint rule over n
// instants instead of by the estimate's space-time kernel. Its own noise is
// measured by rendering the even and the odd instants separately (two
// halves, each a midpoint rule at twice the spacing, with their own photon
// seeds): their difference over two is the standard error of the whole.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "motion/motion.h"
#include "render/renderer.h"
#include "scene/description.h"
#include "scene/scene.h"

namespace tdpm::test {

// The scene at scene time t: shutter [t, t], keyframed objects replaced by
// their pose at t (motion/motion.h's rule: translation and scale linear,
// rotation slerp, combined with the placement by parts). Moving lights or
// a moving camera are not supported (none of the scenes used needs them).
inline scene::SceneDescription frozenAt(const scene::SceneDescription& d, float t) {
  scene::SceneDescription f = d;
  if (!d.camera.motion.empty()) throw std::runtime_error("frozenAt: a moving camera is not supported");
  for (const scene::LightDesc& l : d.lights)
    if (!l.motion.empty()) throw std::runtime_error("frozenAt: a moving light is not supported");
  f.camera.shutterOpen = f.camera.shutterClose = t;
  for (scene::ObjectDesc& o : f.objects) {
    if (o.motion.empty()) continue;
    std::vector<MotionKey> keys;
    for (size_t i = 0; i < o.motion.times.size(); ++i) {
      const scene::TransformDesc& p = o.motion.poses[i];
      keys.push_back(MotionKey{o.motion.times[i], p.translate, p.rotate, p.scale});
    }
    MotionKey k = Motion::interpolateKeys(keys, t);
    scene::TransformDesc& P = o.placement;
    P.translate = P.translate + k.translate;
    P.rotate = k.rotate * P.rotate;
    P.scale = Vec3f{k.scale.x * P.scale.x, k.scale.y * P.scale.y, k.scale.z * P.scale.z};
    o.motion = {};
  }
  return f;
}

struct FrozenReference {
  std::vector<Rgb> mean;   // all instants
  std::vector<Rgb> halfA;  // even instants
  std::vector<Rgb> halfB;  // odd instants
  int width = 0, height = 0;
};

// Averages `instants` frozen renders at t_j = t0 + (j + 0.5) ts / instants
// (instants even), each with `options` (method forced to standard) and
// seed options.seed + j.
inline FrozenReference frozenTimeReference(const scene::SceneDescription& d, RenderOptions options, int instants) {
  if (instants < 2 || instants % 2) throw std::runtime_error("frozenTimeReference: instants must be even and >= 2");
  options.method = RenderMethod::Standard;
  const float t0 = d.camera.shutterOpen, ts = d.camera.shutterClose - d.camera.shutterOpen;
  FrozenReference r;
  r.width = d.camera.width;
  r.height = d.camera.height;
  const size_t n = size_t(r.width) * size_t(r.height);
  r.mean.assign(n, Rgb(0.0f));
  r.halfA.assign(n, Rgb(0.0f));
  r.halfB.assign(n, Rgb(0.0f));
  const uint64_t seed = options.seed;
  for (int j = 0; j < instants; ++j) {
    auto scene = Scene::build(frozenAt(d, t0 + (float(j) + 0.5f) * ts / float(instants)));
    options.seed = seed + uint64_t(j);
    RenderStats st;
    Film film = render(*scene, options, Progress{}, st);
    std::vector<Rgb>& half = j % 2 ? r.halfB : r.halfA;
    for (size_t i = 0; i < n; ++i) half[i] += film.color[i];
  }
  const float inv = 2.0f / float(instants);
  for (size_t i = 0; i < n; ++i) {
    r.halfA[i] = r.halfA[i] * inv;
    r.halfB[i] = r.halfB[i] * inv;
    r.mean[i] = (r.halfA[i] + r.halfB[i]) * 0.5f;
  }
  return r;
}

inline double luminance(Rgb c) { return (double(c.r) + double(c.g) + double(c.b)) / 3.0; }

// Error of a test image against a reference over a pixel mask (the caustic
// region) and over the whole image.
struct RegionError {
  double regionRelative = 0;  // sum over the region of test / of reference - 1
  double maxTest = 0;         // brightest pixel of the test image (luminance, whole image)
  double maxReference = 0;    // brightest pixel of the reference
  double relMse = 0;          // whole image, mean (v - r)^2 / (r + 0.01)^2 over pixels, luminance
};

inline RegionError regionError(const std::vector<Rgb>& test, const std::vector<Rgb>& ref,
                               const std::vector<char>& mask) {
  RegionError e;
  double st = 0, sr = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    double v = luminance(test[i]), r = luminance(ref[i]);
    if (mask[i]) {
      st += v;
      sr += r;
    }
    e.maxTest = std::max(e.maxTest, v);
    e.maxReference = std::max(e.maxReference, r);
    e.relMse += (v - r) * (v - r) / ((r + 0.01) * (r + 0.01));
  }
  e.regionRelative = sr > 0 ? st / sr - 1.0 : 0.0;
  e.relMse /= double(ref.size());
  return e;
}

}  // namespace tdpm::test
