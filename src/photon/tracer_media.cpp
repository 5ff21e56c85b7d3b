// photon/tracer_media.cpp — photon paths through participating media (the
// walk and its rules: photon/tracer_media.h).
#include "photon/tracer_media.h"

#include <limits>
#include <optional>

#include "core/rng.h"
#include "media/medium.h"
#include "media/phase.h"
#include "photon/surface_tag.h"
#include "scene/bsdf.h"

namespace tdpm::photon {

namespace {
// Interface surfaces one path may cross (as render/volume_path.cpp): a
// bound against pathological geometry, far above what a scene needs.
constexpr int kMaxCrossings = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

template <class Stream>
uint64_t walkPhotonInMedia(const Scene& scene, const TraceSettings& settings, const MediaPath& path, Stream& rng,
                           double energyScale, PhotonStore& out, std::vector<ExitPoint>* exits) {
  const bool caustic = settings.kind == MapKind::Caustic, volume = settings.kind == MapKind::Volume;
  Rng mediumRng(hashCombine(settings.seed, uint64_t(settings.kind) + 1, path.pathIndex), 0x6d65646961ull);  // "media"
  uint64_t rays = 0;
  Vec3f origin = path.origin, dir = path.dir;
  Rgb power = path.power;
  int32_t medium = path.medium;
  bool invariant = path.invariant;
  bool allSpecular = true;  // every bounce so far was a delta reflection/refraction
  Vec3f lastSpecular = origin;
  // Whether the photons of this path may still be stored (invariance).
  auto keeps = [&] { return settings.invariant != InvariantPhotons::None || !invariant; };
  // The segment [0, t] met motion: false when nothing further is kept.
  auto segment = [&](float t) {
    if (invariant && settings.motion->meets(origin, dir, t)) {
      invariant = false;
      if (settings.invariant == InvariantPhotons::Only) return false;
    }
    return true;
  };
  int bounce = 0;
  for (int crossings = 0; bounce <= settings.maxBounces && crossings < kMaxCrossings;) {
    Hit hit;
    ++rays;
    const bool found = scene.intersect(origin, dir, kInf, path.time01, hit);
    if (medium >= 0) {
      const media::Medium& med = scene.media[size_t(medium)];
      media::FreeFlight ff =
          media::sampleFreeFlight(med, origin, dir, found ? hit.t : kInf, path.time01, mediumRng, power);
      if (ff.event == media::FreeFlight::Event::Absorb || power.isBlack() || !isFinite(power)) return rays;
      if (ff.event == media::FreeFlight::Event::Scatter) {
        // ---- a medium vertex ----
        if (caustic) return rays;  // L S+ D ends at a scattering event, unstored
        if (!segment(ff.t)) return rays;
        const Vec3f p = origin + dir * ff.t;
        if (volume && keeps()) out.add(p, power * float(energyScale), -dir, path.time, 0);
        Vec2f u = rng.get2D(dims::vertexGroup(bounce, dims::kBsdf));
        Vec3f wi;
        media::sampleHenyeyGreenstein(-dir, med.g, u.x, u.y, wi);  // weight f / pdf = 1
        allSpecular = false;
        origin = p;
        dir = wi;
        ++bounce;
        continue;
      }
    }
    if (!found) return rays;
    if (!segment(hit.t)) return rays;
    if (hit.isLight()) return rays;  // emitters absorb
    const SceneObject& obj = scene.objects[hit.object];
    if (obj.isInterface) {  // no surface: only the medium changes
      medium = obj.mediumAfter(hit.n, dir, medium);
      origin = scene.spawnOrigin(hit.p, hit.n, dir);
      ++crossings;
      continue;
    }
    // ---- a surface vertex: as photon/tracer.cpp's tracePath ----
    Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
    const Material& mat = scene.materialAt(hit, -dir, &mixWeight);
    bool glossyBounce = settings.glossyCaustics && mat.isGlossy();
    if (!mat.isDeltaOnly()) {
      bool store = !volume && (settings.kind == MapKind::Global || (bounce > 0 && allSpecular)) && keeps();
      if (store) {
        out.add(hit.p, power * float(energyScale), -dir, path.time, surfaceTag(hit.object, dot(hit.n, dir) > 0.0f));
        if (exits) exits->push_back({lastSpecular, dot(hit.n, dir) > 0.0f ? -hit.n : hit.n});
      }
      if (caustic && !glossyBounce) return rays;  // L (S|G)+ D ends here
    }
    std::optional<Material> textured;
    ShadingContext ctx = scene.shadingContext(mat, hit, -dir, textured, mixWeight);
    BsdfSample bs;
    Vec3f ub = rng.get3D(dims::vertexGroup(bounce, dims::kBsdf));
    if (!bsdfSample(ctx, {ub.x, ub.y}, ub.z, Transport::Importance, bs)) return rays;
    // Shading normals: the adjoint BSDF (bsdf.h), before the roulette reads the weight.
    if (ctx.shaded) bs.weight = bs.weight * adjointShadingFactor(ctx, -dir, bs.wi);
    bool specularLike = bs.delta || glossyBounce;
    if (caustic && !specularLike) return rays;
    allSpecular = allSpecular && specularLike;
    if (specularLike) lastSpecular = hit.p;
    float survive = std::min(1.0f, bs.weight.maxComponent());
    if (!(survive > 0) || rng.get1D(dims::vertexGroup(bounce, dims::kRoulette)) >= survive) return rays;
    power = power * bs.weight / survive;
    medium = obj.mediumAfter(hit.n, bs.wi, medium);
    origin = scene.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;
    ++bounce;
  }
  return rays;
}

template uint64_t walkPhotonInMedia<RandomStream>(const Scene&, const TraceSettings&, const MediaPath&, RandomStream&,
                                                  double, PhotonStore&, std::vector<ExitPoint>*);
template uint64_t walkPhotonInMedia<SobolStream>(const Scene&, const TraceSettings&, const MediaPath&, SobolStream&,
                                                 double, PhotonStore&, std::vector<ExitPoint>*);

}  // namespace tdpm::photon
