// render/map_kinds.h — the photon maps of a render, by kind (caustic,
// global, and the volume map of participating media). PerMap<T> is
// one value per kind, indexed by photon::MapKind: requests, kernels,
// statistics, memory and the maps themselves are held that way, so code
// loops over kMapKinds instead of naming caustic and global. The one table
// (map_kinds.cpp) maps a kind to its name, the key users and tests read in
// --stats, --json, the EXR metadata and the progressive state
// ("tdpm/caustic_photons", "kernel.caustic.radius_1"), and to its request
// in RenderOptions. Adding a kind: an enum value (photon/map_kind.h), its
// settings in RenderOptions, a row in the table, and what the tracer
// stores and the integrator gathers for it.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "photon/map_kind.h"

namespace tdpm {

using photon::MapKind;

inline constexpr size_t kMapKinds = 3;
// In the order the maps are traced (and their figures reported).
inline constexpr std::array<MapKind, kMapKinds> kAllMapKinds = {MapKind::Caustic, MapKind::Global, MapKind::Volume};

// One T per kind. An aggregate: PerMap<size_t> p = {caustic, global, volume}.
template <class T>
struct PerMap {
  std::array<T, kMapKinds> values{};
  T& operator[](MapKind k) { return values[size_t(k)]; }
  const T& operator[](MapKind k) const { return values[size_t(k)]; }
};

struct RenderOptions;

// A kind's row: its name and its request in the options.
struct MapKindInfo {
  MapKind kind;
  const char* name;         // "caustic", "global": the key in every report (see above)
  const char* optionName;   // the fingerprint's and progressive settings' name of its photon count
  size_t RenderOptions::*photons;               // stored photons wanted
  std::string RenderOptions::*photonsSource;    // the flag or scene key that set them (error messages)
  // Stored photons per emitted path, at most: 1 (a caustic path ends where
  // it stores), or one per bounce (the memory model's pilot and chunks).
  bool storesEveryBounce;
  // Traced only when the render gathers from it (final gather rays, or
  // --global-direct): wantsGlobalMap in render/photon_map.h.
  bool onlyWhenGathered;
  // Part of a render only when its count is not 0 (the volume map: the CLI
  // asks for it only when the scene has media): otherwise its keys stay out
  // of every report, fingerprint and state, so a scene without media keeps
  // the --stats, --json, EXR metadata and fingerprints it had before.
  bool onlyWhenAsked;
};

const MapKindInfo& mapKindInfo(MapKind kind);
// Whether the kind belongs to this render at all (see onlyWhenAsked):
// reports, fingerprints and states skip a kind that does not.
bool mapKindInUse(const RenderOptions& opt, MapKind kind);
inline const char* mapKindName(MapKind kind) { return mapKindInfo(kind).name; }

// What one map cost and holds, summed over the maps of its kind a render
// traced (accumulation frames, progressive passes).
struct MapStats {
  size_t stored = 0;
  uint64_t emitted = 0;
  // k-NN estimates from this map, and those from fewer than
  // estimate::kFewPhotons photons (--stats; 0 for progressive passes, whose
  // kernels are fixed).
  uint64_t estimates = 0, fewEstimates = 0;
};

// From figures alone (printers without the options): the kind is reported
// unless it is onlyWhenAsked and its map neither emitted nor stored.
inline bool mapKindReported(MapKind kind, const MapStats& st) {
  return !mapKindInfo(kind).onlyWhenAsked || st.emitted > 0 || st.stored > 0;
}

}  // namespace tdpm
