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

namespace tdpm {

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
  // Exact scalars the next pass depends on or the user wants reported:
  // e.g. "photons.emitted", "photons.stored", "seconds", "kernel.radius",
  // "kernel.half_window". Doubles, stored as "%.17g" strings (exact round trip).
  std::map<std::string, double> scalars;
  // Per-pixel float arrays (width x height, row-major) the image and the
  // next pass depend on: the running sums "sum.R", "sum.G", "sum.B" (the
  // image is sum / passesDone), "spp", and any per-pixel kernel state.
  // Floats, stored as FLOAT EXR layers (exact round trip).
  std::map<std::string, std::vector<float>> layers;

  bool empty() const { return passesDone == 0; }
};

}  // namespace tdpm
