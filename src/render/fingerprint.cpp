// render/fingerprint.cpp — scene digest, image-changing settings, and the
// fingerprint made of them (render/fingerprint.h).
#include "render/fingerprint.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "core/rng.h"
#include "sampling/filter.h"
#include "sampling/sampler.h"
#include "scene/json_writer.h"

namespace tdpm {
namespace {

// Two independent 64-bit FNV-1a streams, each finished by mix64: 128 bits,
// stable across runs, builds and machines (std::hash is none of these).
struct Hasher {
  uint64_t a = 0xcbf29ce484222325ull, b = 0x84222325cbf29ce4ull;
  void add(const void* data, size_t n) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      a = (a ^ p[i]) * 0x100000001b3ull;
      b = (b ^ p[i]) * 0x100000001b3ull;
      b ^= b >> 29;
    }
  }
  // Length first, so that ("ab", "c") and ("a", "bc") differ.
  void add(const std::string& s) {
    uint64_t n = s.size();
    add(&n, sizeof n);
    add(s.data(), s.size());
  }
  std::string hex() const {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(mix64(a)),
                  static_cast<unsigned long long>(mix64(b ^ 0x5bd1e995ull)));
    return buf;
  }
};

std::string floatText(float v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));  // reads back to the same float
  return buf;
}

const char* spaceKernelName(estimate::SpaceKernel k) {
  switch (k) {
    case estimate::SpaceKernel::Cone: return "cone";
    case estimate::SpaceKernel::Epanechnikov: return "epanechnikov";
    default: return "uniform";
  }
}

const char* timeKernelName(estimate::TimeKernel k) {
  return k == estimate::TimeKernel::Epanechnikov ? "epanechnikov" : "uniform";
}

}  // namespace

std::map<std::string, std::string> renderSettings(const RenderOptions& o, int width, int height) {
  const estimate::Options& e = o.estimate;
  std::map<std::string, std::string> s = {
      {"method", renderMethodName(o.method)},
      {"seed", std::to_string(o.seed)},
      {"sampler", samplerName(o.sampler)},
      {"spp", std::to_string(o.spp)},
      {"max_spp", std::to_string(o.maxSpp)},
      {"contrast", floatText(o.contrast)},
      {"max_depth", std::to_string(o.maxDepth)},
      {"frames", std::to_string(o.frames)},
      {"search", o.spaceTime4D ? "4d" : "twopass"},
      {"kappa", floatText(o.kappa)},
      {"k", std::to_string(e.k)},
      {"ks", std::to_string(e.ks)},
      {"fraction", floatText(e.fraction)},
      {"max_radius", std::isfinite(e.maxRadius) ? floatText(e.maxRadius) : "auto"},
      {"max_dt", std::isfinite(e.maxTimeDistance) ? floatText(e.maxTimeDistance) : "auto"},
      {"max_radius_fraction", floatText(o.maxRadiusFraction)},
      {"max_dt_fraction", floatText(o.maxDtFraction)},
      {"kernel_space", spaceKernelName(e.spaceKernel)},
      {"kernel_time", timeKernelName(e.timeKernel)},
      {"cone_k", floatText(e.coneK)},
      {"min_radius2", floatText(e.minRadius2)},
      {"gather", std::to_string(o.gatherRays)},
      {"global_direct", o.visualizeGlobal ? "yes" : "no"},
      {"resolution", std::to_string(width) + "x" + std::to_string(height)},
      {"filter", filterName(o.filter)},
      {"filter_radius", floatText(o.filterRadius)},
      {"kernel_footprint", floatText(o.kernelFootprint)},
      {"alpha", o.alpha > 0 ? floatText(o.alpha) : "auto"},
  };
  // The photon counts, by the kinds' option names ("photons", "global_photons").
  // The volume map's only when it is traced (mapKindInUse): a scene without
  // media keeps its fingerprint.
  for (MapKind k : kAllMapKinds)
    if (mapKindInUse(o, k)) s[mapKindInfo(k).optionName] = std::to_string(o.*mapKindInfo(k).photons);
  // Likewise the volume kernels' k, only when --volume-k set it (else the
  // progressive default is k_s, already in the fingerprint).
  if (mapKindInUse(o, MapKind::Volume) && o.volumeK > 0) s["volume_k"] = std::to_string(o.volumeK);
  // Progressive passes' per-pixel sample counts (render/sample_allocation.h):
  // one key, present only when they are on, so that a render without them
  // keeps the fingerprint it had before they existed.
  if (o.passExtraSamples > 0 && o.passSampleCap > 1)
    s["extra_samples"] = floatText(o.passExtraSamples) + " (cap " + std::to_string(o.passSampleCap) + ")";
  if (o.directOnly) s["direct_only"] = "yes";  // likewise: only when on
  // An animation frame rendered in passes: its shutter, so that frame i's
  // state cannot be resumed as frame j's (only then: stills keep theirs).
  if (std::isfinite(o.frameOpen)) s["frame_shutter"] = floatText(o.frameOpen) + " to " + floatText(o.frameClose);
  if (!o.frameSharing.empty()) s["frame_sharing"] = o.frameSharing;  // likewise: only when its passes share photons
  if (!o.gatherGuide) s["gather_guide"] = "off";  // likewise (only when off, its default since 2026-12): states made before it resume
  return s;
}

