// photon/map_kind.h — the kinds of photon map (what a path stores, and
// where): its own header so that code holding one value per map
// (render/map_kinds.h) need not include the tracer.
#pragma once
#include <cstdint>

namespace tdpm::photon {

// caustic: L (S|G)+ D, stored at the first diffuse-like surface after a
// specular one; global: every diffuse-like hit; volume: every scattering
// event in a participating medium, never at surfaces (photon/tracer.h;
// traced only when the scene has media).
enum class MapKind : uint8_t { Caustic, Global, Volume };

}  // namespace tdpm::photon
