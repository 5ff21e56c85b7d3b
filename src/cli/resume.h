// cli/resume.h — `tdpm render --resume previous.exr`: the checks made before
// a progressive render continues from the state an earlier run wrote into
// its EXR (render/progressive_io.h), so that a wrong file costs no render
// and writes nothing. docs/resume.md says what the user sees.
#pragma once
#include <string>

#include "render/progressive_state.h"
#include "render/renderer.h"
#include "scene/description.h"

namespace tdpm::cli {

// --resume is only for progressive renders: throws tdpm::Error
// "--resume needs --progressive ..." when `resumePath` is set and
// `progressive` is not. Called with the other flag checks, before the
// scene is loaded.
void checkResumeFlags(const std::string* resumePath, bool progressive);

// The state in `path`, checked against this run: `scene` as loaded (with
// --resolution applied to its camera) and `options` as merged. Throws
// tdpm::Error "--resume <path>: <what>" when the file is missing, not
// readable, not an OpenEXR file, holds no progressive state ("was not
// written by a progressive render") or a damaged one, has another
// resolution, or was rendered from another scene or with other settings
// (each difference named: "photons: 200000 in old.exr, 100000 now").
// Reads the whole file into memory, so the output may be the same file
// (the new one replaces it atomically, core/atomic_file.h).
ProgressiveState loadResumeState(const std::string& path, const scene::SceneDescription& scene,
                                 const RenderOptions& options);

// What a progressive render starts from: the checked state of `resumePath`
// (loadResumeState), or, when it is null, an empty state (pass 0) that
// already carries this render's fingerprint and settings, so that every
// EXR the pass loop writes can be resumed.
ProgressiveState initialProgressiveState(const std::string* resumePath, const scene::SceneDescription& scene,
                                         const RenderOptions& options);

}  // namespace tdpm::cli
