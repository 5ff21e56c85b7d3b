// cli/render_command.h — `tdpm render SCENE.json`: flags, validation, and
// the run (load -> build -> photon passes -> render -> EXR + PNG -> summary).
// Every setting comes from, in order: a flag, the scene's "render" block,
// the renderer's default (RenderOptions).
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

namespace tdpm::cli {

struct RenderArgs {
  std::string scene;
  std::string output;  // default: <scene stem>.exr in the working directory
  std::optional<std::string> method;
  std::optional<int> spp, maxSpp, maxDepth;
  std::optional<float> contrast;
  std::optional<int64_t> seed;  // >= 0 (CLI11 would wrap -3 into a huge unsigned)
  std::optional<std::string> resolution;  // "WxH"
  std::optional<float> exposure;
  // photon methods
  std::optional<int64_t> photons, globalPhotons;
  std::optional<int> frames, k, gather;
  std::optional<std::string> search, kernelSpace, kernelTime;
  std::optional<std::string> sampler;
  std::optional<float> fraction, kappa, maxRadius, maxDt;
  bool globalDirect = false;
  // progressive passes (cli/progressive_options.h)
  bool progressive = false;
  std::optional<int> passes;
  std::optional<double> timeLimit;
  std::optional<float> alpha;
  int threads = 0;  // 0: all cores
  bool quiet = false;
  bool stats = false;  // --stats: memory, photon and timing figures after the summary
};

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args);
int runRender(const RenderArgs& args);

}  // namespace tdpm::cli
