// photon/tracer_media.h — a photon path through a scene with participating
// media (issue 25): the walk photon/tracer.cpp hands a path to after its
// emission when Scene::hasMedia(). Scenes without media never come here,
// so their paths, draws and maps are exactly as before.
//
// The walk, as the volumetric path tracer's (render/volume_path.cpp):
//   - the path starts in its light's medium (Scene::lightMedia) and carries
//     the medium it is in; an interface surface (SceneObject::isInterface)
//     only changes it (mediumAfter along the direction, no bounce); any
//     other surface changes it by mediumAfter along the new direction
//     (a refraction into a glass ball enters the ball's interior);
//   - each segment samples free flight in the current medium
//     (media::sampleFreeFlight, spectral tracking): the photon's power is
//     the `beta` it multiplies. Escape: the power carries the tracking's
//     weight (1 in grey media), i.e. surfaces beyond fog see the photon
//     with probability T (grey) or with weight T / P (spectral);
//     Absorb: the path ends. So the single-scattering albedo's roulette is
//     the free flight's own choice between absorption and scattering: a
//     scattering photon keeps its power (weight 1 in grey media);
//   - a scattering event: the volume map (MapKind::Volume) stores a photon
//     there with the power as it arrived (free flight's weight included,
//     before any albedo: a scatter event happens at rate sigma_s per unit
//     length, which is what estimate/volume_estimators.h's derivation
//     needs), the direction it came from (-d) and the path's time; then
//     the path goes on in a Henyey-Greenstein direction (weight 1). A
//     caustic path (L S+ D) that scatters is no longer one: it ends there.
//     A global path goes on unstored (its later surface hits store).
//   - surfaces: caustic and global paths store and bounce as in
//     photon/tracer.cpp; the volume map's paths bounce off every surface as
//     global paths do but never store there.
// Medium vertices count as bounces (TraceSettings::maxBounces), as in the
// volumetric path tracer; interface crossings do not (bounded separately).
// The free-flight random numbers come from a PCG stream per path, seeded
// from (map seed, kind, global path index), so a map stays a function of
// its seed for any thread count and either sampler.
#pragma once
#include <cstdint>
#include <vector>

#include "photon/store.h"
#include "photon/tracer.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm::photon {

// One emitted photon, ready to walk.
struct MediaPath {
  Vec3f origin, dir;   // origin already off the emitter
  Rgb power;           // flux / light pdf
  float time01 = 0.0f, time = 0.0f;
  int32_t medium = -1;  // the light's medium
  bool invariant = false;  // see tracer.cpp (TraceSettings::invariant)
  uint64_t pathIndex = 0;
};

// Traces the path and stores its photons of settings.kind into `out`
// (energies times energyScale); exits as tracer.cpp's (caustic guide).
// Returns the rays cast.
template <class Stream>
uint64_t walkPhotonInMedia(const Scene& scene, const TraceSettings& settings, const MediaPath& path, Stream& rng,
                           double energyScale, PhotonStore& out, std::vector<ExitPoint>* exits);

extern template uint64_t walkPhotonInMedia<RandomStream>(const Scene&, const TraceSettings&, const MediaPath&,
                                                         RandomStream&, double, PhotonStore&, std::vector<ExitPoint>*);
extern template uint64_t walkPhotonInMedia<SobolStream>(const Scene&, const TraceSettings&, const MediaPath&,
                                                        SobolStream&, double, PhotonStore&, std::vector<ExitPoint>*);

}  // namespace tdpm::photon
