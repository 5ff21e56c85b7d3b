// cli/render_command.h — `tdpm render SCENE.json`: flags, validation, and
// the run (load -> build -> photon passes -> render -> EXR + PNG -> summary).
// Every setting comes from, in order: a flag, the scene's "render" block,
// the renderer's default (RenderOptions).
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "render/render_options.h"
#include "scene/description.h"

namespace tdpm::cli {

struct RenderArgs {
  std::string scene;
  std::string output;  // default: <scene stem>.exr in the working directory
  std::optional<std::string> method;
  std::optional<int> spp, maxSpp, maxDepth;
  std::optional<float> causticGuiding;
  std::optional<std::string> gatherGuide;  // "on" / "off"
  std::optional<float> contrast;
  std::optional<int64_t> seed;  // >= 0 (CLI11 would wrap -3 into a huge unsigned)
  std::optional<std::string> resolution;  // "WxH"
  std::optional<float> exposure;
  // photon methods
  std::optional<int64_t> photons, globalPhotons, volumePhotons;
  std::optional<int> frames, k, gather, volumeK;
  std::optional<std::string> search, kernelSpace, kernelTime;
  std::optional<std::string> sampler, filter;
  std::optional<float> filterRadius;
  std::optional<float> fraction, kappa, maxRadius, maxDt;
  std::optional<float> kernelFootprint;
  bool globalDirect = false;
  // --resume: the EXR of an earlier progressive render to continue (cli/resume.h).
  std::optional<std::string> resume;
  // animations (scenes with an "animation" block, cli/animation_command.h)
  std::optional<std::string> frameRange, video;
  std::optional<int> window;
  bool independentFrames = false;
  std::optional<double> sharedPhotons, movingPhotons;  // --shared-photons, --moving-photons
  bool continuePaths = false, noContinuePaths = false;  // --continue-paths / --no-continue-paths
  // progressive passes (cli/progressive_options.h)
  bool progressive = false;
  bool fixedBudget = false;  // --fixed-budget: overrides render.progressive of the scene
  std::optional<int> passes;
  std::optional<double> timeLimit;
  std::optional<float> alpha;
  std::optional<float> extraSamples;  // --extra-samples (render/sample_allocation.h)
  std::optional<int> extraCap;        // --extra-cap
  int threads = 0;  // 0: all cores
  bool quiet = false;
  bool stats = false;  // --stats: memory, photon and timing figures after the summary
};

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args);
// The render options of `args` over the scene's "render" block over the
// defaults (what runRender renders with, before --resolution is applied to
// the scene's camera; render.photons_per_pixel is sized from desc's camera).
// Throws tdpm::Error for contradictory settings.
RenderOptions renderOptionsFor(const RenderArgs& args, const scene::SceneDescription& desc);
int runRender(const RenderArgs& args);

}  // namespace tdpm::cli
