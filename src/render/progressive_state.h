// render/progressive_state.h — everything a progressive render (a sequence
// of passes, each with fresh photons and fixed kernels, averaged into the
// image) needs to continue where it stopped: written into the output EXR
// after every run (layers + attributes, see image/ and cli/) and read back
// by `--resume`. The pass loop starts from a state (empty: pass 0) and
// updates it after each finished pass; a run of 2N passes and one of N
// passes resumed for N more must give bit-identical images, so every value
// the next pass depends on lives here, stored exactly.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/map_kinds.h"

namespace tdpm {

// What pass 0 fixes for one photon map kind, for every later pass.
struct ProgressiveMapPilot {
  // Paths each pass traces (the tracer's pilot in pass 0 chose it): pass i
  // traces global path indices [i p, (i + 1) p).
  double pathsPerPass = 0;
  // Pass 1's kernels from the k-NN pilot on pass 0's photons
  // (render/progressive.cpp pilotKernel): the space-time radius and half
  // window, and the spatial radius.
  double radius = 0, halfWindow = 0, spatialRadius = 0;
  bool operator==(const ProgressiveMapPilot& o) const {
    return pathsPerPass == o.pathsPerPass && radius == o.radius && halfWindow == o.halfWindow &&
           spatialRadius == o.spatialRadius;
  }
};

struct ProgressivePilot {
  bool done = false;  // pass 0 has fixed the values below
  PerMap<ProgressiveMapPilot> maps;
  bool operator==(const ProgressivePilot& o) const {
    if (done != o.done) return false;
    for (MapKind k : kAllMapKinds)
      if (!(maps[k] == o.maps[k])) return false;
    return true;
  }
};

// Running totals over the passes done, and the last pass's caustic kernel,
// for the user (nothing reads them back but the checks).
struct ProgressiveTotals {
  double photonsEmitted = 0, photonsStored = 0;
  double seconds = 0;  // wall clock: differs between runs of the same render
  double kernelRadius = 0, kernelSpatialRadius = 0, kernelHalfWindow = 0;
};

struct ProgressiveState {
  // Identifies the render: a hash of the scene as loaded and of every option
  // that changes the image (method, seed, sampler, photons per pass, spp per
  // pass, kernels, alpha, ...). Resume refuses a state whose fingerprint
  // differs, naming what differs when it can (see `settings`).
  std::string fingerprint;
  // The options that went into the fingerprint, as "name" -> "value"
  // strings, so that a mismatch can be reported option by option.
  std::map<std::string, std::string> settings;

  int passesDone = 0;
  // Exact values the next pass depends on, and the totals: doubles, stored
  // as "%.17g" strings (exact round trip) under the names of
  // render/progressive_io.h's one table (e.g. "kernel.caustic.radius_1").
  ProgressivePilot pilot;
  ProgressiveTotals totals;
  // Per-pixel float arrays (width x height, row-major) the image and the
  // next pass depend on: the running sums "sum.R", "sum.G", "sum.B" (the
  // image is sum / passesDone), "sumsq.*", "spp".
  // Floats, stored as FLOAT EXR layers (exact round trip).
  std::map<std::string, std::vector<float>> layers;

  bool empty() const { return passesDone == 0; }
};

}  // namespace tdpm
