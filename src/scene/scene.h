// scene/scene.h — the built scene every later stage reads: camera, shutter,
// materials, lights, objects with their motion and swept bounds, and ray
// queries (through EmbreeScene) that return fully shaded hit records.
// Built once per render from a validated SceneDescription; read-only after.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "math/bounds.h"
#include "media/medium.h"
#include "motion/motion.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/description.h"
#include "scene/embree_scene.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/quadric.h"
#include "scene/texture.h"

namespace tdpm {

struct SceneObject {
  enum class Kind : uint8_t { Sphere, Triangles, Quadric };
  std::string name;
  Kind kind = Kind::Triangles;
  bool reverseOrientation = false;  // hit normals flipped (ShapeDesc::reverseOrientation)
  Quadric quadric;                  // Kind::Quadric: the disk or cylinder
  uint32_t material = 0;
  Motion motion;                    // object-to-world over the shutter
  Bounds3f objectBounds;            // object space
  Bounds3f sweptBounds;             // world, over the whole shutter
  std::vector<Vec3f> faceNormals;   // triangles: object-space unit normals
  std::vector<Vec2f> uvs;           // triangles: (u, v) per corner, or empty (pbrt's default per triangle)
  // Triangles: shading normals per corner (scene::ShapeDesc::normals), or
  // empty (the geometric normal shades). World space (inverse transpose of
  // the placement, not normalised) when the object is still, object space
  // when it moves (Scene::interpolatedNormal transforms them per hit).
  std::vector<Vec3f> normals;
  // Triangles, only in scenes with shading normals (bump / normal maps):
  // object-space dp/du and dp/dv per triangle (pbrt's Triangle, from uvs).
  std::vector<Vec3f> dpdu, dpdv;
  // Static objects only (precomputed, so a hit costs no matrix inverse):
  std::vector<Vec3f> worldNormals;  // triangles: world-space unit normals
  Vec3f worldCentre;                // sphere centre
  Affine3f inversePlacement;
  // Media on its two sides (indices into Scene::media, -1 vacuum); when
  // !present the object is no medium boundary (a ray keeps its medium).
  scene::MediumInterfaceDesc mediumInterface;
  bool isInterface = false;  // "interface" material: no surface, only the media boundary
  // The medium a ray leaving the surface along w is in (pbrt's rule: the
  // side w points into), or `current` when the object bounds no media.
  int32_t mediumAfter(Vec3f n, Vec3f w, int32_t current) const {
    if (!mediumInterface.present) return current;
    return dot(w, n) > 0 ? mediumInterface.outside : mediumInterface.inside;
  }
};

struct Hit {
  float t = 0;
  Vec3f p;             // world position
  Vec3f n;             // outward geometric normal, world, unit
  Vec3f localP;        // object-space position (textures)
  uint32_t object = 0; // index into objects (when !isLight)
  uint32_t primitive = 0;  // triangle within the object
  Vec2f bary;              // triangles: barycentrics of its vertices 1 and 2
  int32_t light = -1;  // index into lights when an area light was hit
  float time01 = 0;    // the ray's normalised time (a moving object's tangents)
  bool isLight() const { return light >= 0; }
};

class Scene {
 public:
  static std::unique_ptr<Scene> build(const scene::SceneDescription& desc);

