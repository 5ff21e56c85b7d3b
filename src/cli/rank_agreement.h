// cli/rank_agreement.h — the ranks of an `mpirun` job agree on what they
// render before they render it (issue 27 item 1). Ranks started with other
// scenes or options used to run into collectives of other shapes and spin
// for ever (another --resolution, -m or --photons, another scene), or to
// add up into a silently mixed image (another --seed, a stale scene copy).
//
// Every rank hashes its scene (render/fingerprint.h sceneDigest: the loaded
// description after includes, mesh bytes included, not its path) and every
// option that changes what is rendered or how the ranks share the work;
// the hashes are exchanged (one fixed-size allgather, the first collective
// after the agreed setup check) and on any difference every rank throws the
// same dist::AgreedError, naming the ranks that differ from rank 0 and what
// differs (the scene, and each option with its value on each side).
#pragma once
#include <map>
#include <string>

#include "cli/render_command.h"
#include "distributed/comm.h"
#include "render/renderer.h"
#include "scene/description.h"

namespace tdpm::cli {

// What the ranks must agree on: renderSettings + "scene" (the digest) +
// "estimator" (render/fingerprint.h), and the options that are not in the
// resume fingerprint but still change the image or the work's shape:
// progressive, passes, time_limit, caustic_guiding, exposure, and for an
// animation frame_range, window, independent_frames and output (each rank
// writes its own frames).
std::map<std::string, std::string> rankSettings(const RenderArgs& args, const scene::SceneDescription& desc,
                                                const RenderOptions& options, float exposure);

// Collective (a no-op for one process): throws dist::AgreedError on every
// rank when any rank's `settings` differ from rank 0's. `scenePath` only
// names each rank's scene file in the message (the same scene may live
// under other paths on other machines).
void requireRanksAgree(dist::Comm& comm, const std::map<std::string, std::string>& settings,
                       const std::string& scenePath);

// The message of requireRanksAgree, from every rank's settings and scene
// path (index = rank); "" when they agree. Separate for tests.
std::string rankDisagreement(const std::vector<std::map<std::string, std::string>>& settings,
                             const std::vector<std::string>& scenePaths);

}  // namespace tdpm::cli
