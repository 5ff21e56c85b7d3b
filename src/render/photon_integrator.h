// render/photon_integrator.h — eye paths for the four photon-map methods.
// An eye path at time t follows mirrors and glass (at its first two glass
// surfaces both branches, weighted by Fresnel; later one, chosen by Fresnel)
// and sharp metals (adding their direct light and caustics, then one BSDF
// ray on) to the first diffuse-like surface, the gather point, and there adds
//   direct light (shadow rays at t) + caustics (caustic map) +
//   indirect light (final gather: BSDF-sampled rays whose first non-delta
//   hit is estimated from the global map).
// Which estimate (method.md section 3, "when to use which"): with
// `timeDependent`, a gather point whose eye path (or gather ray) passed
// through the swept bounds of anything moving, or whose camera moves, uses
// the time-dependent estimate; any other uses the standard one, which is
// exactly the time average the pixel wants there. Counts of both are kept.
// Scenes with participating media take their own eye path
// (render/photon_integrator_media.cpp; one branch on Scene::hasMedia()).
#pragma once
#include <cstdint>
#include <array>
#include <atomic>
#include <memory>

#include "core/rng.h"
#include "estimate/estimators.h"
#include "estimate/fixed_kernel.h"
#include "render/photon_map.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

struct PhotonIntegratorSettings {
  bool timeDependent = true;      // method `time`; false: standard everywhere
  bool spaceTime4D = false;       // --search 4d
  estimate::Options estimate;     // k, ks, fraction, radii, kernels (method set per query)
  int gatherRays = 1;             // final-gather rays per eye sample
  // Each gather ray a pair: one BSDF sample and one toward the incoming
  // directions of the global photons nearest the gather point (Jensen
  // 1995), balance heuristic (render/guided_sampling.h); false: the BSDF
  // sample alone.
  bool gatherGuide = false;
  bool visualizeGlobal = false;   // gather point = global-map estimate alone (no direct, no gather)
  int maxDepth = 16;
  // Time-dependent two-pass caustic estimates seen from the camera: the
  // smallest kernel volume is footprintVolume x (eye path length)^2, the
  // space-time share of one eye sample (pixel area at that distance x
  // shutter / spp, times a scale); 0: none. See estimate/estimators.h.
  float footprintVolume = 0.0f;
  // Progressive passes (render/progressive.h): every estimate uses the fixed
  // kernels below (estimate/fixed_kernel.h) instead of the k-NN: the
  // space-time kernel where the time-dependent estimate applies, the spatial
  // one over the whole shutter elsewhere (the skip rule).
  bool fixedKernels = false;
  PerMap<estimate::MapKernel> kernels;
  // Animation frames (render/animation.h): whether an eye path meets motion
  // is tested against what moves during the frame's shutter, not the whole
  // timeline (null: Scene::segmentMeetsMotion, the shutter's bounds).
  const photon::MotionBounds* eyeMotion = nullptr;
};

struct EstimateCounts {
  uint64_t standard = 0, timeDependent = 0;
  // k-NN estimates per map, and those whose sum ran over fewer than
  // estimate::kFewPhotons photons (--stats; issue 24). Counted per thread,
  // summed at flush. The progressive fixed kernels are not counted here.
  PerMap<uint64_t> estimates, few;
};

struct GuideCones;  // render/guided_sampling.h

class PhotonIntegrator {
 public:
  struct ThreadState {
    std::unique_ptr<estimate::Gatherer> caustic, caustic3, global, global3;
    std::unique_ptr<estimate::FixedKernelGatherer> fixed;  // fixedKernels only
    EstimateCounts counts;
    photon::KnnQuery guideQuery;  // the gather guide's photons (gatherGuide)
    std::unique_ptr<photon::BeamQuery> beams;  // scenes with media: the volume map's beam queries
  };

  // The maps by kind (PhotonMaps::view(), render/photon_map.h); null or
  // empty maps add nothing.
  PhotonIntegrator(const Scene& scene, const PerMap<const PhotonMap*>& maps, const PhotonIntegratorSettings& settings);

