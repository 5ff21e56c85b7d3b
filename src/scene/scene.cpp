// scene/scene.cpp — ray queries returning shaded hit records.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tdpm {

namespace {
// Normals transform by the inverse transpose: inv^T n, given inv.
Vec3f inverseTransposeTimes(const Affine3f& inv, Vec3f n) {
  return {inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
          inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
          inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z};
}
}  // namespace

float Scene::epsilon(Vec3f p) const {
  // Relative to both the point's magnitude (float spacing grows with it) and
  // the scene's size, so a scene scaled by 1e-3 or 1e3 behaves the same.
  float m = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1e-2f * sceneScale_});
  return 2e-5f * m;
}

void Scene::computeScale(const scene::CameraDesc& camera) {
  if (bounds.empty()) return;
  // The camera's distance to what it looks at, over its keyframes.
  float view = length(camera.target - camera.position);
  for (const scene::CameraKeyframe& k : camera.motion) view = std::max(view, length(k.target - k.position));
  float limit = kViewScales * view;
  if (!(limit > 0.0f) || !std::isfinite(limit)) limit = std::numeric_limits<float>::infinity();
  Vec3f d = bounds.diagonal();
  float diag = length(d);
  float coords = std::max({std::fabs(bounds.lo.x), std::fabs(bounds.lo.y), std::fabs(bounds.lo.z),
                           std::fabs(bounds.hi.x), std::fabs(bounds.hi.y), std::fabs(bounds.hi.z)});
  extent_ = std::min(diag, limit);
  sceneScale_ = std::min(std::max(coords, diag), limit);
  if (!(extent_ > 0.0f)) extent_ = std::max(sceneScale_, 1e-30f);
}

Vec3f Scene::spawnOrigin(Vec3f p, Vec3f n, Vec3f d) const {
  return p + faceForward(n, d) * epsilon(p);
}

bool Scene::intersect(Vec3f o, Vec3f d, float tFar, float time01, Hit& hit) const {
  RawHit raw;
  if (!embree_.intersect(o, d, tFar, time01, raw)) return false;
  hit.t = raw.t;
  hit.p = o + d * raw.t;
  hit.time01 = time01;
  int32_t owner = geometryOwner_[raw.geometryId];
  if (owner < 0) {
    hit.light = -owner - 1;
    hit.object = 0;
    const Light& light = lights[size_t(hit.light)];
    hit.n = areaLightNormal(light, areaLightFrame(light, time01), hit.p, raw.primitiveId);  // the emitting side
    hit.localP = hit.p;
    return true;
  }
  hit.light = -1;
  hit.object = uint32_t(owner);
  hit.primitive = raw.primitiveId;
  hit.bary = {raw.u, raw.v};
  const SceneObject& obj = objects[size_t(owner)];
  if (!obj.motion.moving()) {
    // Static: world-space normals and the inverse placement were made once.
    hit.localP = obj.inversePlacement.point(hit.p);
    if (obj.kind == SceneObject::Kind::Sphere) hit.n = normalize(hit.p - obj.worldCentre);
    else if (obj.kind == SceneObject::Kind::Triangles) hit.n = obj.worldNormals[raw.primitiveId];
    else hit.n = normalize(inverseTransposeTimes(obj.inversePlacement, quadricNormal(obj.quadric, hit.localP)));
  } else {
    Affine3f m = obj.motion.atNormalized(time01);
    Affine3f inv = m.inverse();  // once: for the object-space point and the normal
    hit.localP = inv.point(hit.p);
    if (obj.kind == SceneObject::Kind::Sphere) hit.n = normalize(hit.p - m.point({0, 0, 0}));
    else if (obj.kind == SceneObject::Kind::Triangles) hit.n = normalize(inverseTransposeTimes(inv, obj.faceNormals[raw.primitiveId]));
    else hit.n = normalize(inverseTransposeTimes(inv, quadricNormal(obj.quadric, hit.localP)));
  }
  if (obj.reverseOrientation) hit.n = -hit.n;
  return true;
}

