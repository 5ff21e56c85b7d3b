// render/photon_integrator_media.cpp — the photon methods' eye side in
// scenes with participating media (issue 25; docs/media.md). PhotonIntegrator
// ::trace hands over here when Scene::hasMedia(); scenes without media never
// run this file.
//
// The eye path carries its medium (the camera's at the start) and never
// scatters in a medium itself: every piece of the ray through a medium
// (render/media_transport.h: interface surfaces passed, the medium changed)
// adds beta x the in-scattered radiance along it from the volume map, the
// beam radiance estimate (estimate/volume_estimators.h) with the piece's
// transmittance, and multiplies beta by the piece's transmittance (closed
// form in homogeneous media, ratio tracking in grids). The skip rule is the
// surfaces' one: the time-dependent form where the path so far or the piece
// meets motion (or the camera moves), else the standard form on the same
// discs (the time average the pixel wants there). At surfaces as in
// photon_integrator.cpp (mirrors, glass, sharp metals, the gather point with
// direct light, caustics and the final gather), except:
//   - shadow rays carry their transmittance (direct_light.h, directLightMedia);
//   - final-gather rays carry theirs and add the in-scattered radiance along
//     each of their pieces (the medium lights the surface);
//   - glass is not split into both branches: one is chosen by Fresnel, as
//     at any later glass vertex (the split's recursion would carry the
//     medium and the media streams; left for later, docs/media.md);
//   - emission, background and environment are seen attenuated.
// Progressive passes (fixedKernels): the pass's volume map is a Fixed beam
// map (render/progressive.cpp), every photon the pass's disc radius and
// time window, so the same beamRadiance reads it; the skip rule is the
// surfaces' one again: the pass's window where the time-dependent estimate
// applies, the whole shutter on the same discs elsewhere (kTimeless). Each
// pass's photons carry energies for that pass's emitted count, so a pass's
// estimate stands alone and renderProgressive averages the passes as it
// does the surface estimates.
#include <cmath>
#include <limits>
#include <optional>

#include "estimate/volume_estimators.h"
#include "media/medium.h"
#include "render/direct_light.h"
#include "render/guided_sampling.h"
#include "render/media_transport.h"
#include "render/photon_integrator.h"
#include "scene/bsdf.h"

