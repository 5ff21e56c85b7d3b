// scene/embree_scene.cpp — Embree 3 device, geometry in layers (still
// meshes, spheres, moving meshes with vertices per time step, disks and
// cylinders as user geometry), and
// single-ray queries (rtcIntersect1 / rtcOccluded1) that visit a layer only
// where its bounds are.
#include "scene/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "math/bounds.h"

namespace tdpm {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "vertex arrays are copied as packed float triples");

const char* embreeErrorName(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE: return "none";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown";
  }
}

RTCScene newScene(RTCDevice device) {
  RTCScene scene = rtcNewScene(device);
  // Robust traversal: rays grazing edges of adjacent triangles do not leak.
  if (scene) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  return scene;
}

// A triangle mesh with `steps` time steps in `scene`: fillStep(step, out)
// writes the vertexCount vertices of each step. Returns
// RTC_INVALID_GEOMETRY_ID if Embree could not allocate a buffer (the
// reason is left on the device).
template <class FillStep>
uint32_t attachTriangles(RTCDevice device, RTCScene scene, unsigned steps, size_t vertexCount,
                         const std::vector<uint32_t>& indices, FillStep fillStep) {
  TDPM_ASSERT(steps >= 1 && indices.size() % 3 == 0, "bad triangle input");
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (steps > 1) rtcSetGeometryTimeStepCount(g, steps);
  for (unsigned step = 0; step < steps; ++step) {
    auto* v = static_cast<Vec3f*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, step, RTC_FORMAT_FLOAT3, sizeof(Vec3f), vertexCount));
    if (!v) {
      rtcReleaseGeometry(g);
      return RTC_INVALID_GEOMETRY_ID;
    }
    fillStep(step, v);
  }
  auto* idx = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), indices.size() / 3));
  if (!idx) {
    rtcReleaseGeometry(g);
    return RTC_INVALID_GEOMETRY_ID;
  }
  std::memcpy(idx, indices.data(), indices.size() * sizeof(uint32_t));
  rtcCommitGeometry(g);
  uint32_t id = rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  return id;
}

// A disk or cylinder as Embree user geometry: the callbacks below take a
// ray to object space with the placement's inverse at the ray's time (the
// blended steps of motion/motion.h, the same blend Embree applies to moving
// vertices), so the surface is exact under any affine placement.
struct QuadricRecord {
  Quadric shape;
  Motion motion;
  Affine3f stillInverse;  // world-to-object, when still
};

void quadricBoundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* q = static_cast<const QuadricRecord*>(args->geometryUserPtr);
  Bounds3f b = transformBounds(q->motion.step(int(args->timeStep)), quadricBounds(q->shape));
  // Pad past float rounding of the object-space test (a hit on the rim
  // must not be culled by the box).
  float size = std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x), std::fabs(b.hi.y),
                         std::fabs(b.hi.z)});
  Vec3f pad(1e-5f * size + 1e-6f);
  RTCBounds* out = args->bounds_o;
  out->lower_x = b.lo.x - pad.x; out->lower_y = b.lo.y - pad.y; out->lower_z = b.lo.z - pad.z;
  out->upper_x = b.hi.x + pad.x; out->upper_y = b.hi.y + pad.y; out->upper_z = b.hi.z + pad.z;
}

// The ray in object space: rtcIntersect1 / rtcOccluded1 call with N = 1,
// where the ray packet is a plain RTCRay(Hit).
bool quadricRayHit(const QuadricRecord& q, const RTCRay& r, float& s) {
  Affine3f inv = q.motion.moving() ? q.motion.atNormalized(r.time).inverse() : q.stillInverse;
  Vec3f o = inv.point({r.org_x, r.org_y, r.org_z}), d = inv.vector({r.dir_x, r.dir_y, r.dir_z});
  return intersectQuadric(q.shape, o, d, r.tnear, r.tfar, s);
}

void quadricIntersectCallback(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  float s;
  if (!quadricRayHit(*static_cast<const QuadricRecord*>(args->geometryUserPtr), rh->ray, s)) return;
  rh->ray.tfar = s;
  rh->hit.u = rh->hit.v = 0.0f;
  rh->hit.Ng_x = 0.0f; rh->hit.Ng_y = 0.0f; rh->hit.Ng_z = 1.0f;  // unused: scene.cpp makes the normal
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
}