Vec2f Scene::uvAt(const Hit& hit) const {
  const SceneObject& obj = objects[hit.object];
  if (obj.kind == SceneObject::Kind::Sphere) {
    Vec3f q = hit.localP;
    float r = length(q);
    float phi = std::atan2(q.y, q.x);
    if (phi < 0) phi += 2 * kPi;
    float theta = r > 0 ? std::acos(std::clamp(q.z / r, -1.0f, 1.0f)) : 0.0f;
    return {phi / (2 * kPi), 1.0f - theta / kPi};  // pbrt: v = (theta - pi) / (0 - pi)
  }
  if (obj.kind == SceneObject::Kind::Quadric) {
    // pbrt's parameterisation: u = phi / phiMax; a disk's v runs from its rim
    // (0) to its inner radius (1), a cylinder's from zMin (0) to zMax (1).
    const Quadric& q = obj.quadric;
    Vec3f p = hit.localP;
    float phi = std::atan2(p.y, p.x);
    if (phi < 0) phi += 2 * kPi;
    float u = std::clamp(phi / q.phiMax, 0.0f, 1.0f);
    float v = q.kind == Quadric::Kind::Disk
                  ? (q.radius - std::sqrt(p.x * p.x + p.y * p.y)) / (q.radius - q.innerRadius)
                  : (p.z - q.zMin) / (q.zMax - q.zMin);
    return {u, std::clamp(v, 0.0f, 1.0f)};
  }
  float b1 = hit.bary.x, b2 = hit.bary.y, b0 = 1 - b1 - b2;
  if (obj.uvs.empty()) return {b1 + b2, b2};  // corners (0,0), (1,0), (1,1)
  const Vec2f* c = &obj.uvs[size_t(hit.primitive) * 3];
  return {b0 * c[0].x + b1 * c[1].x + b2 * c[2].x, b0 * c[0].y + b1 * c[1].y + b2 * c[2].y};
}

bool Scene::segmentMeetsMotion(Vec3f o, Vec3f d, float tMax) const {
  if (movingBounds.empty()) return false;
  Vec3f inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
  for (const Bounds3f& b : movingBounds)
    if (b.intersectsSegment(o, inv, 0.0f, tMax)) return true;
  return false;
}

bool Scene::occluded(Vec3f o, Vec3f d, float tFar, float time01) const {
  return embree_.occluded(o, d, tFar, time01);
}

}  // namespace tdpm

namespace tdpm {

const Material& Scene::shadeTextured(const Material& m, const Hit& hit, std::optional<Material>& scratch) const {
  TexturePoint tp{uvAt(hit), hit.localP};
  scratch.emplace(m);
  // A coated conductor's eta and k are relative to its coating (build.cpp).
  const float rel = m.type == Material::Type::CoatedConductor ? 1.0f / m.ior : 1.0f;
  if (m.specularTexture >= 0) {
    Rgb v = textures.eval(uint32_t(m.specularTexture), tp);
    Rgb r{std::clamp(v.r, 0.0f, 1.0f), std::clamp(v.g, 0.0f, 1.0f), std::clamp(v.b, 0.0f, 1.0f)};
    if (m.type == Material::Type::Conductor || m.type == Material::Type::CoatedConductor) {
      // pbrt-v4's conductor reflectance, as the constant path (parse.cpp, pbrt_mapping.cpp).
      scratch->eta = Rgb(rel);
      for (int i = 0; i < 3; ++i) {
        float ri = std::min(r[i], 0.9999f);
        scratch->k[i] = 2.0f * std::sqrt(ri) / std::sqrt(1.0f - ri) * rel;
      }
    } else {
      scratch->specular = r;
    }
  }
  // pbrt-v4's conductor eta / k textures (unbounded spectra): eta kept
  // positive and k non-negative, which the Fresnel formula needs.
  if (m.etaTexture >= 0) {
    Rgb v = textures.eval(uint32_t(m.etaTexture), tp);
    for (int i = 0; i < 3; ++i) scratch->eta[i] = std::max(v[i], 1e-3f) * rel;
  }
  if (m.kTexture >= 0) {
    Rgb v = textures.eval(uint32_t(m.kTexture), tp);
    for (int i = 0; i < 3; ++i) scratch->k[i] = std::max(v[i], 0.0f) * rel;
  }
  if (m.iorTexture >= 0) scratch->ior = std::max(textures.eval(uint32_t(m.iorTexture), tp).r, 1.0f);
  if (m.roughnessTexture >= 0) {
    float x = textures.eval(uint32_t(m.roughnessTexture), tp).r;
    scratch->alpha = std::clamp(roughnessToAlpha(x, m.roughnessRemap), 1e-3f, 1.0f);
  }
  if (m.baseRoughnessTexture >= 0) {
    float x = textures.eval(uint32_t(m.baseRoughnessTexture), tp).r;
    scratch->baseAlpha = std::clamp(roughnessToAlpha(x, m.roughnessRemap), 1e-3f, 1.0f);
  }
  if (m.sigmaTexture >= 0) orenNayarAB(textures.eval(uint32_t(m.sigmaTexture), tp).r, &scratch->orenA, &scratch->orenB);
  if (m.thicknessTexture >= 0) scratch->thickness = std::max(textures.eval(uint32_t(m.thicknessTexture), tp).r, 0.0f);
  return *scratch;
}

}  // namespace tdpm
