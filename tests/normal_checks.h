// tests/normal_checks.h — what the shading-normal tests (bump, normal maps:
// test_shading_normals.cpp) and the vertex-normal tests
// (test_vertex_normals.cpp) share: their render options (photon counts large
// enough for the photon method to match the path tracer), and the check that
// light arriving from below the geometric surface stays out whatever the
// shading normal says.
#pragma once
#include <doctest/doctest.h>

#include <cstdint>
#include <optional>

#include "render_fixtures.h"
#include "scene/bsdf.h"
#include "scene/description.h"
#include "scene/scene.h"

namespace tdpm::test {

inline RenderOptions normalTestOptions(RenderMethod m, int spp, int maxDepth, uint64_t seed) {
  RenderOptions o = smallRenderOptions(m, spp, maxDepth, seed);
  o.globalPhotons = 20000;
  o.causticPhotons = 20000;
  return o;
}

// `hit` is on the scene's first material, seen from straight above (wo = +y);
// `wi` points toward a light below the geometric surface but inside the
// shading hemisphere. The BSDF must give it nothing, and the path tracer and
// the photon method must both render black.
inline void checkLightFromBelowStaysOut(const scene::SceneDescription& d, const Scene& s, const Hit& hit, Vec3f wi) {
  REQUIRE(dot(s.shadingNormal(s.materials[0], hit), wi) > 0);  // the shading normal alone would let it in
  std::optional<Material> scratch;
  ShadingContext c = s.shadingContext(s.materials[0], hit, {0, 1, 0}, scratch);
  CHECK(c.shaded);
  CHECK(bsdfEval(c, wi).isBlack());
  CHECK(bsdfPdf(c, wi) == 0.0f);
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Time})
    CHECK(imageSum(renderOnce(d, normalTestOptions(m, 4, 3, 5))) == 0.0);
}

}  // namespace tdpm::test
