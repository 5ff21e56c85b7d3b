// render/progressive_check.h — whether a progressive state read from a file
// (render/progressive_io.h) is one a render of these options could have
// written, field by field, before any pass runs (issue 27 item 3).
// Why: the pass loop trusts its state (it wrote it): a damaged or edited
// file must not reach it. Each count is checked against its range and
// against the others (passes against the spp layer, the paths per pass
// against the photons emitted), every value and layer for being finite.
#pragma once
#include <string>

#include "render/progressive_state.h"
#include "render/renderer.h"

namespace tdpm {

// Most passes a progressive render runs or resumes: --passes' range
// (scene/limits.h kPasses). Below it every pass index, pass count and
// float spp count the loop forms stays exact.
int maxProgressivePasses();

// Throws tdpm::Error "damaged progressive state: <path>: <field> ..." when
// `state` (read from `path`, its layers of width x height pixels) is not one
// a render with `opt` writes: passes outside [1, maxProgressivePasses()],
// a scalar missing, unknown, not finite or out of its range, photon paths
// per pass that are not whole batches or above the tracer's cap for the
// photons asked for, photons emitted that are not passes x paths per pass,
// a layer missing, unknown, of the wrong size or holding a value that is
// not finite (or a negative sumsq, or an spp count that is not passes x
// this render's per-pass samples).
void checkProgressiveState(const ProgressiveState& state, const RenderOptions& opt, int width, int height,
                           const std::string& path);

}  // namespace tdpm
