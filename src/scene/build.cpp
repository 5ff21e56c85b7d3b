// scene/build.cpp — SceneDescription -> Scene: tessellates quads and boxes
// (spheres, disks and cylinders stay analytic),
// resamples motion into time steps, uploads geometry, derives light
// constants, swept bounds and the scene's scale.
#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.h"
#include "scene/bsdf_pbrt.h"
#include "scene/build_media.h"
#include "scene/limits.h"
#include "scene/scene.h"
#include "scene/subdivision.h"

namespace tdpm {

namespace {

using scene::ShapeDesc;

struct TriangleMesh {
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;
  std::vector<Vec2f> uvs;  // per corner, or empty
  std::vector<Vec3f> normals;  // shading normals per corner, or empty
};

// Quad in the local x-z plane, normal +y (counter-clockwise seen from +y).
TriangleMesh makeQuad(float sx, float sz) {
  float x = 0.5f * sx, z = 0.5f * sz;
  // (u, v): u along +x, v along -z, so an image lies upright seen from +y
  // with -z up (its top row at z = -sz / 2).
  return {{{-x, 0, -z}, {-x, 0, z}, {x, 0, z}, {x, 0, -z}},
          {0, 1, 2, 0, 2, 3},
          {{0, 1}, {0, 0}, {1, 0}, {0, 1}, {1, 0}, {1, 1}},
          {}};
}

// Axis-aligned box centred at the origin, outward-facing triangles.
TriangleMesh makeBox(Vec3f size) {
  Vec3f h = size * 0.5f;
  TriangleMesh m;
  for (int c = 0; c < 8; ++c) m.vertices.push_back({(c & 1) ? h.x : -h.x, (c & 2) ? h.y : -h.y, (c & 4) ? h.z : -h.z});
  // Each face: four corners counter-clockwise seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

std::vector<MotionKey> toKeys(const scene::MotionDesc& d) {
  std::vector<MotionKey> keys(d.times.size());
  for (size_t i = 0; i < keys.size(); ++i)
    keys[i] = {d.times[i], d.poses[i].translate, d.poses[i].rotate, d.poses[i].scale};
  return keys;
}

Motion makeMotion(const scene::TransformDesc& placement, const scene::MotionDesc& motion, const Shutter& shutter) {
  if (motion.empty()) return Motion::still(placement.matrix());
  MotionKey p{0.0f, placement.translate, placement.rotate, placement.scale};
  return Motion::keyframed(p, toKeys(motion), shutter);
}

// A mesh into Embree: world-space vertices when it stands still, else its
// object-space vertices under the motion's step transforms.
uint32_t addMesh(EmbreeScene& embree, const Motion& m, const TriangleMesh& mesh) {
  if (!m.moving()) {
    std::vector<Vec3f> world;
    world.reserve(mesh.vertices.size());
    for (Vec3f v : mesh.vertices) world.push_back(m.step(0).point(v));
    return embree.addTriangles(world, mesh.indices);
  }
  std::vector<Affine3f> steps;
  for (int s = 0; s < m.stepCount(); ++s) steps.push_back(m.step(s));
  return embree.addMovingTriangles(mesh.vertices, mesh.indices, steps);
}

// Uniform scale factor of a step matrix (spheres require uniform scale).
float uniformScale(const Affine3f& m) { return std::cbrt(std::fabs(m.determinant3())); }

// The disk or cylinder of a shape (parse.cpp and the pbrt import checked
// the radii, heights and phiMax).
Quadric toQuadric(const ShapeDesc& d) {
  Quadric q;
  q.kind = d.type == ShapeDesc::Type::Disk ? Quadric::Kind::Disk : Quadric::Kind::Cylinder;
  q.radius = d.radius;
  q.innerRadius = d.innerRadius;
  q.height = d.height;
  q.zMin = d.zMin;
  q.zMax = d.zMax;
  q.phiMax = std::min(d.phiMax, 360.0f) * kPi / 180.0f;
  return q;
}

Material toMaterial(const scene::MaterialDesc& d) {
  Material m;
  switch (d.type) {
    case scene::MaterialDesc::Type::Diffuse: m.type = Material::Type::Diffuse; break;
    case scene::MaterialDesc::Type::Mirror: m.type = Material::Type::Mirror; break;
    case scene::MaterialDesc::Type::Dielectric: m.type = Material::Type::Dielectric; break;
    case scene::MaterialDesc::Type::Metal: m.type = Material::Type::Metal; break;
    case scene::MaterialDesc::Type::Plastic: m.type = Material::Type::Plastic; break;
    case scene::MaterialDesc::Type::Conductor: m.type = Material::Type::Conductor; break;
    case scene::MaterialDesc::Type::RoughDielectric: m.type = Material::Type::RoughDielectric; break;
    case scene::MaterialDesc::Type::Uber: m.type = Material::Type::Uber; break;
    case scene::MaterialDesc::Type::Substrate: m.type = Material::Type::Substrate; break;
    case scene::MaterialDesc::Type::CoatedDiffuse: m.type = Material::Type::CoatedDiffuse; break;
    case scene::MaterialDesc::Type::CoatedConductor: m.type = Material::Type::CoatedConductor; break;
    case scene::MaterialDesc::Type::Mix: m.type = Material::Type::Mix; break;
    case scene::MaterialDesc::Type::Interface: m.type = Material::Type::Interface; break;
  }
  m.albedo.kind = d.albedo.kind == scene::TextureDesc::Kind::Checker ? Texture::Kind::Checker : Texture::Kind::Constant;
  m.albedo.a = d.albedo.color;
  m.albedo.b = d.albedo.color2;
  m.albedo.invScale = 1.0f / d.albedo.scale;
  m.albedoTexture = d.albedoTexture;
  m.specularTexture = d.specularTexture;  // node i of the TextureSet is desc.textures[i]
  m.roughnessTexture = d.roughnessTexture;
  m.baseRoughnessTexture = d.baseRoughnessTexture;
  m.etaTexture = d.etaTexture;
  m.kTexture = d.kTexture;
  m.amountTexture = d.amountTexture;
  m.iorTexture = d.iorTexture;
  m.bumpTexture = d.bumpTexture;
  m.bumpScale = d.bumpScale;
  using R = scene::MaterialDesc::Remap;
  m.roughnessRemap = d.roughnessRemap == R::PbrtV3   ? RoughnessRemap::PbrtV3
                     : d.roughnessRemap == R::PbrtV4 ? RoughnessRemap::PbrtV4
                                                     : RoughnessRemap::None;
  m.specular = d.specular;
  m.ior = d.ior;
  // Keep GGX away from alpha -> 0, where D is a numerically unstable spike.
  m.alpha = std::max(d.roughness, 1e-3f);
  // pbrt's materials (scene/bsdf_pbrt.cpp): below pbrt-v4's smooth limit a
  // conductor is delta and a dielectric the smooth one; a coating keeps the
  // sharp GGX floor above (its delta lobe beside a diffuse one has no place
  // in tdpm's delta / non-delta split: docs/scene-format.md).
  using T = Material::Type;
  if (m.type == T::Conductor) m.alpha = d.roughness < kSmoothAlpha ? 0.0f : d.roughness;
  if (m.type == T::RoughDielectric && d.roughness < kSmoothAlpha) m.type = T::Dielectric;
  m.eta = d.eta;
  m.k = d.k;
  if (m.type == T::CoatedConductor) {
    m.eta = d.eta / d.ior;  // the conductor under the coating sees index ior, not 1
    m.k = d.k / d.ior;
    m.baseAlpha = std::max(d.baseRoughness, kSmoothAlpha);
  }
  m.thickness = d.thickness;
  if (m.type == T::CoatedDiffuse || m.type == T::CoatedConductor) m.coatInternal = coatInternalReflectance(d.ior);
  m.mixOf[0] = d.mix[0];
  m.mixOf[1] = d.mix[1];
  m.mixAmount = d.amount;
  m.mixPerChannel = d.amountPerChannel;
  m.mixAmountRgb = d.amountRgb;
  m.thicknessTexture = d.thicknessTexture;
  // pbrt-v3's matte with a sigma: Oren-Nayar; sigma 0 stays Lambert (bsdf.cpp's own path).
  if (m.type == T::Diffuse && (d.sigma > 0.0f || d.sigmaTexture >= 0)) {
    m.type = T::OrenNayar;
    orenNayarAB(d.sigma, &m.orenA, &m.orenB);
    m.sigmaTexture = d.sigmaTexture;
  }
  return m;
}

// A textured roughness: the per-hit alpha comes from the texture
// (Scene::shadedMaterial); the classification (isDeltaOnly, isGlossy) from
// the alphas the texture's range allows, fixed per material. A conductor or
// rough dielectric is delta (smooth) only when every value is below the
// smooth limit; otherwise `alpha` is the sharpest alpha in range (at least
// 1e-3), so a texture that reaches a sharp metal anywhere makes the whole
// material a caustic bounce (docs/scene-format.md says why).
// The alphas a roughness texture can give, [*aLo, *aHi]; an error outside [0, 1].
void texturedAlphaRange(const Material& m, const scene::MaterialDesc& d, int32_t node, const TextureSet& textures,
                        float* aLo, float* aHi) {
  if (node >= int32_t(textures.nodes.size()))
    throw Error("material \"" + d.name + "\": roughness texture index out of range");
  float lo, hi;
  textures.range(uint32_t(node), &lo, &hi);
  *aLo = roughnessToAlpha(lo, m.roughnessRemap);
  *aHi = roughnessToAlpha(hi, m.roughnessRemap);
  if (*aLo > *aHi) std::swap(*aLo, *aHi);
  if (!(lo >= 0) || !(*aHi <= 1))
    throw Error("material \"" + d.name + "\": its roughness texture's values [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "] give GGX alphas [" + std::to_string(*aLo) + ", " + std::to_string(*aHi) +
                "], outside the [0, 1] tdpm supports");
}

void classifyTexturedRoughness(Material& m, const scene::MaterialDesc& d, const TextureSet& textures) {
  float aLo, aHi;
  if (d.baseRoughnessTexture >= 0)  // a coated conductor's base: per hit only, no classification
    texturedAlphaRange(m, d, d.baseRoughnessTexture, textures, &aLo, &aHi);
  if (d.roughnessTexture < 0) return;
  texturedAlphaRange(m, d, d.roughnessTexture, textures, &aLo, &aHi);
  using T = Material::Type;
  if (aHi < kSmoothAlpha && (m.type == T::Conductor || m.type == T::RoughDielectric)) {
    m.roughnessTexture = -1;  // smooth everywhere: as a constant roughness 0
    m.alpha = 0.0f;
    if (m.type == T::RoughDielectric) m.type = T::Dielectric;
    return;
  }
  if (m.type == T::Dielectric) m.type = T::RoughDielectric;  // JSON: "dielectric" with a roughness texture
  m.alpha = std::max(aLo, kSmoothAlpha);
}

// A textured ior: every value the texture can give at least 1 (as a
// constant ior must be; the dielectric BSDF assumes the outside is the
// lower index).
void checkTexturedIor(const scene::MaterialDesc& d, const TextureSet& textures) {
  if (d.iorTexture >= int32_t(textures.nodes.size()))
    throw Error("material \"" + d.name + "\": ior texture index out of range");
  float lo, hi;
  textures.range(uint32_t(d.iorTexture), &lo, &hi);
  if (!(lo >= 1))
    throw Error("material \"" + d.name + "\": its ior texture's values [" + std::to_string(lo) + ", " + std::to_string(hi) +
                "] reach below 1, which tdpm does not support (an ior must be at least 1)");
}

// A material's texture index (sigma, thickness, a per-channel amount): none or a node of the set.
void checkTextureIndex(const scene::MaterialDesc& d, int32_t node, const char* what, const TextureSet& textures) {
  if (node >= int32_t(textures.nodes.size()))
    throw Error("material \"" + d.name + "\": " + what + " texture index out of range");
}

// A textured coating thickness: every value at least 0 (as the constant;
// a negative optical depth would make the layer amplify).
void checkTexturedThickness(const scene::MaterialDesc& d, const TextureSet& textures) {
  float lo, hi;
  textures.range(uint32_t(d.thicknessTexture), &lo, &hi);
  if (!(lo >= 0))
    throw Error("material \"" + d.name + "\": its thickness texture's values [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "] reach below 0; a coating's thickness must not be negative");
}

// A mix's components' classification (Material::causticTarget), through
// mixes of mixes (state: 0 unseen, 1 on the stack, 2 done); a mix that
// reaches itself is refused.
void classifyMix(std::vector<Material>& ms, const std::vector<scene::MaterialDesc>& desc, size_t i,
                 std::vector<uint8_t>& state) {
  if (state[i] == 2) return;
  if (state[i] == 1) throw Error("material \"" + desc[i].name + "\": a mix material that contains itself");
  state[i] = 1;
  Material& m = ms[i];
  for (uint32_t c : m.mixOf) {
    if (c >= ms.size()) throw Error("material \"" + desc[i].name + "\": mix component index out of range");
    if (ms[c].type == Material::Type::Mix) classifyMix(ms, desc, c, state);
    const Material& k = ms[c];
    m.mixDelta = m.mixDelta || k.isDeltaOnly() || k.mixDelta;
    m.mixCaustic = m.mixCaustic || k.isCausticBounce() || k.mixCaustic;
  }
  state[i] = 2;
}

// Per-step radii and normals (sphere, disk: Embree blends them between
// steps, and so does the light's frame) and a mesh emitter's triangles and
// CDF by area (world space when still, object space when moving).
void prepareEmitter(Light& l, const scene::LightDesc& d) {
  for (int i = 0; i < l.motion.stepCount(); ++i) {
    const Affine3f& m = l.motion.step(i);
    // A disk's radius is its local x axis's (parse.cpp keeps x and z alike).
    l.stepRadius.push_back(l.shape == Light::AreaShape::Disk ? length(m.vector({l.radius, 0, 0}))
                                                             : l.radius * uniformScale(m));
    l.stepNormal.push_back(normalize(m.normal({0, -1, 0})));
  }
  if (l.shape != Light::AreaShape::Mesh) return;
  auto mesh = std::make_shared<EmitterMesh>();
  if (d.mesh.loopLevels >= 0) {
    scene::LoopMesh refined = scene::loopSubdivide(d.mesh.vertices, d.mesh.indices, d.mesh.loopLevels,
                                                   scene::limits::kMaxSubdividedTriangles);
    mesh->vertices = std::move(refined.vertices);
    mesh->indices = std::move(refined.indices);
  } else {
    mesh->vertices = d.mesh.vertices;
    mesh->indices = d.mesh.indices;
  }
  const Affine3f& m0 = l.motion.step(0);
  bool moving = l.motion.moving();
  if (!moving) {
    // World vertices; a mirroring placement's winding swapped back, so that
    // the emitting side is the object-space normal transformed as a normal
    // (as a moving light's, and as objects' normals are).
    for (Vec3f& v : mesh->vertices) v = m0.point(v);
    if (m0.determinant3() < 0)
      for (size_t i = 0; i + 2 < mesh->indices.size(); i += 3) std::swap(mesh->indices[i + 1], mesh->indices[i + 2]);
  }
  mesh->det0 = std::fabs(m0.determinant3());
  double total = 0;
  Vec3f centroid{0, 0, 0};
  std::vector<double> acc;
  for (size_t i = 0; i < mesh->indices.size(); i += 3) {
    Vec3f a = mesh->vertices[mesh->indices[i]], b = mesh->vertices[mesh->indices[i + 1]],
          c = mesh->vertices[mesh->indices[i + 2]];
    float area = moving ? 0.5f * length(cross(m0.vector(b - a), m0.vector(c - a))) : 0.5f * length(cross(b - a, c - a));
    total += area;
    centroid += (a + b + c) * (area / 3.0f);
    acc.push_back(total);
  }
  mesh->area0 = float(total);
  mesh->centroid = total > 0 ? centroid / float(total) : Vec3f(0, 0, 0);
  for (double a : acc) mesh->cdf.push_back(total > 0 ? float(a / total) : 1.0f);
  if (!mesh->cdf.empty()) mesh->cdf.back() = 1.0f;
  l.mesh = std::move(mesh);
}

TexNodeInput toInput(const scene::TexInput& in) { return {in.texture, in.value}; }

// pbrt's Triangle dp/du, dp/dv (object space) from each triangle's (u, v):
// its corners', or pbrt's default (0, 0), (1, 0), (1, 1); a degenerate uv
// mapping gets a frame about the face normal instead.
void triangleTangents(const TriangleMesh& mesh, SceneObject& o) {
  const bool corners = o.uvs.size() == mesh.indices.size();  // o.uvs: the mesh's, moved there
  const Vec2f fallback[3] = {{0, 0}, {1, 0}, {1, 1}};
  o.dpdu.reserve(mesh.indices.size() / 3);
  o.dpdv.reserve(mesh.indices.size() / 3);
  for (size_t i = 0; i < mesh.indices.size(); i += 3) {
    Vec3f p0 = mesh.vertices[mesh.indices[i]], p1 = mesh.vertices[mesh.indices[i + 1]],
          p2 = mesh.vertices[mesh.indices[i + 2]];
    const Vec2f* uv = corners ? &o.uvs[i] : fallback;
    Vec2f duv02{uv[0].x - uv[2].x, uv[0].y - uv[2].y}, duv12{uv[1].x - uv[2].x, uv[1].y - uv[2].y};
    Vec3f dp02 = p0 - p2, dp12 = p1 - p2;
    float det = duv02.x * duv12.y - duv02.y * duv12.x;
    Vec3f du, dv;
    bool ok = std::fabs(det) >= 1e-9f;
    if (ok) {
      float inv = 1.0f / det;
      du = (dp02 * duv12.y - dp12 * duv02.y) * inv;
      dv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
      ok = length(cross(du, dv)) > 0 && std::isfinite(du.x + du.y + du.z + dv.x + dv.y + dv.z);
    }
    if (!ok) {
      Vec3f n = cross(p1 - p0, p2 - p0);
      float l = length(n);
      Frame f(l > 0 ? n / l : Vec3f(0, 1, 0));
      du = f.s;
      dv = f.t;
    }
    o.dpdu.push_back(du);
    o.dpdv.push_back(dv);
  }
}

// desc.textures -> flat nodes (same indices) and each image's texels once.
TextureSet toTextures(const std::vector<scene::TextureDef>& defs) {
  using K = scene::TextureDef::Kind;
  TextureSet set;
  std::map<const image::ImageRgb*, uint32_t> imageIndex;
  for (const scene::TextureDef& d : defs) {
    TextureNode n;
    switch (d.kind) {
      case K::Constant: n.kind = TextureNode::Kind::Constant; break;
      case K::Image: n.kind = TextureNode::Kind::Image; break;
      case K::Scale: n.kind = TextureNode::Kind::Scale; break;
      case K::Mix: n.kind = TextureNode::Kind::Mix; break;
      case K::Checkerboard: n.kind = TextureNode::Kind::Checkerboard; break;
      case K::Checker3D: n.kind = TextureNode::Kind::Checker3D; break;
    }
    n.a = toInput(d.a);
    n.b = toInput(d.b);
    n.amount = toInput(d.amount);
    n.uscale = d.uscale, n.vscale = d.vscale, n.udelta = d.udelta, n.vdelta = d.vdelta;
    n.invCell = 1.0f / d.cell;
    if (d.kind == K::Image) {
      TDPM_ASSERT(d.image && !d.image->empty(), "image texture without texels");
      auto [it, added] = imageIndex.try_emplace(d.image.get(), uint32_t(set.images.size()));
      if (added) {
        set.images.push_back({d.image->width, d.image->height, set.texels.size()});
        set.texels.insert(set.texels.end(), d.image->pixels.begin(), d.image->pixels.end());
      }
      n.image = it->second;
      n.wrap = d.wrap == scene::TextureDef::Wrap::Repeat  ? TextureNode::Wrap::Repeat
               : d.wrap == scene::TextureDef::Wrap::Clamp ? TextureNode::Wrap::Clamp
                                                          : TextureNode::Wrap::Black;
      n.bilinear = d.filter == scene::TextureDef::Filter::Bilinear;
      n.scale = d.scale;
      n.invert = d.invert;
      n.firstChannel = d.isFloat;
    }
    set.nodes.push_back(n);
  }
  return set;
}

Light toLight(const scene::LightDesc& d, const Shutter& shutter) {
  Light l;
  switch (d.type) {
    case scene::LightDesc::Type::Point: l.type = Light::Type::Point; break;
    case scene::LightDesc::Type::Spot: l.type = Light::Type::Spot; break;
    case scene::LightDesc::Type::Directional: l.type = Light::Type::Directional; break;
    case scene::LightDesc::Type::Area: l.type = Light::Type::Area; break;
    case scene::LightDesc::Type::Environment: l.type = Light::Type::Environment; break;
  }
  l.power = d.power;
  l.position = d.position;
  l.direction = normalize(d.direction);
  l.cosTotal = std::cos(d.coneAngle * kPi / 180.0f);
  l.cosFalloffStart = std::cos(d.falloffStart * kPi / 180.0f);
  l.size = d.areaSize;
  l.radius = d.radius;
  l.twoSided = d.twoSided;
  l.reversed = d.reverseOrientation;
  switch (d.areaShape) {
    case scene::LightDesc::AreaShape::Rect: l.shape = Light::AreaShape::Rect; break;
    case scene::LightDesc::AreaShape::Sphere: l.shape = Light::AreaShape::Sphere; break;
    case scene::LightDesc::AreaShape::Disk: l.shape = Light::AreaShape::Disk; break;
    case scene::LightDesc::AreaShape::Mesh: l.shape = Light::AreaShape::Mesh; break;
  }
  l.motion = makeMotion(d.placement, d.motion, shutter);
  if (l.type == Light::Type::Environment) {
    Affine3f toWorld = d.placement.matrix();
    Rgb k = d.radiance * d.scale;
    l.env = std::make_shared<const EnvironmentMap>(d.map ? EnvironmentMap::fromLatLong(*d.map, k, toWorld)
                                                         : EnvironmentMap::constant(k, toWorld));
  }
  if (l.type == Light::Type::Area) prepareEmitter(l, d);
  finalizeLight(l);
  return l;
}

// An area light's emitter into Embree (camera and BSDF rays can hit it):
// its Embree id; `local` gets its object-space bounds.
uint32_t addEmitterShape(EmbreeScene& embree, const Light& l, Bounds3f& local) {
  std::vector<Vec3f> centres;
  for (int i = 0; i < l.motion.stepCount(); ++i) centres.push_back(l.motion.step(i).point({0, 0, 0}));
  switch (l.shape) {
    case Light::AreaShape::Rect: {
      TriangleMesh quad = makeQuad(l.size.x, l.size.y);
      for (Vec3f v : quad.vertices) local.extend(v);
      return addMesh(embree, l.motion, quad);
    }
    case Light::AreaShape::Sphere:
      local = {Vec3f(-l.radius), Vec3f(l.radius)};
      return embree.addSphere(centres, l.stepRadius);
    case Light::AreaShape::Disk:
      local = {{-l.radius, 0, -l.radius}, {l.radius, 0, l.radius}};
      return embree.addOrientedDisc(centres, l.stepNormal, l.stepRadius);
    case Light::AreaShape::Mesh: {
      TriangleMesh m{l.mesh->vertices, l.mesh->indices, {}, {}};
      if (!l.motion.moving()) return embree.addTriangles(m.vertices, m.indices);  // world vertices
      for (Vec3f v : m.vertices) local.extend(v);
      return addMesh(embree, l.motion, m);
    }
  }
  return ~0u;
}

// The emitter's Embree id; `swept` gets its world bounds over the shutter.
uint32_t addEmitterGeometry(EmbreeScene& embree, const Light& l, Bounds3f& swept) {
  Bounds3f local;
  uint32_t id = addEmitterShape(embree, l, local);
  if (l.shape == Light::AreaShape::Mesh && !l.motion.moving()) {
    for (Vec3f v : l.mesh->vertices) swept.extend(v);
  } else {
    swept = l.motion.sweptBounds(local);
  }
  return id;
}

}  // namespace

std::unique_ptr<Scene> Scene::build(const scene::SceneDescription& desc) {
  auto scene = std::make_unique<Scene>();
  Scene& s = *scene;
  s.camera = Camera(desc.camera);
  s.shutter = s.camera.shutter();
  s.background = desc.background;
  s.hasMotion = s.camera.moving();
  s.textures = toTextures(desc.textures);
  for (const auto& m : desc.materials) {
    s.materials.push_back(toMaterial(m));
    if (m.roughnessTexture >= 0 || m.baseRoughnessTexture >= 0) classifyTexturedRoughness(s.materials.back(), m, s.textures);
    if (m.iorTexture >= 0) checkTexturedIor(m, s.textures);
    checkTextureIndex(m, m.sigmaTexture, "sigma", s.textures);
    checkTextureIndex(m, m.thicknessTexture, "thickness", s.textures);
    if (m.amountPerChannel) checkTextureIndex(m, m.amountTexture, "amount", s.textures);
    if (m.thicknessTexture >= 0) checkTexturedThickness(m, s.textures);
  }
  // Normal maps: their texels join the texture images (one copy per file).
  bool shadingNormals = false;
  std::map<const image::ImageRgb*, int32_t> normalMaps;
  for (size_t i = 0; i < desc.materials.size(); ++i) {
    const scene::MaterialDesc& d = desc.materials[i];
    if (d.normalMap) {
      auto [it, added] = normalMaps.try_emplace(d.normalMap.get(), int32_t(s.textures.images.size()));
      if (added) {
        s.textures.images.push_back({d.normalMap->width, d.normalMap->height, s.textures.texels.size()});
        s.textures.texels.insert(s.textures.texels.end(), d.normalMap->pixels.begin(), d.normalMap->pixels.end());
      }
      s.materials[i].normalMapImage = it->second;
    }
    shadingNormals = shadingNormals || s.materials[i].hasShadingNormal();
  }
  std::vector<uint8_t> mixState(s.materials.size(), 0);
  for (size_t i = 0; i < s.materials.size(); ++i)
    if (s.materials[i].type == Material::Type::Mix) classifyMix(s.materials, desc.materials, i, mixState);

  const bool media = scene::usesMedia(desc);
  for (const auto& od : desc.objects) {
    // An "interface" surface is no surface: without media to bound it is
    // not in the scene at all (pbrt's importer drops it the same way).
    bool isInterface = desc.materials[od.material].type == scene::MaterialDesc::Type::Interface;
    if (isInterface && (!media || !od.media.present)) continue;
    SceneObject o;
    o.name = od.name;
    o.isInterface = isInterface;
    o.mediumInterface = od.media;  // description indices until buildMedia
    o.material = od.material;
    o.reverseOrientation = od.shape.reverseOrientation;
    o.motion = makeMotion(od.placement, od.motion, s.shutter);
    if (od.shape.type == ShapeDesc::Type::Sphere) {
      o.kind = SceneObject::Kind::Sphere;
      float r = od.shape.radius;
      o.objectBounds = {{-r, -r, -r}, {r, r, r}};
      std::vector<Vec3f> centres;
      std::vector<float> radii;
      for (int i = 0; i < o.motion.stepCount(); ++i) {
        centres.push_back(o.motion.step(i).point({0, 0, 0}));
        radii.push_back(r * uniformScale(o.motion.step(i)));
      }
      s.geometryOwner_.push_back(int32_t(s.objects.size()));
      uint32_t id = s.embree_.addSphere(centres, radii);
      TDPM_ASSERT(id + 1 == s.geometryOwner_.size(), "geometry ids out of order");
    } else if (od.shape.type == ShapeDesc::Type::Disk || od.shape.type == ShapeDesc::Type::Cylinder) {
      o.kind = SceneObject::Kind::Quadric;
      o.quadric = toQuadric(od.shape);
      o.objectBounds = quadricBounds(o.quadric);
      s.geometryOwner_.push_back(int32_t(s.objects.size()));
      uint32_t id = s.embree_.addQuadric(o.quadric, o.motion);
      TDPM_ASSERT(id + 1 == s.geometryOwner_.size(), "geometry ids out of order");
    } else {
      TriangleMesh mesh;
      switch (od.shape.type) {
        case ShapeDesc::Type::Quad: mesh = makeQuad(od.shape.size.x, od.shape.size.z); break;
        case ShapeDesc::Type::Box: mesh = makeBox(od.shape.size); break;
        default:
          if (od.shape.loopLevels >= 0) {
            // parse.cpp and the pbrt import checked topology and budget.
            scene::LoopMesh refined = scene::loopSubdivide(od.shape.vertices, od.shape.indices, od.shape.loopLevels,
                                             scene::limits::kMaxSubdividedTriangles);
            mesh = {std::move(refined.vertices), std::move(refined.indices), {}, {}};
          } else {
            mesh = {od.shape.vertices, od.shape.indices, od.shape.uvs, od.shape.normals};
          }
          break;
      }
      for (Vec3f v : mesh.vertices) o.objectBounds.extend(v);
      if (mesh.uvs.size() == mesh.indices.size()) o.uvs = std::move(mesh.uvs);
      if (mesh.normals.size() == mesh.indices.size()) o.normals = std::move(mesh.normals);
      if (shadingNormals) triangleTangents(mesh, o);
      o.faceNormals.reserve(mesh.indices.size() / 3);
      for (size_t i = 0; i < mesh.indices.size(); i += 3) {
        Vec3f a = mesh.vertices[mesh.indices[i]], b = mesh.vertices[mesh.indices[i + 1]],
              c = mesh.vertices[mesh.indices[i + 2]];
        Vec3f n = cross(b - a, c - a);
        float len = length(n);
        o.faceNormals.push_back(len > 0 ? n / len : Vec3f(0, 1, 0));
      }
      s.geometryOwner_.push_back(int32_t(s.objects.size()));
      uint32_t id = addMesh(s.embree_, o.motion, mesh);
      TDPM_ASSERT(id + 1 == s.geometryOwner_.size(), "geometry ids out of order");
    }
    if (!o.motion.moving()) {
      const Affine3f& m = o.motion.step(0);
      o.worldCentre = m.point({0, 0, 0});
      o.inversePlacement = m.inverse();
      o.worldNormals.reserve(o.faceNormals.size());
      for (Vec3f n : o.faceNormals) o.worldNormals.push_back(normalize(m.normal(n)));
      // Shading normals to world space once, as normals and not normalised
      // (the transform is linear, so interpolating them afterwards is
      // interpolating in object space; pbrt transforms them at load too).
      for (Vec3f& n : o.normals) n = o.inversePlacement.transposedVector(n);
    }
    o.sweptBounds = o.motion.sweptBounds(o.objectBounds);
    s.bounds.extend(o.sweptBounds);
    if (o.motion.moving()) {
      s.hasMotion = true;
      s.movingBounds.push_back(o.sweptBounds);
    }
    s.objects.push_back(std::move(o));
  }

  for (const auto& ld : desc.lights) {
    Light l = toLight(ld, s.shutter);
    if (l.motion.moving()) s.hasMotion = true;
    if (l.type == Light::Type::Area) {
      // The emitter is geometry too: camera and BSDF rays can hit it.
      s.geometryOwner_.push_back(-int32_t(s.lights.size()) - 1);
      Bounds3f swept;
      l.geometryId = addEmitterGeometry(s.embree_, l, swept);
      TDPM_ASSERT(l.geometryId + 1 == s.geometryOwner_.size(), "geometry ids out of order");
      s.bounds.extend(swept);
      if (l.motion.moving()) s.movingBounds.push_back(swept);
    } else if (l.type == Light::Type::Environment) {
      s.environmentLights.push_back(uint32_t(s.lights.size()));  // at infinity: no bounds
    } else if (l.type != Light::Type::Directional) {
      for (int i = 0; i < l.motion.stepCount(); ++i) s.bounds.extend(l.motion.step(i).point(l.position));
    }
    s.lights.push_back(std::move(l));
  }
  s.embree_.commit();
  s.computeScale(desc.camera);
  if (media) s.buildMedia(desc);
  return scene;
}

}  // namespace tdpm
