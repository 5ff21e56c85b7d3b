// render/map_kinds.cpp — the one table from a photon map kind to its name
// and its request in RenderOptions (render/map_kinds.h).
#include "render/map_kinds.h"

#include "core/error.h"
#include "render/render_options.h"

namespace tdpm {

namespace {

const MapKindInfo kTable[kMapKinds] = {
    {MapKind::Caustic, "caustic", "photons", &RenderOptions::causticPhotons, &RenderOptions::causticPhotonsSource,
     false, false, false},
    {MapKind::Global, "global", "global_photons", &RenderOptions::globalPhotons, &RenderOptions::globalPhotonsSource,
     true, true, false},
    {MapKind::Volume, "volume", "volume_photons", &RenderOptions::volumePhotons, &RenderOptions::volumePhotonsSource,
     true, false, true},
};

}  // namespace

const MapKindInfo& mapKindInfo(MapKind kind) {
  const MapKindInfo& row = kTable[size_t(kind)];
  TDPM_ASSERT(row.kind == kind, "render/map_kinds.cpp: the table is out of the enum's order");
  return row;
}

bool mapKindInUse(const RenderOptions& opt, MapKind kind) {
  const MapKindInfo& row = mapKindInfo(kind);
  return !row.onlyWhenAsked || opt.*row.photons > 0;
}

}  // namespace tdpm
