// render/fingerprint.h — what identifies a render, so that `--resume` can
// refuse to continue a progressive render with another scene or other
// settings (ProgressiveState::fingerprint and ::settings).
//
// The fingerprint is a hash of
//  * the scene as loaded: the canonical JSON that scene/json_writer makes of
//    the SceneDescription (numbers written so they read back bit for bit),
//    without its "render" block (those settings are the options below, as
//    the flags and the scene merged them) and without the resolution (an
//    option below), plus the mesh triangles' bytes: the same scene read
//    from another path, or converted from pbrt to JSON, is the same scene;
//  * every option that changes the image, kept as a name -> value map so a
//    mismatch can name what differs (renderSettings below).
// Options that do not change the image are not in it: --threads (images are
// bit-identical for any thread count), --passes and --time-limit (how long
// to go on; a resumed render continues the same sequence), the output path,
// --exposure (PNG preview only), --quiet, --stats.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "scene/description.h"

namespace tdpm {

// The key of the scene's digest in the settings map.
inline constexpr const char* kSceneSettingKey = "scene";
// The key of the estimator's version in the settings map, and this build's
// version: bumped whenever what a method adds for a sample changes with the
// same scene and options, so that --resume refuses a state whose samples
// estimate differently from this run's. 2: the photon methods' eye path
// splits its first two glass vertices and passes through sharp metals
// (stop 18); states written before it carry no version.
inline constexpr const char* kEstimatorSettingKey = "estimator";
inline constexpr const char* kEstimatorVersion = "2";

// The image-changing options as text (floats "%.9g", exact): method, seed,
// sampler, spp (per pass in a progressive render), max_spp, contrast,
// max_depth, photons, global_photons, frames, search, k, ks, fraction,
// kappa, max_radius ("auto" when unset), max_dt, max_radius_fraction,
// max_dt_fraction, kernel_space, kernel_time, cone_k, min_radius2, gather,
// global_direct, resolution ("WxH", from `width` and `height`), and
// extra_samples ("F (cap N)", only when passExtraSamples > 0 and
// passSampleCap > 1).
// A new RenderOptions field that changes the image must be added here (and
// to the test that changes each option in tests/test_fingerprint.cpp).
std::map<std::string, std::string> renderSettings(const RenderOptions& options, int width, int height);

// 32 hex digits: the hash of the scene as described above.
std::string sceneDigest(const scene::SceneDescription& scene);

struct RenderFingerprint {
  std::string value;                            // 32 hex digits
  std::map<std::string, std::string> settings;  // renderSettings + "scene" -> sceneDigest
};

// The fingerprint of rendering `scene` (its camera's resolution) with `options`.
RenderFingerprint fingerprintOf(const scene::SceneDescription& scene, const RenderOptions& options);
// The hash of a settings map (what fingerprintOf's value is made of).
std::string fingerprintOfSettings(const std::map<std::string, std::string>& settings);

// What differs between the settings stored in a file (`before`, from
// `file`) and those of this run (`now`), one phrase each, in name order:
// "the scene differs", "the estimator differs (...)", "photons: 200000 in old.exr, 100000 now",
// "alpha: 0.7 in old.exr, not set now", "gather: not set in old.exr, 1 now".
std::vector<std::string> settingDifferences(const std::map<std::string, std::string>& before,
                                            const std::map<std::string, std::string>& now, const std::string& file);

}  // namespace tdpm