  // Stream: RandomStream or SobolStream (sampling/sampler.h dimension order).
  template <class Stream>
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const;
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng, ThreadState& ts) const {
    RandomStream s{&rng};
    return radiance(origin, dir, time01, s, ts);
  }
  // A sample's eye part: what the eye path finds without the photon maps,
  // i.e. emission and background seen directly or through mirrors and
  // glass, and direct light at the gather point with the MIS weight this
  // integrator gives its shadow rays (the final gather holds the rest).
  // radianceSplit returns radiance() and puts the eye part of the same
  // sample (same path, same draws) into `eye`; eyePart computes it alone,
  // without any photon estimate or gather ray. Progressive passes with
  // per-pixel sample counts (render/sample_allocation.h) average the eye
  // part over more samples than the rest: by linearity still unbiased.
  template <class Stream>
  Rgb radianceSplit(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts, Rgb& eye) const;
  template <class Stream>
  Rgb eyePart(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const;
  // Moves a thread's counters into the totals (called once per tile).
  void flush(ThreadState& ts) const;
  EstimateCounts counts() const;

 private:
  // The eye paths' motion test (PhotonIntegratorSettings::eyeMotion).
  bool meetsMotion(Vec3f o, Vec3f d, float tMax) const {
    return s_.eyeMotion ? s_.eyeMotion->meets(o, d, tMax) : scene_.segmentMeetsMotion(o, d, tMax);
  }
  Rgb estimate(const PhotonMap* map, std::unique_ptr<estimate::Gatherer>& g, std::unique_ptr<estimate::Gatherer>& g3,
               const Hit& hit, const struct ShadingContext& ctx, Vec3f wo, float time01, bool timeDependent,
               ThreadState& ts, float minVolume = 0.0f) const;
  enum class Part { All, Split, EyeOnly };
  // Where an eye path (or one branch of it) starts: its throughput, whether
  // it has met motion, its length so far, its depth, and how many glass
  // vertices were split before it (traceFrom).
  struct EyeVertex {
    Rgb beta{1.0f};
    bool touched = false;
    float pathLength = 0.0f;
    int depth = 0;
    int splits = 0;  // glass vertices split so far
    bool emissionCounts = true;  // false once a sharp metal was followed by mirrors/glass
  };
  template <Part kPart, class Stream>
  Rgb trace(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts, Rgb* eye) const;
  template <Part kPart, class Stream>
  Rgb traceFrom(Vec3f origin, Vec3f dir, float time01, EyeVertex v, Stream& sampler, ThreadState& ts,
                Rgb* eye) const;
  template <class Stream>
  Rgb finalGather(const Hit& hit, const struct ShadingContext& ctx, float time01, bool touched, Stream& sampler,
                  int vertex, ThreadState& ts, const GuideCones& cones) const;
  void gatherCones(const Hit& hit, const struct ShadingContext& ctx, float time01, ThreadState& ts,
                   GuideCones& cones) const;
  bool towardLight(Vec3f p, Vec3f w, float time01) const;
  // ---- scenes with media (render/photon_integrator_media.cpp) ----
  template <Part kPart, class Stream>
  Rgb traceMedia(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts, Rgb* eye) const;
  template <class Stream>
  Rgb finalGatherMedia(const Hit& hit, const struct ShadingContext& ctx, float time01, bool touched, int32_t medium,
                       Stream& sampler, int vertex, ThreadState& ts, const GuideCones& cones, Rng& rng,
                       Rng& beamRng) const;
  // One piece of an eye or gather ray in `medium`, [0, tEnd] from o along
  // d: returns beta x the in-scattered radiance along it from the volume
  // map (none when !withEstimate) and multiplies beta by its transmittance.
  Rgb mediumSegment(Vec3f o, Vec3f d, float tEnd, int32_t medium, float time01, bool timeDependent, bool withEstimate,
                    Rgb& beta, ThreadState& ts, Rng& rng, Rng& beamRng) const;

  const Scene& scene_;
  const PhotonMap* caustic_;
  const PhotonMap* global_;
  const PhotonMap* volume_;  // MapKind::Volume (beams), scenes with media
  PhotonIntegratorSettings s_;
  mutable std::atomic<uint64_t> standardCount_{0}, timeCount_{0};
  mutable std::array<std::atomic<uint64_t>, kMapKinds> mapCount_{}, fewCount_{};
  MapKind kindOf(const PhotonMap* map) const { return map == caustic_ ? MapKind::Caustic : MapKind::Global; }
};

}  // namespace tdpm
