// render/direct_light.h — next-event estimation shared by the integrators:
// one shadow ray per light at the path's time. With `misWithBsdf`, area
// lights are weighted by the power heuristic against BSDF sampling (the
// caller then adds MIS-weighted emission when a BSDF-sampled ray hits a
// light); without it they count in full (the caller ignores such hits).
#pragma once
#include "core/rng.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

namespace tdpm {

Rgb directLight(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Rng& rng,
                bool misWithBsdf);

}  // namespace tdpm
