// scene/parse_animation.h — reads the top-level "animation" block
// (fps, frames, shutter_angle) into an AnimationDesc, every value checked
// and every error located. Internal to scene/ (uses parse_node.h).
#pragma once
#include "scene/description.h"
#include "scene/parse_node.h"

namespace tdpm::scene {

// At most this many frames: frame times are float fractions of the
// timeline (Embree's ray time), and 1e5 frames keep a frame's shutter
// above 1e-6 of it (scene/limits.h kMinKeyframeGap has the same margin).
constexpr int kMaxAnimationFrames = 100000;

AnimationDesc readAnimation(const detail::Node& n);

// Time resolution (issue 27 item 2). Frame, photon and ray times are float
// seconds on the animation's timeline (Embree's ray time too), and a frame's
// photon map keys time in 256 bins of its shutter (photon/store.h): every
// bin of the last frame's map must be at least one float step wide there,
// or the shutter is not resolved (a 1e-5 degree shutter had open == close:
// an internal error; at 10 degrees, frame 99999 of 100000 rendered 1.2%
// darker from a shutter only 2.4 float steps wide). The check: the shutter
// is at least 256 float steps at t = frameOpen(frames - 1) + 2 shutters.
// "" when it holds, else what is wrong with the smallest usable
// shutter_angle and the most frames at this angle (0 when none).
std::string animationTimeResolutionProblem(const AnimationDesc& a);
// Float's spacing at t seconds (t >= 0).
double floatTimeStep(double t);

}  // namespace tdpm::scene
