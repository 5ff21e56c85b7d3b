// cli/render_metadata.cpp — the EXR metadata block (cli/render_metadata.h).
#include "cli/render_metadata.h"

#include <cstdio>

#include "cli/flag_ranges.h"

namespace tdpm::cli {

std::map<std::string, std::string> renderMetadata(const std::string& scenePath, const RenderOptions& opt,
                                                  const RenderStats& st, const FrameTag* frame) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", st.seconds);
  std::map<std::string, std::string> m = {{"tdpm/version", TDPM_VERSION},
                                          {"tdpm/scene", scenePath},
                                          {"tdpm/method", renderMethodName(opt.method)},
                                          {"tdpm/spp", std::to_string(opt.spp)},
                                          {"tdpm/max_spp", std::to_string(opt.maxSpp)},
                                          {"tdpm/spp_taken", std::to_string(st.minSpp) + "-" + std::to_string(st.maxSpp)},
                                          {"tdpm/seed", std::to_string(opt.seed)},
                                          {"tdpm/sampler", samplerName(opt.sampler)},
                                          {"tdpm/filter", filterName(opt.filter)},
                                          {"tdpm/max_depth", std::to_string(opt.maxDepth)},
                                          {"tdpm/render_seconds", seconds}};
  if (frame) {
    char shutter[64];
    std::snprintf(shutter, sizeof shutter, "%.9g %.9g", frame->open, frame->close);
    m["tdpm/frame"] = std::to_string(frame->frame);
    m["tdpm/frame_shutter"] = shutter;
  }
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  if (!method.photonMaps) {
    m["tdpm/caustic_guiding"] = formatG(opt.causticGuiding);
    return m;
  }
  for (MapKind k : kAllMapKinds)  // "tdpm/caustic_photons", "tdpm/global_photons", "tdpm/volume_photons" (media)
    if (mapKindInUse(opt, k)) m[std::string("tdpm/") + mapKindName(k) + "_photons"] = std::to_string(st.maps[k].stored);
  if (method.timeDependentEstimate) m["tdpm/search"] = opt.spaceTime4D ? "4d" : "twopass";
  if (method.inBetweenFrames && !opt.progressive) m["tdpm/frames"] = std::to_string(opt.frames);
  return m;
}

}  // namespace tdpm::cli