// A mesh by its bytes under `label`, then emptied so the JSON text hashed
// after it does not carry the triangles (or the file they came from) again.
static void hashMeshBytes(Hasher& h, const std::string& label, scene::ShapeDesc& s) {
  h.add(label);
  uint64_t nv = s.vertices.size(), ni = s.indices.size();
  h.add(&nv, sizeof nv);
  h.add(s.vertices.data(), s.vertices.size() * sizeof(Vec3f));
  h.add(&ni, sizeof ni);
  h.add(s.indices.data(), s.indices.size() * sizeof(uint32_t));
  s.vertices.clear();
  s.indices.clear();
  s.meshFile.clear();
}

// Participating media (issue 25) and where they are, by value and the
// density by its bytes. Only for scenes that define media, so every other
// scene's digest is what it was.
static void hashMedia(Hasher& h, const scene::SceneDescription& d) {
  if (d.media.empty()) return;
  h.add(std::string("media"));
  auto addInt = [&](int64_t v) { h.add(&v, sizeof v); };
  auto addFloats = [&](const float* v, size_t n) { h.add(v, n * sizeof(float)); };
  for (const scene::MediumDesc& m : d.media) {
    h.add(m.name);
    addInt(int64_t(m.type));
    addFloats(&m.sigmaA.r, 3);
    addFloats(&m.sigmaS.r, 3);
    addFloats(&m.scale, 1);
    addFloats(&m.g, 1);
    if (m.type != scene::MediumDesc::Type::Grid) continue;
    addInt(m.grid.nx), addInt(m.grid.ny), addInt(m.grid.nz);
    addInt(int64_t(m.grid.density.size()));
    addFloats(m.grid.density.data(), m.grid.density.size());
    addFloats(&m.grid.bounds.lo.x, 3);
    addFloats(&m.grid.bounds.hi.x, 3);
    Affine3f p = m.placement.matrix();
    addFloats(&p.m[0][0], 12);
  }
  addInt(d.exteriorMedium);
  addInt(d.camera.medium);
  for (const scene::LightDesc& l : d.lights) addInt(l.medium);
  for (const scene::ObjectDesc& o : d.objects) {
    addInt(o.media.present ? 1 : 0);
    addInt(o.media.inside);
    addInt(o.media.outside);
  }
}

