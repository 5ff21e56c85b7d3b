// scene/shading_normal.cpp — shading normals: meshes' interpolated vertex
// normals (pbrt-v4's Triangle), bump and normal maps on top of them
// (pbrt-v4's BumpMap and NormalMap, materials.h), and the surface tangents
// dp/du, dp/dv the maps are built from (pbrt's Sphere, Disk, Cylinder and
// Triangle). Only meshes with normals and materials with a bump or a normal
// map reach this file; every other hit keeps the geometric frame
// (Scene::shadingContext).
#include <algorithm>
#include <cmath>

#include "math/frame.h"
#include "scene/scene.h"

namespace tdpm {

namespace {

// pbrt-v4's du when the ray has no differentials (tdpm traces none).
constexpr float kBumpDelta = 0.0005f;

// Tangents in object space at object-space point q (pbrt's formulas).
void objectTangents(const SceneObject& obj, const Hit& hit, Vec3f q, Vec3f* dpdu, Vec3f* dpdv) {
  if (obj.kind == SceneObject::Kind::Sphere) {
    // u = phi / 2 pi, v = 1 - theta / pi (Scene::uvAt): pbrt's phiMax = 2 pi,
    // thetaMin = pi (the -z pole), thetaMax = 0.
    float r = length(q);
    float rxy = std::sqrt(q.x * q.x + q.y * q.y);
    float cosPhi = rxy > 0 ? q.x / rxy : 1.0f, sinPhi = rxy > 0 ? q.y / rxy : 0.0f;
    float sinTheta = r > 0 ? rxy / r : 0.0f;
    *dpdu = Vec3f(-2 * kPi * q.y, 2 * kPi * q.x, 0);
    *dpdv = Vec3f(q.z * cosPhi, q.z * sinPhi, -r * sinTheta) * (-kPi);
    return;
  }
  if (obj.kind == SceneObject::Kind::Quadric) {
    const Quadric& c = obj.quadric;
    *dpdu = Vec3f(-c.phiMax * q.y, c.phiMax * q.x, 0);
    if (c.kind == Quadric::Kind::Disk) {
      float rh = std::sqrt(q.x * q.x + q.y * q.y);
      *dpdv = rh > 0 ? Vec3f(q.x, q.y, 0) * ((c.innerRadius - c.radius) / rh) : Vec3f(c.innerRadius - c.radius, 0, 0);
    } else {
      *dpdv = Vec3f(0, 0, c.zMax - c.zMin);
    }
    return;
  }
  *dpdu = obj.dpdu[hit.primitive];
  *dpdv = obj.dpdv[hit.primitive];
}

// pbrt-v4's bilinear lookup of the map (repeat; row 0 at v = 1), as
// TextureSet::lookup, but in lerp form: where the four texels are equal the
// result is that texel exactly, so a flat map gives exactly (0, 0, 1).
Rgb normalMapTexel(const TextureSet& set, const TextureImage& im, Vec2f uv) {
  float x = uv.x * float(im.width) - 0.5f, y = (1.0f - uv.y) * float(im.height) - 0.5f;
  if (!(std::fabs(x) < 1e9f && std::fabs(y) < 1e9f)) return Rgb(0.5f, 0.5f, 1.0f);
  float fx = std::floor(x), fy = std::floor(y);
  int xi = int(fx), yi = int(fy);
  float dx = x - fx, dy = y - fy;
  auto W = TextureNode::Wrap::Repeat;
  Rgb a = set.texel(im, W, xi, yi), b = set.texel(im, W, xi + 1, yi);
  Rgb c = set.texel(im, W, xi, yi + 1), d = set.texel(im, W, xi + 1, yi + 1);
  Rgb top = a + (b - a) * dx, bottom = c + (d - c) * dx;
  return top + (bottom - top) * dy;
}

}  // namespace

void Scene::surfaceTangents(const Hit& hit, Vec3f* dpdu, Vec3f* dpdv) const {
  const SceneObject& obj = objects[hit.object];
  objectTangents(obj, hit, hit.localP, dpdu, dpdv);
  // Object to world: the placement at the ray's time (static: step 0).
  Affine3f m = obj.motion.moving() ? obj.motion.atNormalized(hit.time01) : obj.motion.step(0);
  *dpdu = m.vector(*dpdu);
  *dpdv = m.vector(*dpdv);
}

Vec3f Scene::interpolatedNormal(const Hit& hit) const {
  const SceneObject& obj = objects[hit.object];
  const Vec3f* c = &obj.normals[size_t(hit.primitive) * 3];
  const float b1 = hit.bary.x, b2 = hit.bary.y;
  // b0 c0 + b1 c1 + b2 c2 in lerp form: where the three corners are equal
  // the blend is that corner exactly, so normals equal to the face normals
  // give hit.n to the bit (and the image of the mesh without them).
  Vec3f n = c[0] + (c[1] - c[0]) * b1 + (c[2] - c[0]) * b2;
  // Moving: object space, transformed as Scene::intersect transforms hit.n.
  if (obj.motion.moving()) n = obj.motion.atNormalized(hit.time01).inverse().transposedVector(n);
  if (!(lengthSquared(n) > 0) || !std::isfinite(n.x + n.y + n.z)) return hit.n;
  n = normalize(n);
  // The geometric normal decides sides (the import turns windings to agree
  // with N as pbrt does; an OBJ's winding decides for its vn).
  return dot(n, hit.n) < 0 ? -n : n;
}

Vec3f Scene::shadingNormal(const Material& mat, const Hit& hit) const {
  const bool smooth = !objects[hit.object].normals.empty();
  if (!mat.hasShadingNormal()) return smooth ? interpolatedNormal(hit) : hit.n;  // vertex normals or none
  Vec3f dpdu, dpdv;
  surfaceTangents(hit, &dpdu, &dpdv);
  const Vec3f ng = hit.n;  // pbrt's n: the shape's orientation, ReverseOrientation applied
  Vec3f n = ng;            // the frame the map perturbs: pbrt-v4's shading.n
  if (smooth) {
    // pbrt-v4's Triangle shading frame about the interpolated normal:
    // ts = ns x dp/du, ss = ts x ns (dp/du made perpendicular to ns).
    n = interpolatedNormal(hit);
    Vec3f ts = cross(n, dpdu);
    if (lengthSquared(ts) > 0) {
      dpdu = cross(ts, n);
      dpdv = ts;
    } else {
      Frame f(n);
      dpdu = f.s;
      dpdv = f.t;
    }
  }
  Vec3f ns;
  if (mat.normalMapImage >= 0) {
    // pbrt-v4's NormalMap: the texel (2 c - 1, unit) in the frame x =
    // dp/du, z = n, y = z x x; lookups repeat, bilinear, row 0 at v = 1.
    Rgb c = normalMapTexel(textures, textures.images[size_t(mat.normalMapImage)], uvAt(hit));
    Vec3f t{2 * c.r - 1, 2 * c.g - 1, 2 * c.b - 1};
    float tl = length(t);
    if (!(tl > 0)) return n;
    t = t / tl;
    // dp/du made perpendicular to n (it is for every shape here, up to rounding).
    Vec3f x = dpdu - n * dot(dpdu, n);
    float xl = length(x);
    if (!(xl > 0)) {
      Frame f(n);
      x = f.s;
    } else {
      x = x / xl;
    }
    Vec3f y = cross(n, x);
    // Unit already up to rounding (an orthonormal frame times a unit
    // vector): left as it is, so a flat map's (0, 0, 1) gives n itself and
    // renders bit for bit as no map.
    ns = x * t.x + y * t.y + n * t.z;
    if (!std::isfinite(ns.x + ns.y + ns.z)) return n;
    return dot(ns, ng) < 0 ? -ns : ns;
  } else {
    // pbrt-v4's BumpMap: dp/du' = dp/du + (d(u + du) - d(u)) / du n (the
    // displacement's dn/du term is left out: tdpm's shapes carry no dn/du;
    // it matters only for displacements large against the curvature).
    Vec2f uv = uvAt(hit);
    const SceneObject& obj = objects[hit.object];
    Vec3f lu, lv;
    objectTangents(obj, hit, hit.localP, &lu, &lv);
    const uint32_t node = uint32_t(mat.bumpTexture);
    const float du = kBumpDelta, dv = kBumpDelta;
    float d0 = textures.eval(node, {uv, hit.localP}).r;
    float d1 = textures.eval(node, {{uv.x + du, uv.y}, hit.localP + lu * du}).r;
    float d2 = textures.eval(node, {{uv.x, uv.y + dv}, hit.localP + lv * dv}).r;
    Vec3f bu = dpdu + n * (mat.bumpScale * (d1 - d0) / du);
    Vec3f bv = dpdv + n * (mat.bumpScale * (d2 - d0) / dv);
    ns = cross(bu, bv);
  }
  float l = length(ns);
  if (!(l > 0) || !std::isfinite(l)) return n;
  ns = ns / l;
  return dot(ns, ng) < 0 ? -ns : ns;  // pbrt: FaceForward(ns, n)
}

}  // namespace tdpm
