// tests/test_gather_guide.cpp — the final gather's guide as a pair of
// samples (render/guided_sampling.h, guidedPairSample; per-photon cone
// widths, GuideCones::perCone): the pair's sum is unbiased for any cones,
// each sample reports the density it is weighed by, and where the guide has
// no density the BSDF sample's weight is exactly the unguided one (the
// property that keeps an evenly lit room's noise from growing;
// docs/photon-map.md, "The final gather where the global map is sparse").
#include <doctest/doctest.h>

#include <cmath>

#include "core/rng.h"
#include "render/guided_sampling.h"

using namespace tdpm;

namespace {

// Cones of different widths, each drawn with probability 1/count
// (perCone), density sum over the cones holding w of 1 / (count Omega_i):
// one narrow pair overlapping, one wide cone reaching below the horizon.
GuideCones unevenCones() {
  GuideCones cones;
  const Vec3f axes[3] = {normalize(Vec3f{0.2f, 1, 0}), normalize(Vec3f{0.25f, 1, 0.05f}),
                         normalize(Vec3f{-0.9f, 0.25f, 0.3f})};
  const float half[3] = {0.2f, 0.35f, 1.0f};
  for (int i = 0; i < 3; ++i) {
    float omc = 1.0f - std::cos(half[i]);
    cones.cone[size_t(i)] = {axes[i], omc, 2.0f * kPi * omc};
  }
  cones.count = 3;
  for (int i = 0; i < 3; ++i) {
    GuideCones::Cone& k = cones.cone[size_t(i)];
    k.density = 1.0f / (3.0f * k.solidAngle);
    cones.totalSolidAngle += k.solidAngle;
  }
  cones.perCone = true;
  cones.multi = true;
  cones.fraction = 1.0f;
  return cones;
}

}  // namespace

TEST_CASE("gather guide: the pair's sum estimates a constant radiance exactly, with the densities it reports") {
  // A constant unit radiance: the pair's summed weight must average to the
  // albedo (the BSDF's integral). It fails if the balance weights use a
  // density other than p_bsdf + p_guide, if a cone is picked by its size
  // instead of 1/count, or if a cap is sampled non-uniformly.
  Material m;
  m.type = Material::Type::Diffuse;
  ShadingContext ctx = makeShadingContext(m, Rgb(0.5f), Vec3f{0, 1, 0}, normalize(Vec3f{0.3f, 1, 0.1f}));
  GuideCones cones = unevenCones();
  Rng rng(11);
  const int n = 400000;
  double sum = 0, guideOnly = 0;
  int densityMismatch = 0, outside = 0;
  for (int i = 0; i < n; ++i) {
    for (int which = 0; which < 2; ++which) {
      BsdfSample bs;
      if (!guidedPairSample(ctx, cones, which, {rng.uniform(), rng.uniform()}, rng.uniform(), bs)) continue;
      sum += bs.weight.g;
      if (which == 1) guideOnly += bs.weight.g;
      densityMismatch += std::fabs(bs.pdf - (bsdfPdf(ctx, bs.wi) + [&] {
                                     float g = 0;
                                     for (int c = 0; c < cones.count; ++c)
                                       if (cones.cone[size_t(c)].holds(bs.wi)) g += cones.cone[size_t(c)].density;
                                     return g;
                                   }())) > 1e-5f * bs.pdf;
      if (which == 1) {
        bool any = false;
        for (int c = 0; c < cones.count; ++c) any = any || cones.cone[size_t(c)].holds(bs.wi);
        outside += !any;
      }
    }
  }
  MESSAGE("mean pair weight " << sum / n << " (albedo 0.5), the guide's share " << guideOnly / sum);
  CHECK(densityMismatch == 0);
  CHECK(outside == 0);
  CHECK(std::fabs(sum / n - 0.5) < 0.004);  // ~5 standard errors
  CHECK(guideOnly / sum > 0.1);  // the guide sample carries a real share (measured 0.20)
}

TEST_CASE("gather guide: outside every cone the BSDF sample weighs what it weighs unguided") {
  Material m;
  m.type = Material::Type::Diffuse;
  ShadingContext ctx = makeShadingContext(m, Rgb(0.7f), Vec3f{0, 1, 0}, Vec3f{0, 1, 0});
  GuideCones cones = unevenCones();
  Rng rng(3);
  int compared = 0, differ = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec2f u{rng.uniform(), rng.uniform()};
    float uLobe = rng.uniform();
    BsdfSample plain, paired;
    REQUIRE(bsdfSample(ctx, u, uLobe, Transport::Radiance, plain));
    REQUIRE(guidedPairSample(ctx, cones, 0, u, uLobe, paired));
    CHECK(paired.wi.x == plain.wi.x);  // the same direction for the same numbers
    bool inCone = false;
    for (int c = 0; c < cones.count; ++c) inCone = inCone || cones.cone[size_t(c)].holds(plain.wi);
    if (inCone) {
      CHECK(paired.weight.g < plain.weight.g);
      continue;
    }
    ++compared;
    differ += std::fabs(paired.weight.g - plain.weight.g) > 1e-6f * plain.weight.g;
  }
  CHECK(compared > 10000);
  CHECK(differ == 0);
}
