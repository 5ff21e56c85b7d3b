// render/progressive_io.cpp — ProgressiveState <-> EXR channels and
// attributes (layout in progressive_io.h).
#include "render/progressive_io.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <set>

#include "core/error.h"

namespace tdpm {
namespace {

const std::string kAttr = kProgressiveAttributePrefix;
const std::string kLayer = kProgressiveLayerPrefix;
constexpr const char* kLayoutVersion = "1";

bool startsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

std::string joinNames(const std::map<std::string, std::vector<float>>& layers) {
  std::string s;
  for (const auto& kv : layers) s += (s.empty() ? "" : ",") + kv.first;
  return s;
}

std::vector<std::string> splitNames(const std::string& s) {
  std::vector<std::string> out;
  if (s.empty()) return out;
  size_t start = 0;
  for (;;) {
    size_t comma = s.find(',', start);
    out.push_back(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

std::vector<ProgressiveScalar> progressiveScalars(const ProgressiveState& s, bool allKinds) {
  using R = ProgressiveScalarRole;
  std::vector<ProgressiveScalar> v;
  // The volume map (onlyWhenAsked) only where the settings name its count
  // (render/progressive.cpp writes it only when the map is traced).
  auto inState = [&](MapKind k) {
    return allKinds || !mapKindInfo(k).onlyWhenAsked || s.settings.count(mapKindInfo(k).optionName) > 0;
  };
  for (MapKind k : kAllMapKinds)
    if (inState(k))
    v.push_back({std::string("photons.") + mapKindName(k) + "_paths_per_pass", R::Paths, k, &s.pilot.maps[k].pathsPerPass});
  for (MapKind k : kAllMapKinds) {
    if (!inState(k)) continue;
    const std::string p = std::string("kernel.") + mapKindName(k) + ".";
    const ProgressiveMapPilot& m = s.pilot.maps[k];
    v.push_back({p + "radius_1", R::Kernel, k, &m.radius});
    v.push_back({p + "half_window_1", R::Kernel, k, &m.halfWindow});
    v.push_back({p + "spatial_radius_1", R::Kernel, k, &m.spatialRadius});
  }
  const ProgressiveTotals& t = s.totals;
  v.push_back({"photons.emitted", R::Total, MapKind::Caustic, &t.photonsEmitted});
  v.push_back({"photons.stored", R::Total, MapKind::Caustic, &t.photonsStored});
  v.push_back({"seconds", R::Total, MapKind::Caustic, &t.seconds});
  v.push_back({"kernel.radius", R::Report, MapKind::Caustic, &t.kernelRadius});
  v.push_back({"kernel.spatial_radius", R::Report, MapKind::Caustic, &t.kernelSpatialRadius});
  v.push_back({"kernel.half_window", R::Report, MapKind::Caustic, &t.kernelHalfWindow});
  return v;
}

DamagedStateError::DamagedStateError(const std::string& path, const std::string& what)
    : Error("damaged progressive state: " + path + ": " + what) {}

std::string exactDoubleText(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

bool parseExactDouble(const std::string& text, double& v) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
  errno = 0;
  char* end = nullptr;
  double x = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') return false;
  // ERANGE on underflow still returns the right subnormal or zero; on
  // overflow strtod gives +-HUGE_VAL for text that was not "inf": refused.
  if (errno == ERANGE && std::isinf(x)) return false;
  v = x;
  return true;
}

void addProgressiveState(const ProgressiveState& state, image::ExrFile& exr) {
  ProgressiveState copy = state;
  addProgressiveState(std::move(copy), exr);
}

void addProgressiveState(ProgressiveState&& state, image::ExrFile& exr) {
  // Replace, never mix: drop an older state's channels and attributes first.
  for (auto it = exr.metadata.begin(); it != exr.metadata.end();)
    it = startsWith(it->first, kAttr) ? exr.metadata.erase(it) : std::next(it);
  for (auto it = exr.extra.begin(); it != exr.extra.end();)
    it = startsWith(it->name, kLayer) ? exr.extra.erase(it) : std::next(it);

  const size_t pixels = exr.color.pixelCount();
  exr.metadata[kAttr + "layers"] = joinNames(state.layers);
  for (auto& [name, values] : state.layers) {
    TDPM_ASSERT(!name.empty() && name.find(',') == std::string::npos, "progressive layer name '" + name + "'");
    TDPM_ASSERT(values.size() == pixels, "progressive layer '" + name + "' does not have the image's pixel count");
    exr.extra.push_back(image::Channel{kLayer + name, std::move(values)});
  }
  state.layers.clear();
  exr.metadata[kAttr + "version"] = kLayoutVersion;
  exr.metadata[kAttr + "passes"] = std::to_string(state.passesDone);
  exr.metadata[kAttr + "fingerprint"] = state.fingerprint;
  for (const auto& [name, value] : state.settings) exr.metadata[kAttr + "setting/" + name] = value;
  if (state.pilot.done)
    for (const ProgressiveScalar& sc : progressiveScalars(state))
      exr.metadata[kAttr + "scalar/" + sc.name] = exactDoubleText(*sc.value);
}

std::optional<ProgressiveState> progressiveStateOf(const image::ExrFile& exr, const std::string& path) {
  auto version = exr.metadata.find(kAttr + "version");
  if (version == exr.metadata.end()) return std::nullopt;
  auto bad = [&](const std::string& what) { return DamagedStateError(path, what); };
  if (version->second != kLayoutVersion)
    throw Error(path + ": progressive state of layout version '" + version->second + "', this tdpm reads version " +
                kLayoutVersion);
  auto need = [&](const std::string& key) -> const std::string& {
    auto it = exr.metadata.find(kAttr + key);
    if (it == exr.metadata.end()) throw bad("attribute " + kAttr + key + " is missing");
    return it->second;
  };

  ProgressiveState state;
  const std::string& passes = need("passes");
  {
    char* end = nullptr;
    errno = 0;
    long long n = std::strtoll(passes.c_str(), &end, 10);
    if (passes.empty() || *end != '\0' || errno == ERANGE || n < 0 || n > INT32_MAX ||
        !std::isdigit(static_cast<unsigned char>(passes[0])))
      throw bad(kAttr + "passes is '" + passes + "', not a number of passes");
    state.passesDone = int(n);
  }
  state.fingerprint = need("fingerprint");
  // The scalars by their names on disk; `state` is ours, so its fields may be written through the table.
  std::map<std::string, double*> fields;
  for (const ProgressiveScalar& sc : progressiveScalars(state, true)) fields[sc.name] = const_cast<double*>(sc.value);
  size_t found = 0;
  std::vector<std::string> foundNames;
  for (const auto& [key, value] : exr.metadata) {
    if (!startsWith(key, kAttr)) continue;
    const std::string name = key.substr(kAttr.size());
    if (startsWith(name, "setting/")) {
      state.settings[name.substr(8)] = value;
    } else if (startsWith(name, "scalar/")) {
      double v = 0;
      if (!parseExactDouble(value, v)) throw bad(key + " is '" + value + "', not a number");
      auto field = fields.find(name.substr(7));
      if (field == fields.end()) throw bad(key + " is not a value a progressive render writes");
      *field->second = v;
      ++found;
      foundNames.push_back(name.substr(7));
    }
  }
  // A kind's scalars only where its settings are (progressiveScalars).
  {
    std::set<std::string> expected;
    for (const ProgressiveScalar& sc : progressiveScalars(state)) expected.insert(sc.name);
    for (const std::string& n : foundNames)
      if (!expected.count(n)) throw bad(kAttr + "scalar/" + n + " is not a value a progressive render writes");
  }
  // All of them (the pilot is done) or none (pass 0 never ended).
  state.pilot.done = found > 0;
  // (the settings are read now: the list of the kinds this state holds)
  if (found > 0)
    for (const ProgressiveScalar& sc : progressiveScalars(state))
      if (!exr.metadata.count(kAttr + "scalar/" + sc.name)) throw bad(kAttr + "scalar/" + sc.name + " is missing");
  // The layers hold floats that must come back exactly: a file converted
  // to HALF or to a lossy compression no longer does (issue 27 item 3).
  if (exr.lossyCompression)
    throw bad("the file is " + exr.compression + "-compressed, which is lossy: its " + kLayer +
              "* layers are not the floats that were written");
  std::set<std::string> listed;
  for (const std::string& name : splitNames(need("layers"))) {
    if (name.empty() || !listed.insert(name).second) throw bad(kAttr + "layers lists '" + name + "' badly");
    const image::Channel* c = exr.findChannel(kLayer + name);
    if (!c) throw bad("layer " + kLayer + name + " is missing");
    if (c->fileType != image::Channel::FileType::Float)
      throw bad("layer " + kLayer + name + " is stored as " +
                (c->fileType == image::Channel::FileType::Half ? "HALF" : "UINT") +
                ", not FLOAT: it does not hold the floats that were written");
    state.layers[name] = c->values;
  }
  for (const image::Channel& c : exr.extra)
    if (startsWith(c.name, kLayer) && !listed.count(c.name.substr(kLayer.size())))
      throw bad("layer " + c.name + " is not listed in " + kAttr + "layers");
  return state;
}

}  // namespace tdpm
