// cli/animation_command.h — `tdpm render` for a scene with an "animation"
// block: the frame range, one EXR + PNG per frame from an output pattern,
// the optional --video assembled by ffmpeg, progress by frame and a summary
// with per-frame and total times (render/animation.h does the rendering).
#pragma once
#include <string>

#include "cli/render_command.h"
#include "render/renderer.h"
#include "scene/description.h"

namespace tdpm::cli {

// The full path of an executable `name` found on $PATH, or "".
std::string findOnPath(const std::string& name);

// Everything is checked (range, pattern, --video and ffmpeg, output
// directories) before the first frame is rendered.
int runAnimation(const RenderArgs& args, const scene::SceneDescription& desc, const RenderOptions& options,
                 float exposure);

}  // namespace tdpm::cli
