// scene/parse_animation.cpp — the "animation" block: fps > 0, frames >= 1,
// shutter_angle in (0, 360] (default 180). The keyframe clock check (every
// keyframe inside [0, frames / fps]) is parse.cpp's, which reads keyframes
// against the camera's shutter, here the whole timeline.
#include "scene/parse_animation.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "scene/limits.h"

namespace tdpm::scene {

AnimationDesc readAnimation(const detail::Node& n) {
  n.expectObject({"fps", "frames", "shutter_angle"});
  AnimationDesc a;
  detail::Node fps = n.required("fps");
  a.fps = fps.number();
  fps.require(a.fps > 0, "fps must be > 0, got " + detail::formatNumber(a.fps));
  detail::Node frames = n.required("frames");
  int64_t count = frames.integer();
  frames.require(count >= 1 && count <= kMaxAnimationFrames,
                 "frames must be between 1 and " + std::to_string(kMaxAnimationFrames) + ", got " +
                     std::to_string(count));
  a.frames = int(count);
  if (n.has("shutter_angle")) {
    detail::Node angle = n.member("shutter_angle");
    a.shutterAngle = angle.number();
    angle.require(a.shutterAngle > 0 && a.shutterAngle <= 360,
                  "shutter_angle must be in (0, 360] degrees, got " + detail::formatNumber(a.shutterAngle));
  }
  // The timeline and a frame's shutter must be finite, non-zero floats.
  float duration = float(a.duration()), shutter = float(a.shutterLength());
  n.require(std::isfinite(duration) && shutter >= std::numeric_limits<float>::min(),
            "fps " + detail::formatNumber(a.fps) + " with " + std::to_string(a.frames) +
                " frames gives a timeline of " + detail::formatNumber(a.duration()) + " s and a shutter of " +
                detail::formatNumber(a.shutterLength()) + " s, outside the float range");
  std::string problem = animationTimeResolutionProblem(a);
  if (!problem.empty()) (n.has("shutter_angle") ? n.member("shutter_angle") : n).fail(problem);
  return a;
}

double floatTimeStep(double t) {
  float f = float(t);
  return double(std::nextafter(f, std::numeric_limits<float>::infinity())) - double(f);
}

namespace {

constexpr double kBins = limits::kTimeBins;

// The latest time a frame's map of `shutter` seconds reaches: the last
// frame's shutter and a time kernel's reach of at most one shutter past it.
double lastTime(double fps, int64_t frames, double shutter) { return double(frames - 1) / fps + 2 * shutter; }

// Near t = 0 floats resolve any shutter, but below about 1e-21 s the
// photon pass of a one-frame animation never ended (measured: a 1e-17
// degree shutter at 24 fps, 1.2e-21 s, ran for ever; 1e-15 degrees, 1.2e-19 s,
// rendered): shutters below a picosecond are refused, far from that.
constexpr double kMinShutterSeconds = 1e-12;

bool resolved(double fps, int64_t frames, double shutter) {
  return shutter >= kMinShutterSeconds * (1 - 1e-6) && shutter >= kBins * floatTimeStep(lastTime(fps, frames, shutter));
}

}  // namespace

std::string animationTimeResolutionProblem(const AnimationDesc& a) {
  const double shutter = a.shutterLength();
  if (resolved(a.fps, a.frames, shutter)) return "";
  const double t = lastTime(a.fps, a.frames, shutter);
  // The smallest usable angle, by bisection (a longer shutter only pushes
  // the last time a little later), checked as printed.
  auto usable = [&](double angle) { return resolved(a.fps, a.frames, angle / 360.0 / a.fps); };
  double minAngle = 361;
  if (usable(360)) {
    double lo = a.shutterAngle, hi = 360;
    for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
      double mid = 0.5 * (lo + hi);
      (usable(mid) ? hi : lo) = mid;
    }
    minAngle = hi;
    for (int i = 0; i < 8 && !usable(std::strtod(limits::boundText(minAngle, true, false).c_str(), nullptr)); ++i)
      minAngle *= 1.001;
  }
  // The most frames at this angle: the last time must stay below the
  // power of two where float's step exceeds a bin (then a few steps to be exact).
  const double bin = shutter / kBins;
  const double top = std::ldexp(1.0, int(std::floor(std::log2(bin))) + 24);
  int64_t most = !(shutter >= kMinShutterSeconds * (1 - 1e-6)) ? 0 : std::max<int64_t>(0, int64_t(std::ceil(a.fps * (top - 2 * shutter))));
  most = std::min<int64_t>(most, a.frames);
  while (most > 0 && !resolved(a.fps, most, shutter)) --most;
  while (most + 1 < a.frames && resolved(a.fps, most + 1, shutter)) ++most;
  char buf[400];
  if (!(shutter >= kMinShutterSeconds * (1 - 1e-6))) {  // the tolerance: 8.64e-09 degrees (a float in the parser) at 24 fps is 1e-12 s
    std::snprintf(buf, sizeof buf, "shutter_angle %s with fps %s gives a frame shutter of %.3g s, below tdpm's shortest "
                  "shutter of 1e-12 s", detail::formatNumber(a.shutterAngle).c_str(), detail::formatNumber(a.fps).c_str(),
                  shutter);
  } else {
    std::snprintf(buf, sizeof buf,
                  "shutter_angle %s with fps %s and %d frames gives a frame shutter of %.3g s, which float time "
                  "(photon, shutter and ray times) cannot resolve at t = %.4g s, near the last frame: its step "
                  "there is %.3g s and a frame's photon map needs %d steps in a shutter, one per time bin",
                  detail::formatNumber(a.shutterAngle).c_str(), detail::formatNumber(a.fps).c_str(), a.frames, shutter,
                  t, floatTimeStep(t), limits::kTimeBins);
  }
  std::string msg = buf;
  if (minAngle <= 360) msg += "; the smallest usable shutter_angle for this fps and frame count is " +
                              limits::boundText(minAngle, true, false);
  else msg += "; no shutter_angle works for this fps and frame count";
  if (most >= 1)
    msg += (minAngle <= 360 ? ", or at most " : "; at most ") + std::to_string(most) + (most == 1 ? " frame" : " frames") +
           " at this angle";
  return msg + " (docs/animation.md)";
}

}  // namespace tdpm::scene