std::string sceneDigest(const scene::SceneDescription& d) {
  Hasher h;
  hashMedia(h, d);
  scene::SceneDescription c = d;
  c.sourcePath.clear();
  c.render = scene::RenderSettings{};  // the options, merged with the flags, are hashed as settings
  c.camera.width = c.camera.height = 1;  // the resolution is a setting of its own
  // Names the image does not depend on, and that the writer requires to be
  // unique: by position instead.
  for (size_t i = 0; i < c.materials.size(); ++i) c.materials[i].name = "m" + std::to_string(i);
  for (scene::ObjectDesc& o : c.objects) {
    scene::ShapeDesc& s = o.shape;
    if (s.type != scene::ShapeDesc::Type::Mesh) continue;
    // The triangles by their bytes (exact, and cheaper than OBJ text); the
    // file they came from does not matter.
    hashMeshBytes(h, "mesh " + o.name, s);
  }
  for (scene::LightDesc& l : c.lights) {
    if (l.areaShape == scene::LightDesc::AreaShape::Mesh) {
      // A mesh light's triangles, as a mesh object's.
      hashMeshBytes(h, "mesh light " + l.name, l.mesh);
    }
    if (!l.map) continue;
    // An environment map by its (lat-long) texels, like a mesh by its triangles.
    h.add("environment " + l.name);
    int64_t size[2] = {l.map->width, l.map->height};
    h.add(size, sizeof size);
    h.add(l.map->pixels.data(), l.map->pixels.size() * sizeof(Rgb));
    l.map.reset();
    l.mapFile.clear();
  }
  h.add(pbrt::sceneToJson(c, "scene.json").json);
  return h.hex();
}

std::string fingerprintOfSettings(const std::map<std::string, std::string>& settings) {
  Hasher h;
  h.add("tdpm fingerprint 1");
  for (const auto& [name, value] : settings) {
    h.add(name);
    h.add(value);
  }
  return h.hex();
}

RenderFingerprint fingerprintOf(const scene::SceneDescription& scene, const RenderOptions& options) {
  RenderFingerprint f;
  f.settings = renderSettings(options, scene.camera.width, scene.camera.height);
  f.settings[kSceneSettingKey] = sceneDigest(scene);
  f.settings[kEstimatorSettingKey] = kEstimatorVersion;
  f.value = fingerprintOfSettings(f.settings);
  return f;
}

std::vector<std::string> settingDifferences(const std::map<std::string, std::string>& before,
                                            const std::map<std::string, std::string>& now, const std::string& file) {
  std::vector<std::string> out;
  auto valueIn = [](const std::map<std::string, std::string>& m, const std::string& key) -> const std::string* {
    auto it = m.find(key);
    return it == m.end() ? nullptr : &it->second;
  };
  std::map<std::string, bool> keys;
  for (const auto& kv : before) keys[kv.first] = true;
  for (const auto& kv : now) keys[kv.first] = true;
  // The scene first: when it differs, that is the news.
  const std::string* sb = valueIn(before, kSceneSettingKey);
  const std::string* sn = valueIn(now, kSceneSettingKey);
  if (!sb || !sn || *sb != *sn) out.push_back("the scene differs");
  const std::string* eb = valueIn(before, kEstimatorSettingKey);
  const std::string* en = valueIn(now, kEstimatorSettingKey);
  if (!eb || !en || *eb != *en)
    out.push_back(std::string("the estimator differs (") + (eb ? "version " + *eb : "an older version") + " in " + file +
                  ", " + (en ? "version " + *en : "an older version") + " now): it was written by another tdpm");
  for (const auto& kv : keys) {
    const std::string& key = kv.first;
    if (key == kSceneSettingKey || key == kEstimatorSettingKey) continue;
    const std::string* b = valueIn(before, key);
    const std::string* n = valueIn(now, key);
    if (b && n && *b == *n) continue;
    out.push_back(key + ": " + (b ? *b + " in " + file : "not set in " + file) + ", " + (n ? *n + " now" : "not set now"));
  }
  return out;
}

}  // namespace tdpm