  // Closest hit along o + s d, s in (0, tFar), at normalised time time01.
  bool intersect(Vec3f o, Vec3f d, float tFar, float time01, Hit& hit) const;
  bool occluded(Vec3f o, Vec3f d, float tFar, float time01) const;
  // The surface's (u, v) at a hit on an object: interpolated per triangle
  // corner, or pbrt's sphere parameterisation (u = phi / 2 pi about local
  // +z, v = theta / pi from the -z pole). Only textured materials ask.
  Vec2f uvAt(const Hit& hit) const;
  // The material's albedo at the hit: its texture node if it has one,
  // clamped to [0, 1] as pbrt-v4 clamps a reflectance (energy).
  Rgb albedoAt(const Material& m, const Hit& hit) const {
    if (m.albedoTexture < 0) return m.albedo.at(hit.localP);
    Rgb v = textures.eval(uint32_t(m.albedoTexture), {uvAt(hit), hit.localP});
    return {std::clamp(v.r, 0.0f, 1.0f), std::clamp(v.g, 0.0f, 1.0f), std::clamp(v.b, 0.0f, 1.0f)};
  }
  // The material the BSDF sees at the hit: m itself, or (textured
  // parameters) a copy in `scratch` with the values at the hit: the
  // specular colour clamped to [0, 1] (a conductor's reflectance becomes
  // its eta, k), a textured eta / k (clamped to eta >= 1e-3, k >= 0), a textured ior (>= 1), the roughness remapped and clamped to [1e-3, 1] (never a
  // delta lobe on a material classified non-delta), Oren-Nayar's A, B from a
  // textured sigma, a textured coating thickness (>= 0). An empty optional costs
  // an untextured hit nothing.
  const Material& shadedMaterial(const Material& m, const Hit& hit, std::optional<Material>& scratch) const {
    if (m.specularTexture < 0 && m.roughnessTexture < 0 && m.baseRoughnessTexture < 0 && m.etaTexture < 0 &&
        m.kTexture < 0 && m.iorTexture < 0 && m.sigmaTexture < 0 && m.thicknessTexture < 0)
      return m;
    return shadeTextured(m, hit, scratch);
  }
  // The shading context at a hit on an object for the material materialAt
  // gave (textured parameters in `scratch`, as shadedMaterial): its frame
  // about the geometric normal, or about the shading normal when the mesh
  // has vertex normals or the material a bump / normal map
  // (scene/shading_normal.cpp). Every integrator
  // builds its contexts here, so shading normals apply everywhere.
  // mixWeight: what materialAt gave for a per-channel mix (1 otherwise).
  ShadingContext shadingContext(const Material& m, const Hit& hit, Vec3f wo, std::optional<Material>& scratch,
                                Rgb mixWeight = Rgb(1.0f)) const {
    ShadingContext c =
        !m.hasShadingNormal() && objects[hit.object].normals.empty()
            ? makeShadingContext(shadedMaterial(m, hit, scratch), albedoAt(m, hit), hit.n, wo)
            : makeShadingContext(shadedMaterial(m, hit, scratch), albedoAt(m, hit), hit.n, wo, shadingNormal(m, hit));
    if (mixWeight.r != 1.0f || mixWeight.g != 1.0f || mixWeight.b != 1.0f) {
      c.mixWeighted = true;
      c.mixWeight = mixWeight;
    }
    return c;
  }
  // The shading normal at the hit (unit, on hit.n's side): the mesh's
  // interpolated vertex normals when it has them (else hit.n), perturbed by
  // the material's bump or normal map as pbrt-v4 does: BumpMap (the
  // displaced surface's dp/du x dp/dv) or NormalMap (the map's tangent-space
  // normal in the frame of dp/du and the normal).
  Vec3f shadingNormal(const Material& m, const Hit& hit) const;
  // A mesh hit's vertex normals blended by its barycentrics, in world space,
  // unit, on hit.n's side (pbrt-v4's Triangle: ns = b0 n0 + b1 n1 + b2 n2,
  // normalised); hit.n where the blend vanishes. Only for objects with normals.
  Vec3f interpolatedNormal(const Hit& hit) const;
  // World-space dp/du, dp/dv at a hit on an object, pbrt's for each shape
  // (triangles: from their (u, v), or a frame about the normal when those
  // are degenerate). Triangles need the tangents built (scene with shading normals).
  void surfaceTangents(const Hit& hit, Vec3f* dpdu, Vec3f* dpdv) const;
  // The material a hit on an object uses, seen from direction wo:
  // resolveMaterial (material.h) with each mix's amount at the hit, its
  // texture evaluated there when it has one (pbrt-v4's FloatTexture amount).
  // A per-channel mix (Material::mixPerChannel) multiplies *mixWeight by
  // its choice's weight, which the caller passes on to shadingContext:
  // every integrator does, so the per-channel blend holds in each. Without
  // mixWeight (tests, classification) the choice alone.
  const Material& materialAt(const Hit& hit, Vec3f wo, Rgb* mixWeight = nullptr) const {
    Rgb channels;  // the per-channel amount of the mix being resolved
    return resolveMaterial(
        materials.data(), objects[hit.object].material, hit.p, wo,
        [&](const Material& m) {
          if (!m.mixPerChannel)
            return m.amountTexture < 0 ? m.mixAmount : textures.eval(uint32_t(m.amountTexture), {uvAt(hit), hit.localP}).r;
          channels = channelAmount(m, hit);
          return (channels.r + channels.g + channels.b) * (1.0f / 3.0f);
        },
        [&](const Material& m, bool second, float p) {
          if (!m.mixPerChannel || !mixWeight) return;
          *mixWeight = *mixWeight * (second ? channels / p : (Rgb(1.0f) - channels) / (1.0f - p));
        });
  }
  // A per-channel mix's amount at the hit, each channel clamped to [0, 1] (pbrt-v3's Clamp()).
  Rgb channelAmount(const Material& m, const Hit& hit) const {
    Rgb a = m.amountTexture < 0 ? m.mixAmountRgb : textures.eval(uint32_t(m.amountTexture), {uvAt(hit), hit.localP});
    return {std::clamp(a.r, 0.0f, 1.0f), std::clamp(a.g, 0.0f, 1.0f), std::clamp(a.b, 0.0f, 1.0f)};
  }
  // The raw ray tracer (benchmarks compare our tracing against it).
  const EmbreeScene& embree() const { return embree_; }
  // Origin for a ray leaving surface point p (normal n) in direction d:
  // pushed off the surface by a distance relative to the scene's scale.
  Vec3f spawnOrigin(Vec3f p, Vec3f n, Vec3f d) const;
  // Whether the segment o + s d, s in [0, tMax], passes through the swept
  // bounds of anything that moves (conservative: bounds, not surfaces).
  bool segmentMeetsMotion(Vec3f o, Vec3f d, float tMax) const;
  float epsilon(Vec3f p) const;
  // The length the scene's relative tolerances are taken from: the
  // diagonal of its bounds, but at most kViewScales times the camera's
  // distance to its target. A floor of 1e8 around a scene of a few metres
  // must not make ray offsets of 20 m (it did: the image mean fell from
  // 0.05 to 2e-6, and at 1e7 the caustic vanished) nor photon search radii
  // of 3e6 m. The shipped scenes are 3x (cube-caustic) to 16x
  // (truck-laser's 80 m ground) their view distance: unchanged.
  float extent() const { return extent_; }
  static constexpr float kViewScales = 20.0f;
  // Sets extent() and the epsilon's scale from the bounds (call after they
  // are final) and the camera's keyframes.
  void computeScale(const scene::CameraDesc& camera);
  // Fills media, cameraMedium, lightMedia and each object's medium
  // interface from the description (scene/build_media.cpp).
  void buildMedia(const scene::SceneDescription& desc);

