// scene/parse.h — reading a scene file into a validated SceneDescription.
// Strict: unknown keys, wrong types, out-of-range or non-finite values are
// errors. Every error is a tdpm::Error whose message names the file, the
// JSON path and (where known) the line: "scene.json:14: objects[2].motion[1].translate: ..."
#pragma once
#include <string>

#include "scene/description.h"

namespace tdpm::scene {

// Reads `path`; mesh files are resolved relative to its directory.
SceneDescription loadScene(const std::string& path);

// Parses JSON text. `sourcePath` is used in messages and to resolve meshes.
SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath);

}  // namespace tdpm::scene