void quadricOccludedCallback(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* r = reinterpret_cast<RTCRay*>(args->ray);
  float s;
  if (quadricRayHit(*static_cast<const QuadricRecord*>(args->geometryUserPtr), *r, s))
    r->tfar = -std::numeric_limits<float>::infinity();
}

}  // namespace

// Embree pays a fixed price for every acceleration structure a ray visits,
// hit or miss: on scenes/cube-caustic.json (valgrind, x86-64-v3 build) ~470
// instructions a ray for the still triangles, ~420 for one sphere's point
// BVH and ~1,020 for the moving box's motion-blur BVH even with the box
// moved 50 m out of every ray's way. So geometry lives in layers, each its
// own Embree scene: still meshes (always traced), spheres, moving meshes
// (Embree's motion-blur triangles; instancing each moving mesh with a
// transform per step cost 0.8% fewer instructions on cube-caustic but made
// the truck's renders 28-37% slower, its 11 moving parts overlapping).
// A ray enters a sphere or moving layer only when the segment it still has
// to search meets the layer's bounds (each geometry's, padded, or their
// union when there are many), which few rays do.
struct EmbreeScene::Impl {
  enum LayerId { kStillMeshes = 0, kSpheres, kMovingMeshes, kQuadrics, kLayers };
  static constexpr size_t kMaxListedBounds = 8;  // beyond: one union box

  struct Layer {
    RTCScene scene = nullptr;
    std::vector<uint32_t> ids;       // Embree geometry id in this layer -> our id
    std::vector<Bounds3f> bounds;    // per geometry, padded (gated layers only)
    Bounds3f all;                    // their union

    bool empty() const { return ids.empty(); }
    bool meets(Vec3f o, Vec3f invD, float tMax) const {
      if (bounds.size() > kMaxListedBounds) return all.intersectsSegment(o, invD, 0.0f, tMax);
      for (const Bounds3f& b : bounds)
        if (b.intersectsSegment(o, invD, 0.0f, tMax)) return true;
      return false;
    }
  };

  RTCDevice device = nullptr;
  Layer layers[kLayers];
  bool gated = false;                // a sphere, moving or quadric layer holds geometry
  uint32_t nextId = 0;
  std::vector<std::unique_ptr<QuadricRecord>> quadrics;  // the user data of the quadric layer's geometry

  void check(const char* what) const {
    RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE) throw Error(std::string("Embree failed to ") + what + ": " + embreeErrorName(e));
  }
  uint32_t record(LayerId l, uint32_t embreeId, const Bounds3f& b) {
    Layer& layer = layers[l];
    TDPM_ASSERT(embreeId == layer.ids.size(), "Embree geometry ids out of order");
    layer.ids.push_back(nextId);
    if (l != kStillMeshes) {
      // Pad by more than float rounding of a hit point at this size, so
      // that the slab test never rejects a hit Embree would report.
      float size = std::max(maxAbs(b.lo), maxAbs(b.hi)) + maxComponent(b.hi - b.lo);
      Vec3f pad(1e-5f * size + 1e-6f);
      Bounds3f padded{b.lo - pad, b.hi + pad};
      layer.bounds.push_back(padded);
      layer.all.extend(padded);
      gated = true;
    }
    return nextId++;
  }
  static float maxAbs(Vec3f v) { return std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z))); }
  static float maxComponent(Vec3f v) { return std::max(v.x, std::max(v.y, v.z)); }
};

EmbreeScene::EmbreeScene() : impl_(std::make_unique<Impl>()) {
  // No "threads=" in the config: Embree would cap TBB for the whole process.
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw Error("Embree could not create a device (unsupported CPU?)");
  if (!rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED))
    throw Error("this Embree build lacks point (sphere) geometry");
  for (Impl::Layer& l : impl_->layers) {
    l.scene = newScene(impl_->device);
    impl_->check("create a scene");
  }
}

