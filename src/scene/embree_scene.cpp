// scene/embree_scene.cpp — Embree 3 device, geometry with time steps, and
// single-ray queries (rtcIntersect1 / rtcOccluded1).
#include "scene/embree_scene.h"

#include <embree3/rtcore.h>

#include <cstring>
#include <limits>
#include <string>

#include "core/error.h"

namespace tdpm {

namespace {

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

}  // namespace

struct EmbreeScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  void check(const char* what) const {
    RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE) throw Error(std::string("Embree failed to ") + what + ": " + embreeErrorName(e));
  }
};

EmbreeScene::EmbreeScene() : impl_(std::make_unique<Impl>()) {
  // No "threads=" in the config: Embree would cap TBB for the whole process.
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw Error("Embree could not create a device (unsupported CPU?)");
  if (!rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED))
    throw Error("this Embree build lacks point (sphere) geometry");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust traversal: rays grazing edges of adjacent triangles do not leak.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  impl_->check("create a scene");
}

EmbreeScene::~EmbreeScene() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

uint32_t EmbreeScene::addTriangles(const std::vector<std::vector<Vec3f>>& steps, const std::vector<uint32_t>& indices) {
  TDPM_ASSERT(!steps.empty() && indices.size() % 3 == 0, "bad triangle input");
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryTimeStepCount(g, unsigned(steps.size()));
  size_t vertexCount = steps[0].size();
  for (size_t s = 0; s < steps.size(); ++s) {
    TDPM_ASSERT(steps[s].size() == vertexCount, "time steps differ in vertex count");
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(s), RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), vertexCount));
    if (!v) { rtcReleaseGeometry(g); impl_->check("allocate a vertex buffer"); }
    for (size_t i = 0; i < vertexCount; ++i) {
      v[3 * i + 0] = steps[s][i].x;
      v[3 * i + 1] = steps[s][i].y;
      v[3 * i + 2] = steps[s][i].z;
    }
  }
  auto* idx = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), indices.size() / 3));
  if (!idx) { rtcReleaseGeometry(g); impl_->check("allocate an index buffer"); }
  std::memcpy(idx, indices.data(), indices.size() * sizeof(uint32_t));
  rtcCommitGeometry(g);
  uint32_t id = rtcAttachGeometry(impl_->scene, g);
  rtcReleaseGeometry(g);
  impl_->check("add a triangle mesh");
  return id;
}

uint32_t EmbreeScene::addSphere(const std::vector<Vec3f>& centres, const std::vector<float>& radii) {
  TDPM_ASSERT(!centres.empty() && centres.size() == radii.size(), "bad sphere input");
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  rtcSetGeometryTimeStepCount(g, unsigned(centres.size()));
  for (size_t s = 0; s < centres.size(); ++s) {
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, unsigned(s), RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    if (!v) { rtcReleaseGeometry(g); impl_->check("allocate a sphere buffer"); }
    v[0] = centres[s].x; v[1] = centres[s].y; v[2] = centres[s].z; v[3] = radii[s];
  }
  rtcCommitGeometry(g);
  uint32_t id = rtcAttachGeometry(impl_->scene, g);
  rtcReleaseGeometry(g);
  impl_->check("add a sphere");
  return id;
}

void EmbreeScene::commit() {
  rtcCommitScene(impl_->scene);
  impl_->check("build the scene");
}

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
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.geometryId = rh.hit.geomID;
  hit.primitiveId = rh.hit.primID;
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
  rtcOccluded1(impl_->scene, &ctx, &r);
  return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

}  // namespace tdpm
