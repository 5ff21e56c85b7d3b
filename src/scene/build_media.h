// scene/build_media.h — the media part of building a Scene (issue 25):
// which description media a render uses, and the runtime media
// (media/medium.h) with each object's medium interface, the camera's and
// the lights' media. Scene::buildMedia (build_media.cpp) is its entry.
#pragma once
#include "scene/description.h"

namespace tdpm::scene {

// Whether anything in the scene is inside a medium: the exterior, the
// camera, a light or either side of an object's interface names one.
// Media that are defined but never referenced do not count.
bool usesMedia(const SceneDescription& desc);

}  // namespace tdpm::scene
