// cli/render_metadata.h — the one EXR metadata block tdpm writes: the
// settings and figures of a render, for a single image (cli/render_command.cpp)
// and for every animation frame (cli/animation_command.cpp) alike, so the
// two cannot drift (frames used to lack tdpm/filter, tdpm/search and
// tdpm/caustic_guiding). A progressive render's state is added by
// render/progressive_io on top.
#pragma once
#include <map>
#include <string>

#include "render/render_options.h"

namespace tdpm::cli {

// An animation frame's place in the timeline.
struct FrameTag {
  int frame = 0;
  double open = 0, close = 0;  // scene seconds
};

// tdpm/version, scene, method, spp, max_spp, spp_taken, seed, sampler,
// filter, max_depth, render_seconds; pathtrace: caustic_guiding; photon
// methods: caustic_photons, global_photons, time: search, a fixed-budget
// accumulation: frames; a frame: frame and frame_shutter.
std::map<std::string, std::string> renderMetadata(const std::string& scenePath, const RenderOptions& opt,
                                                  const RenderStats& stats, const FrameTag* frame = nullptr);

}  // namespace tdpm::cli
