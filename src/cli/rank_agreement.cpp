// cli/rank_agreement.cpp — every rank's scene digest and options compared
// before any work (cli/rank_agreement.h).
#include "cli/rank_agreement.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

#include "render/fingerprint.h"

namespace tdpm::cli {

namespace {

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// "key=value\n" per entry, in key order (the map's): what is exchanged when
// the hashes differ, so that the message can name each differing option.
std::string serialize(const std::map<std::string, std::string>& m) {
  std::string s;
  for (const auto& [k, v] : m) s += k + "=" + v + "\n";
  return s;
}

std::map<std::string, std::string> deserialize(const std::string& s) {
  std::map<std::string, std::string> m;
  size_t at = 0;
  while (at < s.size()) {
    size_t eq = s.find('=', at), nl = s.find('\n', at);
    if (eq == std::string::npos || nl == std::string::npos || eq > nl) break;
    m[s.substr(at, eq - at)] = s.substr(eq + 1, nl - eq - 1);
    at = nl + 1;
  }
  return m;
}

// Every rank's `text`, in rank order (sizes exchanged first).
std::vector<std::string> allgatherText(dist::Comm& comm, const std::string& text) {
  std::vector<uint64_t> sizes = comm.allgather(uint64_t(text.size()));
  uint64_t total = 0;
  for (uint64_t n : sizes) total += n;
  std::string all(size_t(total), '\0');
  comm.allgatherv(text.data(), &all[0], sizes);
  std::vector<std::string> out;
  uint64_t offset = 0;
  for (uint64_t n : sizes) {
    out.push_back(all.substr(size_t(offset), size_t(n)));
    offset += n;
  }
  return out;
}

std::string rankList(const std::vector<int>& ranks) {
  std::string s = ranks.size() == 1 ? "rank " : "ranks ";
  for (size_t i = 0; i < ranks.size(); ++i) s += (i ? ", " : "") + std::to_string(ranks[i]);
  return s;
}

}  // namespace

std::map<std::string, std::string> rankSettings(const RenderArgs& a, const scene::SceneDescription& desc,
                                                const RenderOptions& o, float exposure) {
  std::map<std::string, std::string> s = fingerprintOf(desc, o).settings;
  s["progressive"] = o.progressive ? "yes" : "no";
  s["passes"] = std::to_string(o.passes);
  s["time_limit"] = exact(o.timeLimitSeconds);
  s["caustic_guiding"] = exact(o.causticGuiding);
  s["exposure"] = exact(exposure);
  if (desc.animation) {
    const scene::AnimationDesc& an = *desc.animation;
    s["animation"] = "fps " + exact(an.fps) + ", frames " + std::to_string(an.frames) + ", shutter_angle " +
                     exact(an.shutterAngle);
    s["frame_range"] = a.frameRange.value_or("all");
    s["window"] = a.window ? std::to_string(*a.window) : "default";
    s["independent_frames"] = a.independentFrames ? "yes" : "no";
    s["shared_photons"] = a.sharedPhotons ? exact(*a.sharedPhotons) : "default";
    s["moving_photons"] = a.movingPhotons ? exact(*a.movingPhotons) : "default";
    s["continue_paths"] = a.continuePaths ? "yes" : a.noContinuePaths ? "no" : "default";
    s["output"] = a.output;
  }
  return s;
}

std::string rankDisagreement(const std::vector<std::map<std::string, std::string>>& settings,
                             const std::vector<std::string>& scenePaths) {
  // Rank by rank against rank 0; ranks that differ in the same way are
  // named together.
  std::map<std::string, std::vector<int>> byDifference;
  std::vector<std::string> order;
  for (size_t r = 1; r < settings.size(); ++r) {
    if (settings[r] == settings[0]) continue;
    std::vector<std::string> parts;
    auto value = [](const std::map<std::string, std::string>& m, const std::string& k) {
      auto it = m.find(k);
      return it == m.end() ? std::string("not set") : it->second;
    };
    std::map<std::string, bool> keys;
    for (const auto& kv : settings[0]) keys[kv.first] = true;
    for (const auto& kv : settings[r]) keys[kv.first] = true;
    std::string rank = "rank " + std::to_string(r);
    if (value(settings[0], kSceneSettingKey) != value(settings[r], kSceneSettingKey))
      parts.push_back("the scene (" + scenePaths[0] + " on rank 0, " + scenePaths[r] + " on " + rank +
                      (scenePaths[0] == scenePaths[r] ? ": another copy or version of the file" : "") + ")");
    std::string options;
    for (const auto& kv : keys) {
      const std::string& k = kv.first;
      if (k == kSceneSettingKey) continue;
      std::string v0 = value(settings[0], k), vr = value(settings[r], k);
      if (v0 == vr) continue;
      options += std::string(options.empty() ? "" : ", ") + k + " (" + v0 + " on rank 0, " + vr + " on " + rank + ")";
    }
    if (!options.empty()) parts.push_back("the options " + options);
    std::string what;
    for (size_t i = 0; i < parts.size(); ++i) what += (i ? " and " : "") + parts[i];
    if (!byDifference.count(what)) order.push_back(what);
    byDifference[what].push_back(int(r));
  }
  if (order.empty()) return "";
  std::string msg = "the ranks of this mpirun job do not render the same thing: ";
  for (size_t i = 0; i < order.size(); ++i) {
    const std::vector<int>& ranks = byDifference[order[i]];
    msg += (i ? "; " : "") + rankList(ranks) + (ranks.size() == 1 ? " differs" : " differ") + " from rank 0 in " +
           order[i];
  }
  return msg + ". Every rank must be started with the same scene and options (docs/distributed.md)";
}

void requireRanksAgree(dist::Comm& comm, const std::map<std::string, std::string>& settings,
                       const std::string& scenePath) {
  if (!comm.distributed()) return;
  // One fixed-size exchange: the only one every rank can size whatever it loaded.
  std::string hash = fingerprintOfSettings(settings);
  char mine[32] = {};
  std::memcpy(mine, hash.data(), std::min(hash.size(), sizeof mine));
  std::vector<char> all(sizeof mine * size_t(comm.size()));
  comm.allgatherv(mine, all.data(), std::vector<uint64_t>(size_t(comm.size()), sizeof mine));
  bool same = true;
  for (int r = 1; r < comm.size(); ++r)
    same = same && std::memcmp(all.data(), all.data() + sizeof mine * size_t(r), sizeof mine) == 0;
  if (same) return;
  // Every rank saw the difference: all of them exchange the details.
  std::vector<std::string> texts = allgatherText(comm, serialize(settings));
  std::vector<std::string> paths = allgatherText(comm, scenePath);
  std::vector<std::map<std::string, std::string>> maps;
  for (const std::string& t : texts) maps.push_back(deserialize(t));
  std::string message = rankDisagreement(maps, paths);
  // A hash collision of equal texts cannot happen (equal texts hash the same).
  throw dist::AgreedError(message.empty() ? "the ranks of this mpirun job disagree on the render's settings" : message);
}

}  // namespace tdpm::cli
