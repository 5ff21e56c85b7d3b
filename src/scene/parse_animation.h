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

}  // namespace tdpm::scene