EmbreeScene::~EmbreeScene() {
  for (Impl::Layer& l : impl_->layers)
    if (l.scene) rtcReleaseScene(l.scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

uint32_t EmbreeScene::addTriangles(const std::vector<Vec3f>& vertices, const std::vector<uint32_t>& indices) {
  uint32_t e = attachTriangles(impl_->device, impl_->layers[Impl::kStillMeshes].scene, 1, vertices.size(), indices,
                               [&](unsigned, Vec3f* out) { std::copy(vertices.begin(), vertices.end(), out); });
  impl_->check("add a triangle mesh");
  if (e == RTC_INVALID_GEOMETRY_ID) throw Error("Embree failed to allocate a triangle mesh");
  return impl_->record(Impl::kStillMeshes, e, {});
}

uint32_t EmbreeScene::addMovingTriangles(const std::vector<Vec3f>& objectVertices,
                                         const std::vector<uint32_t>& indices, const std::vector<Affine3f>& steps) {
  TDPM_ASSERT(steps.size() >= 2, "a moving mesh needs two or more time steps");
  // Between steps every vertex moves on the segment joining its positions
  // at the two steps, so the box of all steps' vertices holds the mesh.
  Bounds3f swept;
  uint32_t e = attachTriangles(impl_->device, impl_->layers[Impl::kMovingMeshes].scene, unsigned(steps.size()),
                               objectVertices.size(), indices, [&](unsigned step, Vec3f* out) {
                                 for (size_t i = 0; i < objectVertices.size(); ++i) {
                                   out[i] = steps[step].point(objectVertices[i]);
                                   swept.extend(out[i]);
                                 }
                               });
  impl_->check("add a moving mesh");
  if (e == RTC_INVALID_GEOMETRY_ID) throw Error("Embree failed to allocate a moving mesh");
  return impl_->record(Impl::kMovingMeshes, e, swept);
}

// Spheres and discs are both Embree points in the sphere layer: a centre and
// radius per time step, and for a disc its unit normal.
static uint32_t addPointGeometry(RTCDevice device, RTCScene layer, RTCGeometryType type, const std::vector<Vec3f>& centres,
                                 const std::vector<Vec3f>* normals, const std::vector<float>& radii,
                                 const std::function<void(const char*)>& check, Bounds3f& swept) {
  RTCGeometry g = rtcNewGeometry(device, type);
  rtcSetGeometryTimeStepCount(g, unsigned(centres.size()));
  for (size_t s = 0; s < centres.size(); ++s) {
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(s), RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    float* n = normals ? static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, unsigned(s),
                                                                     RTC_FORMAT_FLOAT3, 3 * sizeof(float), 1))
                       : nullptr;
    if (!v || (normals && !n)) {
      rtcReleaseGeometry(g);
      check(normals ? "allocate a disc buffer" : "allocate a sphere buffer");
    }
    v[0] = centres[s].x; v[1] = centres[s].y; v[2] = centres[s].z; v[3] = radii[s];
    if (n) { n[0] = (*normals)[s].x; n[1] = (*normals)[s].y; n[2] = (*normals)[s].z; }
    Vec3f r(std::fabs(radii[s]));
    swept.extend(centres[s] - r);
    swept.extend(centres[s] + r);
  }
  rtcCommitGeometry(g);
  uint32_t e = rtcAttachGeometry(layer, g);
  rtcReleaseGeometry(g);
  check(normals ? "add a disc" : "add a sphere");
  return e;
}

uint32_t EmbreeScene::addSphere(const std::vector<Vec3f>& centres, const std::vector<float>& radii) {
  TDPM_ASSERT(!centres.empty() && centres.size() == radii.size(), "bad sphere input");
  Bounds3f swept;
  uint32_t e = addPointGeometry(impl_->device, impl_->layers[Impl::kSpheres].scene, RTC_GEOMETRY_TYPE_SPHERE_POINT, centres,
                                nullptr, radii, [&](const char* what) { impl_->check(what); }, swept);
  return impl_->record(Impl::kSpheres, e, swept);
}

