// cli/progressive_options.h — the render subcommand's progressive flags
// (--progressive, --passes, --time-limit, --alpha, --extra-samples,
// --extra-cap; scene keys
// render.progressive, render.passes, render.time_limit), their validation,
// and what a progressive render adds to the EXR metadata and the summary.
// Kept apart from render_command.cpp so that the pass loop's CLI is one file.
#pragma once
#include <CLI/CLI.hpp>
#include <map>
#include <string>

#include "cli/render_command.h"
#include "core/progress.h"
#include "render/progressive_state.h"
#include "render/render_options.h"
#include "scene/description.h"
#include "scene/limits.h"

namespace tdpm::cli {

// --extra-samples when not given: a progressive render spends this fraction
// more eye samples per pass where an eye-only pilot finds noise
// (render/sample_allocation.h, docs/photon-map.md section 7).
constexpr float kDefaultExtraSamples = 0.5f;
constexpr scene::limits::FloatRange kExtraSamplesRange{0.0f, 64.0f};
constexpr scene::limits::IntRange kExtraCapRange{1, 64};

void addProgressiveOptions(CLI::App* c, RenderArgs& a);

// Flags over the scene's keys into `o` (after the method is known). Throws
// tdpm::Error (exit 1) for --passes / --time-limit / --alpha without
// --progressive (naming the flag or key) and for --progressive with a
// method that has no progressive variant.
//
// The default (neither --progressive, --fixed-budget nor render.progressive
// given): a scene rendered with its own method — render.method, or the
// default `time` when it names none — renders progressively when that method
// has passes (time, accumulation, standard), with the default 30 s limit
// unless --passes or --time-limit say otherwise. `defaultAllowed` is false
// where passes are not available (an animation's frames): such renders keep
// one budget. A method chosen with -m keeps one budget unless --progressive
// asks. Notes on unused scene keys go to stderr when `printNotes` (under
// mpirun: rank 0 only).
void mergeProgressiveOptions(const RenderArgs& a, const scene::RenderSettings& sc, const std::string& sourcePath,
                             RenderOptions& o, bool defaultAllowed = true, bool printNotes = true);

// "tdpm/passes", "tdpm/photons_emitted", "tdpm/kernel_radius", ... from the state.
void addProgressiveMetadata(const ProgressiveState& state, std::map<std::string, std::string>& metadata);

// When no progress bar is drawn (stderr not a terminal) and not --quiet:
// one line per finished pass on stderr, "tdpm: pass N done ...", so logs
// (and tests waiting to send a signal) see the passes go by.
Progress withPassLines(Progress p);

// One summary line: passes, photons, final kernel, seconds.
std::string progressiveSummary(const ProgressiveState& state);

}  // namespace tdpm::cli