  Camera camera;
  Shutter shutter;
  std::vector<Material> materials;
  TextureSet textures;
  std::vector<SceneObject> objects;
  std::vector<Light> lights;
  std::vector<uint32_t> environmentLights;  // indices into lights: what an escaping ray meets
  Rgb background{0.0f};
  Bounds3f bounds;                    // everything, over the whole shutter
  std::vector<Bounds3f> movingBounds; // swept bounds of each moving object / area light
  bool hasMotion = false;             // any moving object, light or camera
  // Participating media (media/medium.h): one runtime medium per
  // description medium that is used, and one more per object a grid moves
  // with. Empty unless the scene has media: every integrator but the
  // volumetric path tracer refuses such scenes (render/renderer.cpp).
  std::vector<media::Medium> media;
  int32_t cameraMedium = -1;          // index into media, -1 vacuum
  std::vector<int32_t> lightMedia;    // per light: the medium it emits into
  bool hasMedia() const { return !media.empty(); }
  // Where media end: the exterior medium fills the sphere around the scene's
  // bounds and the camera's positions (docs/media.md, "The media's world"),
  // vacuum beyond, so that a sun or sky reaches the scene through a finite
  // depth of fog, the same for shadow rays, escaping eye and path rays and
  // the photons emitted from outside (scene/build_media.cpp).
  Vec3f mediaWorldCentre{0, 0, 0};
  float mediaWorldRadius = 0.0f;
  // The distance along unit d from o to where the media's world ends (its
  // sphere's far root; 0 when the line misses it or leaves it behind o):
  // what a ray that escapes the scene's geometry crosses of a medium.
  float mediaExit(Vec3f o, Vec3f d) const {
    Vec3f oc = o - mediaWorldCentre;
    float b = dot(oc, d), c = dot(oc, oc) - mediaWorldRadius * mediaWorldRadius;
    float disc = b * b - c;
    if (disc <= 0.0f) return 0.0f;
    return std::max(0.0f, -b + std::sqrt(disc));
  }
  // The near root (negative when o is inside): where a ray from outside
  // enters the media's world.
  float mediaEntry(Vec3f o, Vec3f d) const {
    Vec3f oc = o - mediaWorldCentre;
    float b = dot(oc, d), c = dot(oc, oc) - mediaWorldRadius * mediaWorldRadius;
    float disc = b * b - c;
    return disc <= 0.0f ? 0.0f : -b - std::sqrt(disc);
  }

 private:
  const Material& shadeTextured(const Material& m, const Hit& hit, std::optional<Material>& scratch) const;
  EmbreeScene embree_;
  // Embree geometry id -> object index (>= 0) or -(light index) - 1.
  std::vector<int32_t> geometryOwner_;
  float sceneScale_ = 1.0f;  // max(|bounds' coordinates|, diagonal), clipped like extent_
  float extent_ = 1.0f;
};

}  // namespace tdpm
