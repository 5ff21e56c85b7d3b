// render/animation_progressive.h — progressive animation frames
// (docs/animation.md section 6), called by renderAnimation
// (render/animation.cpp) for options.progressive: each frame in passes,
// the frames of a block sharing each pass's time-invariant photons when
// --shared-photons is on and the scene has no media.
#pragma once
#include "render/animation.h"

namespace tdpm {

AnimationStats renderProgressiveFrames(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                                       const AnimationOptions& ao, const Progress& progress, const FrameSink& sink);

}  // namespace tdpm
