// render/photon_integrator.cpp — gather points, estimates, final gather.
#include "render/photon_integrator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "photon/surface_tag.h"
#include "render/direct_light.h"
#include "render/guided_sampling.h"
#include "scene/bsdf.h"

namespace tdpm {

namespace {
constexpr int kGatherSpecularBounces = 4;  // a gather ray may pass this many mirrors/glass/sharp metals
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kSplitGlassVertices = 2;  // traceFrom
constexpr uint32_t kGuideSub = 1u << 16;  // finalGather: the guide samples' kGather sub-streams
// The gather guide's cones: one per global photon of the GuideCones::kMaxCones
// (32) nearest the gather point, around its incoming direction, as wide as
// the angle to its second-nearest other photon (a density estimate over
// directions whose kernels follow the photons: narrow toward a bright patch
// whose photons bunch, wide where they spread over the hemisphere), held in
// [0.2 rad, 1 rad]. 0.2 rad is wider than the photons' 1.2-degree encoding
// error and than the spread of directions toward a bright patch a few metres
// away across one estimate's disc (with fixed 0.2-rad cones: 0.08 rad left
// 4x the salt on scenes/sparse-room.json). Measured (docs/photon-map.md):
// widths to the 4th-nearest photon gave 1.5x the salt on sparse-room, fixed
// 0.2-rad cones 20% more noise than these on the moving static-room.
constexpr int kGuideNeighbours = 2;
constexpr float kGuideMinOneMinusCos = 0.019933f;  // 1 - cos(0.2)
constexpr float kGuideMaxOneMinusCos = 0.459698f;  // 1 - cos(1)
// A guide photon whose direction meets an area light, or is within 0.05 rad
// of a delta light's direction, most likely came straight from it: its cone
// would find only the light, whose direct light the shadow rays already
// carry (or nothing: a delta light cannot be hit), so it gives no cone. Not
// widened for area lights: the bright wall right beside a lamp is what the
// cones must find (a 0.1-rad margin doubled sparse-room's relMSE). Only in
// scenes with at most kGuideLightTests lights (the test is per light and
// photon).
constexpr float kTowardLightCos = 0.99875f;  // cos(0.05)
constexpr size_t kGuideLightTests = 8;
}  // namespace

PhotonIntegrator::PhotonIntegrator(const Scene& scene, const PerMap<const PhotonMap*>& maps,
                                   const PhotonIntegratorSettings& settings)
    : scene_(scene),
      caustic_(maps[MapKind::Caustic]),
      global_(maps[MapKind::Global]),
      volume_(maps[MapKind::Volume]),
      s_(settings) {
  // The floor of r^2 (coincident photons) relative to the scene: an
  // absolute 1e-12 m^2 is a disc as large as a whole scene at 1e-6 scale,
  // which blurred its caustic away (max 0.58 instead of 8).
  float floorR = 1e-6f * scene.extent();
  s_.estimate.minRadius2 = std::min(s_.estimate.minRadius2, std::max(floorR * floorR, 1e-37f));
}

void PhotonIntegrator::flush(ThreadState& ts) const {
  standardCount_ += ts.counts.standard;
  timeCount_ += ts.counts.timeDependent;
  for (MapKind k : kAllMapKinds) {
    mapCount_[size_t(k)] += ts.counts.estimates[k];
    fewCount_[size_t(k)] += ts.counts.few[k];
  }
  ts.counts = {};
}

EstimateCounts PhotonIntegrator::counts() const {
  EstimateCounts c{standardCount_.load(), timeCount_.load(), {}, {}};
  for (MapKind k : kAllMapKinds) {
    c.estimates[k] = mapCount_[size_t(k)].load();
    c.few[k] = fewCount_[size_t(k)].load();
  }
  return c;
}

// Per-map k-NN estimate counts, and those from few photons (--stats).
static void countEstimate(EstimateCounts& c, MapKind kind, int summed) {
  ++c.estimates[kind];
  c.few[kind] += summed < estimate::kFewPhotons;
}

Rgb PhotonIntegrator::estimate(const PhotonMap* map, std::unique_ptr<estimate::Gatherer>& g,
                               std::unique_ptr<estimate::Gatherer>& g3, const Hit& hit, const ShadingContext& ctx,
                               Vec3f wo, float time01, bool timeDependent, ThreadState& ts,
                               float minVolume) const {
  if (!map || map->size() == 0) return Rgb(0.0f);
  EstimateCounts& counts = ts.counts;
  // The gather, for one BSDF functor (instantiated twice: a context without
  // a shading normal keeps exactly its old loop, no branch per photon).
  auto gather = [&](const auto& brdf) -> Rgb {
    Vec3f n = ctx.frame.n;  // faces the viewer: photons from the other side do not count
    // Nor do photons on the other side of this object's surface, which the
    // side test alone lets through convex edges and thin parts of closed
    // objects (photon/surface_tag.h).
    uint8_t tag = photon::surfaceTag(hit.object, dot(hit.n, wo) < 0.0f);
    if (s_.fixedKernels) {
      if (!ts.fixed) ts.fixed = std::make_unique<estimate::FixedKernelGatherer>();
      const estimate::MapKernel& k = s_.kernels[kindOf(map)];
      if (timeDependent) {
        ++counts.timeDependent;
        float t = scene_.shutter.instant() ? map->store.t0() : scene_.shutter.fromNormalized(time01);
        return ts.fixed->spaceTime(map->tree, hit.p, n, wo, t, k.radius, k.halfWindow, brdf, tag);
      }
      ++counts.standard;
      return ts.fixed->spatial(map->spatialTree(), hit.p, n, wo, k.spatialRadius, brdf, tag);
    }
    if (timeDependent) {
      ++counts.timeDependent;
      if (!g) {
        estimate::Options o = s_.estimate;
        o.method = s_.spaceTime4D ? estimate::Method::SpaceTime4D : estimate::Method::TimeTwoPass;
        g = std::make_unique<estimate::Gatherer>(map->tree, o);
      }
      float t = scene_.shutter.instant() ? map->store.t0() : scene_.shutter.fromNormalized(time01);
      Rgb L = g->radiance(hit.p, n, wo, t, brdf, nullptr, tag, minVolume);
      countEstimate(counts, kindOf(map), g->lastSummed());
      return L;
    }
    ++counts.standard;
    if (!g3) {
      estimate::Options o = s_.estimate;
      o.method = estimate::Method::Standard;
      g3 = std::make_unique<estimate::Gatherer>(map->spatialTree(), o);
    }
    Rgb L = g3->standard(hit.p, n, wo, brdf, nullptr, tag);
    countEstimate(counts, kindOf(map), g3->lastSummed());
    return L;
  };
  if (!ctx.shaded) return gather([&ctx](Vec3f wi, Vec3f) { return bsdfEval(ctx, wi); });
  // At a shading normal each photon's f also takes |wi.ns| / |wi.ng| (bsdf.h).
  return gather([&ctx](Vec3f wi, Vec3f) { return bsdfEval(ctx, wi) * gatherShadingFactor(ctx, wi); });
}

// True if direction w from p points at a light (see kTowardLightCos).
bool PhotonIntegrator::towardLight(Vec3f p, Vec3f w, float time01) const {
  for (const Light& light : scene_.lights) {
    if (light.type == Light::Type::Environment) continue;
    if (light.isDelta()) {
      LightSample ls;
      if (sampleLight(light, p, time01, {0.5f, 0.5f}, ls) && dot(ls.wi, w) > kTowardLightCos) return true;
      continue;
    }
    AreaLightFrame f = areaLightFrame(light, time01);
    float den = dot(w, f.normal);
    if (!(den < 0.0f)) continue;  // not toward its emitting side
    float t = dot(f.center - p, f.normal) / den;
    if (!(t > 0.0f)) continue;
    Vec3f q = p + w * t - f.center;
    if (std::fabs(dot(q, f.edgeX)) <= 0.5f * dot(f.edgeX, f.edgeX) && std::fabs(dot(q, f.edgeZ)) <= 0.5f * dot(f.edgeZ, f.edgeZ))
      return true;
  }
  return false;
}

// The gather guide at a gather point: the global photons nearest it that
// arrived on its side give the directions its indirect light comes from in
// proportion to their flux (Jensen 1995, "Importance driven path tracing
// using the photon map"). Unbiased whatever they hold: the mixture with the
// BSDF covers every direction (render/guided_sampling.h).
void PhotonIntegrator::gatherCones(const Hit& hit, const ShadingContext& ctx, float time01, ThreadState& ts,
                                   GuideCones& cones) const {
  cones = GuideCones{};
  // A non-black background lights the scene without photons: the guide
  // would take rays from it (truck-laser's sky: relMSE x2), so none there.
  if (!s_.gatherGuide || !global_ || global_->size() == 0 || !scene_.background.isBlack()) return;
  const photon::KdTree& tree = global_->spatialTree();
  float maxR2 = s_.estimate.maxRadius * s_.estimate.maxRadius;
  int found = tree.knn(hit.p, GuideCones::kMaxCones, maxR2, ts.guideQuery);
  const photon::PhotonStore& st = tree.store();
  const uint32_t* idx = ts.guideQuery.index();
  const bool testLights = scene_.lights.size() <= kGuideLightTests;
  for (int i = 0; i < found && cones.count < GuideCones::kMaxCones; ++i) {
    Vec3f w = st.direction(idx[i]);
    if (!(dot(w, ctx.frame.n) > 0.0f)) continue;
    if (testLights && towardLight(hit.p, w, time01)) continue;
    cones.cone[size_t(cones.count++)].axis = w;
  }
  const int n = cones.count;
  if (n == 0) return;
  // Each cone's half-angle: the angle to its photon's kGuideNeighbours-th
  // nearest other photon, held in [0.2, 1] rad (kGuideMin/MaxOneMinusCos).
  // The top kGuideNeighbours cosines per photon, from each pair's one dot
  // product.
  std::array<std::array<float, kGuideNeighbours>, GuideCones::kMaxCones> near;
  for (auto& r : near) r.fill(-1.0f);
  auto offer = [&near](int i, float d) {
    auto& r = near[size_t(i)];
    if (!(d > r.back())) return;
    size_t q = r.size() - 1;
    for (; q > 0 && d > r[q - 1]; --q) r[q] = r[q - 1];
    r[q] = d;
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      float d = dot(cones.cone[size_t(i)].axis, cones.cone[size_t(j)].axis);
      offer(i, d);
      offer(j, d);
    }
  for (int i = 0; i < n; ++i) {
    // Fewer than kGuideNeighbours others: the widest cone.
    float cosK = near[size_t(i)].back();
    float omc = std::clamp(1.0f - cosK, kGuideMinOneMinusCos, kGuideMaxOneMinusCos);
    GuideCones::Cone& k = cones.cone[size_t(i)];
    k.oneMinusCos = omc;
    k.solidAngle = 2.0f * kPi * omc;
    k.density = 1.0f / (float(n) * k.solidAngle);
    cones.totalSolidAngle += k.solidAngle;
  }
  cones.perCone = true;
  cones.multi = true;
  cones.fraction = 1.0f;
}

template <class Stream>
Rgb PhotonIntegrator::finalGather(const Hit& hit, const ShadingContext& ctx, float time01, bool touched,
                                  Stream& sampler, int vertex, ThreadState& ts, const GuideCones& cones) const {
  Rgb sum(0.0f);
  const int pairs = cones.multi ? 2 : 1;
  for (int r = 0; r < s_.gatherRays * pairs; ++r) {
    // Multi-sample: ray i's BSDF sample draws as without a guide, its guide
    // sample from sub-stream kGuideSub + i.
    const int i = r / pairs, which = r % pairs;
    const uint32_t sub = which ? kGuideSub + uint32_t(i) : uint32_t(i);
    BsdfSample bs;
    Vec3f u = sampler.get3D(dims::vertexGroup(vertex, dims::kGather, sub));
    if (cones.multi ? !guidedPairSample(ctx, cones, which, {u.x, u.y}, u.z, bs)
                    : !guidedBsdfSample(ctx, cones, {u.x, u.y}, u.z, bs))
      continue;
    Rgb beta = bs.weight;
    Vec3f o = scene_.spawnOrigin(hit.p, hit.n, bs.wi), d = bs.wi;
    bool moved = touched;
    for (int bounce = 0; bounce <= kGatherSpecularBounces; ++bounce) {
      Hit h;
      if (!scene_.intersect(o, d, kInf, time01, h)) {
        sum += beta * scene_.background;
        // As an area light below: straight from the gather point only.
        if (bounce == 0 && !scene_.environmentLights.empty())
          sum += beta * environmentEmission(scene_, d, bs.pdf, s_.gatherRays, false);
        break;
      }
      moved = moved || meetsMotion(o, d, h.t);
      if (h.isLight()) {
        // Seen straight from the gather point: the BSDF-sampled half of
        // direct light (MIS with the shadow rays). Through mirrors or
        // glass it is a caustic, which the caustic map holds.
        if (bounce == 0) {
          const Light& light = scene_.lights[size_t(h.light)];
          AreaLightFrame f = areaLightFrame(light, time01);
          float w = emissionWeight(bs.pdf, areaLightPdf(light, f, hit.p, h.p, h.n), s_.gatherRays);
          sum += beta * areaLightRadiance(light, f, h.n, -d) * w;
        }
        break;
      }
      Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
      const Material& m = scene_.materialAt(h, -d, &mixWeight);
      std::optional<Material> textured;
      ShadingContext c = scene_.shadingContext(m, h, -d, textured, mixWeight);
      // Through mirrors, glass and sharp metals to the first diffuse-like
      // surface: light a sharp metal reflects toward the gather point is in
      // the caustic map (L (S|G)+ D, Material::isGlossy), and light reaching
      // the metal from other surfaces is estimated where it comes from.
      if (!m.isCausticBounce()) {
        sum += beta * estimate(global_, ts.global, ts.global3, h, c, -d, time01, s_.timeDependent && moved, ts);
        break;
      }
      BsdfSample sb;
      Vec3f u2 = sampler.get3D(dims::vertexGroup(vertex + 1 + bounce, dims::kGather, sub));
      if (!bsdfSample(c, {u2.x, u2.y}, u2.z, Transport::Radiance, sb)) break;
      beta *= sb.weight;
      o = scene_.spawnOrigin(h.p, h.n, sb.wi);
      d = sb.wi;
    }
  }
  return sum / float(s_.gatherRays);
}

template <class Stream>
Rgb PhotonIntegrator::radiance(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const {
  return trace<Part::All>(origin, dir, time01, sampler, ts, nullptr);
}

template <class Stream>
Rgb PhotonIntegrator::radianceSplit(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts,
                                    Rgb& eye) const {
  eye = Rgb(0.0f);
  return trace<Part::Split>(origin, dir, time01, sampler, ts, &eye);
}

template <class Stream>
Rgb PhotonIntegrator::eyePart(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const {
  return trace<Part::EyeOnly>(origin, dir, time01, sampler, ts, nullptr);
}

// The eye path. Part::All is radiance(); Split also sums the eye part into
// *eye; EyeOnly skips every photon estimate and gather ray (its draws are a
// prefix of All's: the same path and shadow rays for the same stream).
template <PhotonIntegrator::Part kPart, class Stream>
Rgb PhotonIntegrator::trace(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts, Rgb* eye) const {
  if (scene_.hasMedia()) return traceMedia<kPart>(origin, dir, time01, sampler, ts, eye);
  EyeVertex v;
  // A moving camera sees a different surface point at each time: never
  // the fixed-point time average, so always the time-dependent estimate.
  v.touched = scene_.camera.moving();
  return traceFrom<kPart>(origin, dir, time01, v, sampler, ts, eye);
}

// From `v` on (the camera, or one branch of a split glass vertex). At the
// path's first kSplitGlassVertices glass surfaces both branches are
// followed, weighted by Fresnel, instead of choosing one with probability
// F: a highlight reflected on or inside a moving glass ball (F ~ 4%) is
// then found by every sample whose time puts it in the pixel, not by one in
// 25 of them (the grainy streaks on scenes/glass-ball.json's ball). Two
// vertices: the outer reflection and the inner one; a path splits into at
// most 4. Later glass vertices choose.
//
// A sharp metal (Material::isGlossy) is not a gather point: it adds its
// direct light (shadow rays, MIS with its BSDF ray hitting a lamp) and its
// caustics (the caustic map holds L (S|G)+ G), and the path goes on along
// one BSDF-sampled ray to what the metal reflects, which is estimated there
// (its direct light by shadow rays, not the global map's density: the
// steel post of scenes/glass-ball.json reflected the floor grainy). Light
// reached from the metal through mirrors or glass is a caustic on the
// metal, already counted, so it is not added again.
// Longer than 80 lines on purpose: it is the eye path of one sample, the
// render's inner loop, and its running sums (L, eyeL, the branch's) and
// throughput stay local to it instead of passing through calls per vertex.
template <PhotonIntegrator::Part kPart, class Stream>
Rgb PhotonIntegrator::traceFrom(Vec3f origin, Vec3f dir, float time01, EyeVertex v, Stream& sampler,
                                ThreadState& ts, Rgb* eye) const {
  // L: the sample; eyeL: its eye part (emission, background and direct
  // light; radianceSplit), which EyeOnly computes alone.
  Rgb L(0.0f), eyeL(0.0f), branchL(0.0f), branchEye(0.0f);
  auto addEye = [&](Rgb c) {
    L += c;
    eyeL += c;
  };
  Rgb beta = v.beta;
  bool touched = v.touched;
  float pathLength = v.pathLength;  // from the camera, through mirrors and glass: the pixel footprint grows with it
  int splits = v.splits;
  bool emissionCounts = v.emissionCounts;
  float metalPdf = 0.0f;  // > 0: this ray left a sharp metal with this BSDF density (MIS of a lamp it hits)
  Vec3f metalP;
  for (int depth = v.depth; depth < s_.maxDepth; ++depth) {
    Hit hit;
    if (!scene_.intersect(origin, dir, kInf, time01, hit)) {
      addEye(beta * scene_.background);
      // The environment as an area light hit below.
      if (emissionCounts && !scene_.environmentLights.empty())
        addEye(beta * environmentEmission(scene_, dir, metalPdf, 1, !(metalPdf > 0.0f)));
      break;
    }
    pathLength += hit.t;
    touched = touched || meetsMotion(origin, dir, hit.t);
    if (hit.isLight()) {
      // Seen through mirrors/glass only, or straight from a sharp metal:
      // shadow rays cannot (or, from the metal, share it by MIS).
      if (emissionCounts) {
        const Light& light = scene_.lights[size_t(hit.light)];
        AreaLightFrame f = areaLightFrame(light, time01);
        float w = metalPdf > 0.0f ? emissionWeight(metalPdf, areaLightPdf(light, f, metalP, hit.p, hit.n), 1) : 1.0f;
        addEye(beta * areaLightRadiance(light, f, hit.n, -dir) * w);
      }
      break;
    }
    Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
    const Material& mat = scene_.materialAt(hit, -dir, &mixWeight);
    std::optional<Material> textured;
    ShadingContext ctx = scene_.shadingContext(mat, hit, -dir, textured, mixWeight);
    bool timeDependent = s_.timeDependent && touched;
    float minVolume = s_.footprintVolume * pathLength * pathLength;

    if (mat.isGlossy() && !s_.visualizeGlobal) {
      // ---- sharp metal: direct light and caustics here, then onward ----
      addEye(beta * directLight(scene_, hit, ctx, time01, sampler, depth, 1));
      if constexpr (kPart != Part::EyeOnly)
        L += beta * estimate(caustic_, ts.caustic, ts.caustic3, hit, ctx, -dir, time01, timeDependent, ts, minVolume);
      BsdfSample bs;
      Vec3f u = sampler.get3D(dims::vertexGroup(depth, dims::kBsdf));
      if (!bsdfSample(ctx, {u.x, u.y}, u.z, Transport::Radiance, bs) || !(bs.pdf > 0.0f)) break;
      beta *= bs.weight;
      if (beta.isBlack() || !isFinite(beta)) break;
      emissionCounts = true;
      metalPdf = bs.pdf;
      metalP = hit.p;
      origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
      dir = bs.wi;
      continue;
    }

    if (!mat.isDeltaOnly()) {
      // ---- gather point ----
      if (s_.visualizeGlobal) {
        if constexpr (kPart != Part::EyeOnly)
          L += beta * estimate(global_, ts.global, ts.global3, hit, ctx, -dir, time01, timeDependent, ts);
        break;
      }
      bool gather = global_ && global_->size() > 0 && s_.gatherRays > 0;
      // The gather guide changes the gather rays' density, which the direct
      // light's MIS weights must use too.
      GuideCones cones;
      if (gather) gatherCones(hit, ctx, time01, ts, cones);
      addEye(beta * directLight(scene_, hit, ctx, time01, sampler, depth, gather ? s_.gatherRays : 0, &cones));
      if constexpr (kPart == Part::EyeOnly) break;
      L += beta * estimate(caustic_, ts.caustic, ts.caustic3, hit, ctx, -dir, time01, timeDependent, ts, minVolume);
      if (gather) L += beta * finalGather(hit, ctx, time01, touched, sampler, depth, ts, cones);
      break;
    }

    // ---- mirror / glass ----
    if (metalPdf > 0.0f) emissionCounts = false;  // a lamp from here on is a caustic on the metal
    metalPdf = 0.0f;
    BsdfSample bs;
    if (splits < kSplitGlassVertices && mat.transmits()) {
      ++splits;
      BsdfSample reflected;
      float F = dielectricBranches(ctx, Transport::Radiance, reflected, bs);
      if (F < 1.0f) {
        // The reflected branch as its own path (weight F x its chosen
        // weight); this loop goes on with the refracted one, x (1 - F).
        EyeVertex r{beta * reflected.weight * F, touched, pathLength, depth + 1, splits, emissionCounts};
        if (!r.beta.isBlack() && isFinite(r.beta)) {
          Rgb eyeR(0.0f);
          branchL += traceFrom<kPart>(scene_.spawnOrigin(hit.p, hit.n, reflected.wi), reflected.wi, time01, r,
                                      sampler, ts, kPart == Part::Split ? &eyeR : nullptr);
          branchEye += eyeR;
        }
        bs.weight = bs.weight * (1.0f - F);
      }
    } else {
      Vec3f u = sampler.get3D(dims::vertexGroup(depth, dims::kBsdf));
      if (!bsdfSample(ctx, {u.x, u.y}, u.z, Transport::Radiance, bs)) break;
    }
    beta *= bs.weight;
    if (beta.isBlack() || !isFinite(beta)) break;
    origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;
  }
  if constexpr (kPart == Part::Split) *eye = eyeL + branchEye;
  return L + branchL;
}

template Rgb PhotonIntegrator::radiance<RandomStream>(Vec3f, Vec3f, float, RandomStream&, ThreadState&) const;
template Rgb PhotonIntegrator::radiance<SobolStream>(Vec3f, Vec3f, float, SobolStream&, ThreadState&) const;
template Rgb PhotonIntegrator::radianceSplit<RandomStream>(Vec3f, Vec3f, float, RandomStream&, ThreadState&,
                                                           Rgb&) const;
template Rgb PhotonIntegrator::radianceSplit<SobolStream>(Vec3f, Vec3f, float, SobolStream&, ThreadState&, Rgb&) const;
template Rgb PhotonIntegrator::eyePart<RandomStream>(Vec3f, Vec3f, float, RandomStream&, ThreadState&) const;
template Rgb PhotonIntegrator::eyePart<SobolStream>(Vec3f, Vec3f, float, SobolStream&, ThreadState&) const;

}  // namespace tdpm
