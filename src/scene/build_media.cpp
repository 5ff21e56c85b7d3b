// scene/build_media.cpp — runtime media for a Scene (see build_media.h).
// One runtime medium per (description medium, owner): a homogeneous medium
// and every medium outside objects is static (owner none); a grid inside
// an object (its interior, or a medium_interface's inside) moves with that
// object, so each such object gets its own instance sharing the density.
#include "scene/build_media.h"

#include <map>
#include <utility>

#include "scene/scene.h"

namespace tdpm {

namespace scene {

bool usesMedia(const SceneDescription& desc) {
  if (desc.media.empty()) return false;
  if (desc.exteriorMedium >= 0 || desc.camera.medium >= 0) return true;
  for (const LightDesc& l : desc.lights)
    if (l.medium >= 0) return true;
  for (const ObjectDesc& o : desc.objects)
    if (o.media.present && (o.media.inside >= 0 || o.media.outside >= 0)) return true;
  return false;
}

}  // namespace scene

void Scene::buildMedia(const scene::SceneDescription& desc) {
  std::map<std::pair<int32_t, int32_t>, int32_t> instances;  // (desc medium, owner object or -1) -> index
  std::vector<std::shared_ptr<const std::vector<float>>> densities(desc.media.size());
  auto instance = [&](int32_t medium, int32_t owner) -> int32_t {
    if (medium < 0) return -1;
    const scene::MediumDesc& d = desc.media[size_t(medium)];
    if (d.type == scene::MediumDesc::Type::Homogeneous) owner = -1;
    auto key = std::make_pair(medium, owner);
    auto it = instances.find(key);
    if (it != instances.end()) return it->second;
    const Motion* motion = owner >= 0 ? &objects[size_t(owner)].motion : nullptr;
    media.push_back(media::makeMedium(d, motion, densities[size_t(medium)]));
    densities[size_t(medium)] = media.back().density;
    return instances[key] = int32_t(media.size() - 1);
  };
  cameraMedium = instance(desc.camera.medium, -1);
  lightMedia.clear();
  for (const scene::LightDesc& l : desc.lights) lightMedia.push_back(instance(l.medium, -1));
  for (size_t i = 0; i < objects.size(); ++i) {
    scene::MediumInterfaceDesc& mi = objects[i].mediumInterface;
    if (!mi.present) continue;
    mi.inside = instance(mi.inside, int32_t(i));
    mi.outside = instance(mi.outside, -1);
  }
  // The media's world: the scene's bounds (every object and emitter over
  // the shutter) and every camera position, in one sphere a little larger
  // than their box's (the directional and sky photons' disc, light.cpp,
  // has the bounds' sphere; this one also holds a camera standing outside
  // the geometry, in the fog it looks through).
  Bounds3f world = bounds;
  world.extend(desc.camera.position);
  for (const scene::CameraKeyframe& k : desc.camera.motion) world.extend(k.position);
  mediaWorldCentre = world.center();
  mediaWorldRadius = std::max(1e-6f, 0.5f * length(world.diagonal()) * 1.01f);
}

}  // namespace tdpm
