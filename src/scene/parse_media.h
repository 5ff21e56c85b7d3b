// scene/parse_media.h — reads participating media from a scene file (issue
// 25; /work docs/scene-format.md "Media"): the top-level "media" and
// "exterior_medium", and the "medium" keys of the camera, the lights and
// the objects ("medium", "medium_interface"). Every value checked, every
// error located as the rest of the parser does. Internal to scene/.
#pragma once
#include <string>

#include "scene/description.h"
#include "scene/parse_node.h"

namespace tdpm::scene::detail {

// Reads root "media" (if any) into scene->media and root
// "exterior_medium" into scene->exteriorMedium. Grid files are resolved
// against sceneDir and read by media::loadDensityGridFile.
void readMedia(const Node& root, const std::string& sceneDir, SceneDescription* scene);

// The camera's or a light's medium: its "medium" key (a name or null for
// vacuum) if present, else the scene's exterior medium.
int32_t readMediumKey(const Node& owner, const SceneDescription& scene);

// An object's "medium" (interior of a closed shape, outside = the exterior
// medium) or "medium_interface" ({"inside": name | null, "outside": name |
// null}); neither: no medium boundary.
void readObjectMedia(const Node& object, const SceneDescription& scene, ObjectDesc* o);

// Whether a shape bounds a volume (an interior medium needs one): spheres
// and boxes; meshes whose every edge has exactly two faces; never quads,
// disks or cylinders. `why` says what is open.
bool shapeIsClosed(const ShapeDesc& shape, std::string* why);

// The largest dense density grid (bytes) a scene may ask for: at most
// limits::kMaxDensityGridBytes and half of the memory available now.
uint64_t maxDensityGridBytes();

// Defined in parse.cpp (the scene's one transform reader).
TransformDesc readPlacement(const Node& n);

}  // namespace tdpm::scene::detail
