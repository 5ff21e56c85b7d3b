// cli/resume.cpp — the checks of `--resume` (cli/resume.h).
#include "cli/resume.h"

#include "core/error.h"
#include "image/exr.h"
#include "render/fingerprint.h"
#include "render/progressive_check.h"
#include "render/progressive_io.h"

namespace tdpm::cli {

void checkResumeFlags(const std::string* resumePath, bool progressive) {
  if (resumePath && !progressive)
    throw Error("--resume " + *resumePath +
                " needs --progressive: only a progressive render (a sequence of passes) can be continued");
}

ProgressiveState loadResumeState(const std::string& path, const scene::SceneDescription& scene,
                                 const RenderOptions& options) {
  const std::string flag = "--resume " + path;
  image::ExrFile exr;
  std::optional<ProgressiveState> state;
  try {
    exr = image::readExr(path);  // "<path>: No such file or directory", "...: not an OpenEXR file", ...
    state = progressiveStateOf(exr, path);
  } catch (const DamagedStateError&) {
    throw;  // "damaged progressive state: <path>: ..."
  } catch (const Error& e) {
    throw Error("--resume " + std::string(e.what()));
  }
  if (!state)
    throw Error(flag + ": was not written by a progressive render (it has no " + kProgressiveAttributePrefix +
                "* attributes), so there is nothing to continue");

  const int w = scene.camera.width, h = scene.camera.height;
  if (exr.color.width != w || exr.color.height != h)
    throw Error(flag + ": its image is " + std::to_string(exr.color.width) + "x" + std::to_string(exr.color.height) +
                ", this render's is " + std::to_string(w) + "x" + std::to_string(h) + " (" +
                options.resolutionSource + ")");

  const RenderFingerprint now = fingerprintOf(scene, options);
  if (state->fingerprint != now.value) {
    std::vector<std::string> diff = settingDifferences(state->settings, now.settings, path);
    if (diff.empty())
      throw Error(flag + ": its fingerprint " + state->fingerprint + " is not this render's " + now.value +
                  " although the settings it records match (written by another version of tdpm, or edited)");
    std::string list;
    for (const std::string& d : diff) list += (list.empty() ? "" : "; ") + d;
    throw Error(flag + ": it is another render, so it cannot be continued: " + list);
  }
  // The same render: now every value must be one it could have written.
  checkProgressiveState(*state, options, w, h, path);
  return std::move(*state);
}

ProgressiveState initialProgressiveState(const std::string* resumePath, const scene::SceneDescription& scene,
                                         const RenderOptions& options) {
  if (resumePath) return loadResumeState(*resumePath, scene, options);
  RenderFingerprint f = fingerprintOf(scene, options);
  ProgressiveState state;
  state.fingerprint = std::move(f.value);
  state.settings = std::move(f.settings);
  return state;
}

}  // namespace tdpm::cli