uint32_t EmbreeScene::addQuadric(const Quadric& shape, const Motion& motion) {
  auto rec = std::make_unique<QuadricRecord>();
  rec->shape = shape;
  rec->motion = motion;
  rec->stillInverse = motion.step(0).inverse();
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
  impl_->check("create a disk or cylinder");
  rtcSetGeometryUserPrimitiveCount(g, 1);
  if (motion.stepCount() > 1) rtcSetGeometryTimeStepCount(g, unsigned(motion.stepCount()));
  rtcSetGeometryUserData(g, rec.get());
  rtcSetGeometryBoundsFunction(g, quadricBoundsCallback, rec.get());
  rtcSetGeometryIntersectFunction(g, quadricIntersectCallback);
  rtcSetGeometryOccludedFunction(g, quadricOccludedCallback);
  rtcCommitGeometry(g);
  uint32_t e = rtcAttachGeometry(impl_->layers[Impl::kQuadrics].scene, g);
  rtcReleaseGeometry(g);
  impl_->check("add a disk or cylinder");
  Bounds3f swept = motion.sweptBounds(quadricBounds(shape));
  impl_->quadrics.push_back(std::move(rec));
  return impl_->record(Impl::kQuadrics, e, swept);
}

uint32_t EmbreeScene::addOrientedDisc(const std::vector<Vec3f>& centres, const std::vector<Vec3f>& normals,
                                      const std::vector<float>& radii) {
  TDPM_ASSERT(!centres.empty() && centres.size() == radii.size() && centres.size() == normals.size(), "bad disc input");
  Bounds3f swept;
  uint32_t e = addPointGeometry(impl_->device, impl_->layers[Impl::kSpheres].scene, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT,
                                centres, &normals, radii, [&](const char* what) { impl_->check(what); }, swept);
  return impl_->record(Impl::kSpheres, e, swept);
}

void EmbreeScene::commit() {
  for (Impl::Layer& l : impl_->layers) {
    rtcCommitScene(l.scene);
    impl_->check("build the scene");
  }
}

namespace {
Vec3f reciprocal(Vec3f d) { return {1.0f / d.x, 1.0f / d.y, 1.0f / d.z}; }
}  // namespace

bool EmbreeScene::intersect(Vec3f o, Vec3f d, float tFar, float time01, RawHit& hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = tFar;
  rh.ray.time = time01;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;  // no instances: stays so
  const Impl::Layer* layers = impl_->layers;
  rtcIntersect1(layers[Impl::kStillMeshes].scene, &ctx, &rh);
  const Impl::Layer* found = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? &layers[Impl::kStillMeshes] : nullptr;
  RawHit best{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v};
  if (impl_->gated) {
    // Each later layer searches only in front of the hit so far (Embree
    // reports a hit only below tfar), and only if its bounds are there.
    Vec3f invD = reciprocal(d);
    for (int l = Impl::kSpheres; l < Impl::kLayers; ++l) {
      const Impl::Layer& layer = layers[l];
      if (layer.empty() || !layer.meets(o, invD, rh.ray.tfar)) continue;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(layer.scene, &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      found = &layer;
      best = {rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v};
    }
  }
  if (!found) return false;
  hit.t = best.t;
  hit.geometryId = found->ids[best.geometryId];
  hit.primitiveId = best.primitiveId;
  hit.u = best.u;
  hit.v = best.v;
  return true;
}

bool EmbreeScene::occluded(Vec3f o, Vec3f d, float tFar, float time01) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
  r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
  r.tnear = 0.0f;
  r.tfar = tFar;
  r.time = time01;
  r.mask = ~0u;
  r.id = 0;
  r.flags = 0;
  const Impl::Layer* layers = impl_->layers;
  rtcOccluded1(layers[Impl::kStillMeshes].scene, &ctx, &r);
  if (r.tfar < 0.0f) return true;  // Embree sets tfar = -inf on a hit
  if (!impl_->gated) return false;
  Vec3f invD = reciprocal(d);
  for (int l = Impl::kSpheres; l < Impl::kLayers; ++l) {
    const Impl::Layer& layer = layers[l];
    if (layer.empty() || !layer.meets(o, invD, tFar)) continue;
    rtcOccluded1(layer.scene, &ctx, &r);
    if (r.tfar < 0.0f) return true;
  }
  return false;
}

}  // namespace tdpm