namespace tdpm {

namespace {

constexpr int kGatherSpecularBounces = 4;  // as photon_integrator.cpp
constexpr float kInf = std::numeric_limits<float>::infinity();

// T(s0, s) in a grid: ratio tracking from the piece's start to the
// photon's projection (one unbiased estimate a photon; the closed form
// stands in for homogeneous media, estimate::HomogeneousTransmittance).
struct GridTransmittance {
  const media::Medium* medium;
  Vec3f o, d;
  float time01;
  Rng* rng;
  Rgb operator()(float s) const { return media::transmittance(*medium, o, d, s, time01, *rng); }
};

}  // namespace

Rgb PhotonIntegrator::mediumSegment(Vec3f o, Vec3f d, float tEnd, int32_t medium, float time01, bool timeDependent,
                                    bool withEstimate, Rgb& beta, ThreadState& ts, Rng& rng, Rng& beamRng) const {
  const media::Medium& m = scene_.media[size_t(medium)];
  Rgb L(0.0f);
  if (withEstimate && volume_ && volume_->volumeBeams(timeDependent).size() > 0 && !m.sigmaS.isBlack()) {
    if (!ts.beams) ts.beams = std::make_unique<photon::BeamQuery>();
    const photon::VolumeBeamMap& map = volume_->volumeBeams(timeDependent);
    photon::Segment seg{o, d, 0.0f, tEnd};
    const float t = scene_.shutter.instant() ? map.store().t0() : scene_.shutter.fromNormalized(time01);
    const estimate::HgPhase phase{m.g};
    Rgb inscattered;
    estimate::BeamReport report;
    // The photons' energies are already sigma_s-weighted events
    // (estimate/volume_estimators.h): beamRadiance is the in-scattered
    // radiance itself, sigma_s L_i integrated along the piece.
    if (m.homogeneous()) {
      estimate::HomogeneousTransmittance tr{m.sigmaT, 0.0f};
      inscattered = timeDependent ? estimate::beamRadiance(map, *ts.beams, seg, t, phase, tr, &report)
                                  : estimate::beamRadiance<true>(map, *ts.beams, seg, t, phase, tr, &report);
    } else {
      GridTransmittance tr{&m, o, d, time01, &beamRng};
      inscattered = timeDependent ? estimate::beamRadiance(map, *ts.beams, seg, t, phase, tr, &report)
                                  : estimate::beamRadiance<true>(map, *ts.beams, seg, t, phase, tr, &report);
    }
    ++ts.counts.estimates[MapKind::Volume];
    ++(timeDependent ? ts.counts.timeDependent : ts.counts.standard);  // --stats' time / standard split
    ts.counts.few[MapKind::Volume] += report.summed < estimate::kFewPhotons;
    L = beta * inscattered;
  }
  // An escaping piece: the in-scattered light came from all of it (above),
  // the sky after it only from the media's world (skyTransmittance).
  beta = beta * (std::isinf(tEnd) ? skyTransmittance(scene_, m, o, d, time01, rng)
                                  : media::transmittance(m, o, d, tEnd, time01, rng));
  return L;
}

template <class Stream>
Rgb PhotonIntegrator::finalGatherMedia(const Hit& hit, const ShadingContext& ctx, float time01, bool touched,
                                       int32_t medium, Stream& sampler, int vertex, ThreadState& ts,
                                       const GuideCones& cones, Rng& rng, Rng& beamRng) const {
  Rgb sum(0.0f);
  const int pairs = cones.multi ? 2 : 1;
  const SceneObject& at = scene_.objects[hit.object];
  for (int r = 0; r < s_.gatherRays * pairs; ++r) {
    const int i = r / pairs, which = r % pairs;
    const uint32_t sub = which ? (1u << 16) + uint32_t(i) : uint32_t(i);  // photon_integrator.cpp's kGuideSub
    BsdfSample bs;
    Vec3f u = sampler.get3D(dims::vertexGroup(vertex, dims::kGather, sub));
    if (cones.multi ? !guidedPairSample(ctx, cones, which, {u.x, u.y}, u.z, bs)
                    : !guidedBsdfSample(ctx, cones, {u.x, u.y}, u.z, bs))
      continue;
    Rgb beta = bs.weight;
    Vec3f o = scene_.spawnOrigin(hit.p, hit.n, bs.wi), d = bs.wi;
    int32_t m = at.mediumAfter(hit.n, d, medium);
    bool moved = touched;
    for (int bounce = 0; bounce <= kGatherSpecularBounces; ++bounce) {
      Hit h;
      bool stopped = false;
      const Vec3f start = o;
      bool found = intersectThroughInterfaces(scene_, o, d, time01, m, h, stopped, [&](Vec3f so, float tEnd, int32_t med) {
        bool td = s_.timeDependent && (moved || meetsMotion(so, d, tEnd));
        sum += mediumSegment(so, d, tEnd, med, time01, td, true, beta, ts, rng, beamRng);
        return !beta.isBlack();
      });
      if (stopped) break;
      if (!found) {
        sum += beta * scene_.background;
        if (bounce == 0 && !scene_.environmentLights.empty())
          sum += beta * environmentEmission(scene_, d, bs.pdf, s_.gatherRays, false);
        break;
      }
      moved = moved || meetsMotion(start, d, length(h.p - start));
      if (h.isLight()) {
        if (bounce == 0) {  // the BSDF-sampled half of direct light (MIS with the shadow rays)
          const Light& light = scene_.lights[size_t(h.light)];
          AreaLightFrame f = areaLightFrame(light, time01);
          float w = emissionWeight(bs.pdf, areaLightPdf(light, f, hit.p, h.p, h.n), s_.gatherRays);
          sum += beta * areaLightRadiance(light, f, h.n, -d) * w;
        }
        break;
      }
      Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
      const Material& mat = scene_.materialAt(h, -d, &mixWeight);
      std::optional<Material> textured;
      ShadingContext c = scene_.shadingContext(mat, h, -d, textured, mixWeight);
      if (!mat.isCausticBounce()) {
        sum += beta * estimate(global_, ts.global, ts.global3, h, c, -d, time01, s_.timeDependent && moved, ts);
        break;
      }
      BsdfSample sb;
      Vec3f u2 = sampler.get3D(dims::vertexGroup(vertex + 1 + bounce, dims::kGather, sub));
      if (!bsdfSample(c, {u2.x, u2.y}, u2.z, Transport::Radiance, sb)) break;
      beta *= sb.weight;
      m = scene_.objects[h.object].mediumAfter(h.n, sb.wi, m);
      o = scene_.spawnOrigin(h.p, h.n, sb.wi);
      d = sb.wi;
    }
  }
  return sum / float(s_.gatherRays);
}

// Longer than 80 lines on purpose, as traceFrom: one sample's eye path,
// its sums, throughput and medium local to the loop.
template <PhotonIntegrator::Part kPart, class Stream>
Rgb PhotonIntegrator::traceMedia(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts,
                                 Rgb* eye) const {
  Rgb L(0.0f), eyeL(0.0f);
  auto addEye = [&](Rgb c) {
    L += c;
    eyeL += c;
  };
  // rng: transmittance and shadow rays (the same draws with or without
  // estimates, so EyeOnly stays a prefix of All); beamRng: the estimates'
  // own ratio tracking in grids.
  Rng rng = mediumRng(sampler);
  Rng beamRng(uint64_t(rng.nextU32()) << 32 | rng.nextU32(), 0x6265616dull);  // "beam"
  constexpr bool kEstimates = kPart != Part::EyeOnly;
  Rgb beta(1.0f);
  int32_t medium = scene_.cameraMedium;
  bool touched = scene_.camera.moving();
  float pathLength = 0.0f;
  bool emissionCounts = true;
  float metalPdf = 0.0f;
  Vec3f metalP;
  for (int depth = 0; depth < s_.maxDepth; ++depth) {
    Hit hit;
    bool stopped = false;
    const Vec3f start = origin;
    bool found = intersectThroughInterfaces(scene_, origin, dir, time01, medium, hit, stopped,
                                            [&](Vec3f so, float tEnd, int32_t med) {
                                              bool td = s_.timeDependent && (touched || meetsMotion(so, dir, tEnd));
                                              L += mediumSegment(so, dir, tEnd, med, time01, td, kEstimates, beta,
                                                                 ts, rng, beamRng);
                                              return !beta.isBlack();
                                            });
    if (stopped) break;
    if (!found) {
      addEye(beta * scene_.background);
      if (emissionCounts && !scene_.environmentLights.empty())
        addEye(beta * environmentEmission(scene_, dir, metalPdf, 1, !(metalPdf > 0.0f)));
      break;
    }
    const float dist = length(hit.p - start);
    pathLength += dist;
    touched = touched || meetsMotion(start, dir, dist);
    if (hit.isLight()) {
      if (emissionCounts) {
        const Light& light = scene_.lights[size_t(hit.light)];
        AreaLightFrame f = areaLightFrame(light, time01);
        float w = metalPdf > 0.0f ? emissionWeight(metalPdf, areaLightPdf(light, f, metalP, hit.p, hit.n), 1) : 1.0f;
        addEye(beta * areaLightRadiance(light, f, hit.n, -dir) * w);
      }
      break;
    }
    const SceneObject& obj = scene_.objects[hit.object];
    Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
    const Material& mat = scene_.materialAt(hit, -dir, &mixWeight);
    std::optional<Material> textured;
    ShadingContext ctx = scene_.shadingContext(mat, hit, -dir, textured, mixWeight);
    bool timeDependent = s_.timeDependent && touched;
    float minVolume = s_.footprintVolume * pathLength * pathLength;

    if (mat.isGlossy() && !s_.visualizeGlobal) {
      // ---- sharp metal: direct light and caustics here, then onward ----
      addEye(beta * directLightMedia(scene_, hit, ctx, time01, sampler, depth, 1, nullptr, medium, rng));
      if constexpr (kEstimates)
        L += beta * estimate(caustic_, ts.caustic, ts.caustic3, hit, ctx, -dir, time01, timeDependent, ts, minVolume);
      BsdfSample bs;
      Vec3f u = sampler.get3D(dims::vertexGroup(depth, dims::kBsdf));
      if (!bsdfSample(ctx, {u.x, u.y}, u.z, Transport::Radiance, bs) || !(bs.pdf > 0.0f)) break;
      beta *= bs.weight;
      if (beta.isBlack() || !isFinite(beta)) break;
      emissionCounts = true;
      metalPdf = bs.pdf;
      metalP = hit.p;
      medium = obj.mediumAfter(hit.n, bs.wi, medium);
      origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
      dir = bs.wi;
      continue;
    }

    if (!mat.isDeltaOnly()) {
      // ---- gather point ----
      if (s_.visualizeGlobal) {
        if constexpr (kEstimates)
          L += beta * estimate(global_, ts.global, ts.global3, hit, ctx, -dir, time01, timeDependent, ts);
        break;
      }
      bool gather = global_ && global_->size() > 0 && s_.gatherRays > 0;
      GuideCones cones;
      if (gather) gatherCones(hit, ctx, time01, ts, cones);
      addEye(beta * directLightMedia(scene_, hit, ctx, time01, sampler, depth, gather ? s_.gatherRays : 0, &cones,
                                     medium, rng));
      if constexpr (!kEstimates) break;
      L += beta * estimate(caustic_, ts.caustic, ts.caustic3, hit, ctx, -dir, time01, timeDependent, ts, minVolume);
      // Gather rays also see the medium around the gather point: with no
      // global map (a scene of fog and no diffuse surface to store on)
      // they still run when there is a volume map.
      bool gatherMedia = s_.gatherRays > 0 && (gather || (volume_ && volume_->beams.size() > 0));
      if (gatherMedia)
        L += beta * finalGatherMedia(hit, ctx, time01, touched, medium, sampler, depth, ts, cones, rng, beamRng);
      break;
    }

    // ---- mirror / glass: one branch, chosen by Fresnel ----
    if (metalPdf > 0.0f) emissionCounts = false;
    metalPdf = 0.0f;
    BsdfSample bs;
    Vec3f u = sampler.get3D(dims::vertexGroup(depth, dims::kBsdf));
    if (!bsdfSample(ctx, {u.x, u.y}, u.z, Transport::Radiance, bs)) break;
    beta *= bs.weight;
    if (beta.isBlack() || !isFinite(beta)) break;
    medium = obj.mediumAfter(hit.n, bs.wi, medium);
    origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;
  }
  if constexpr (kPart == Part::Split) *eye = eyeL;
  return L;
}

#define TDPM_TRACE_MEDIA(PART, STREAM)                                                                          \
  template Rgb PhotonIntegrator::traceMedia<PhotonIntegrator::Part::PART, STREAM>(Vec3f, Vec3f, float, STREAM&, \
                                                                                  PhotonIntegrator::ThreadState&, \
                                                                                  Rgb*) const;
TDPM_TRACE_MEDIA(All, RandomStream)
TDPM_TRACE_MEDIA(All, SobolStream)
TDPM_TRACE_MEDIA(Split, RandomStream)
TDPM_TRACE_MEDIA(Split, SobolStream)
TDPM_TRACE_MEDIA(EyeOnly, RandomStream)
TDPM_TRACE_MEDIA(EyeOnly, SobolStream)
#undef TDPM_TRACE_MEDIA

}  // namespace tdpm
