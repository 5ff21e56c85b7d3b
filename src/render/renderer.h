// render/renderer.h — render(): one built scene + options -> a Film.
// Chooses the integrator for the method once, then runs the tile loop.
#pragma once
#include <cstdint>
#include <string>

#include "core/progress.h"
#include "render/film.h"
#include "scene/scene.h"

namespace tdpm {

struct RenderOptions {
  std::string method = "pathtrace";
  int spp = 16;
  uint64_t seed = 1;
  int maxDepth = 16;
};

struct RenderStats {
  double seconds = 0;
  uint64_t cameraSamples = 0;
};

// Names of the methods the renderer accepts (for validation and --help).
const char* const* renderMethods();
bool isRenderMethod(const std::string& name);
// Whether this build can render a method yet (photon methods come with the
// photon-map renderer).
bool methodAvailable(const std::string& name);

Film render(const Scene& scene, const RenderOptions& options, const Progress& progress, RenderStats& stats);

}  // namespace tdpm
