// scene/parse.h — reading a scene file into a validated SceneDescription.
// Strict: unknown keys, wrong types, out-of-range or non-finite values are
// errors. Every error is a tdpm::Error whose message names the file, the
// JSON path and (where known) the line: "scene.json:14: objects[2].motion[1].translate: ..."
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "scene/description.h"

namespace tdpm::scene {

// Reads `path`; mesh files are resolved relative to its directory.
SceneDescription loadScene(const std::string& path);

// Parses JSON text. `sourcePath` is used in messages and to resolve meshes.
SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath);

// For importers that validate what they made by the JSON format's own
// checks (import/pbrt_import.cpp): mesh shapes take their vertices and
// indices from `meshes(file, &vertices, &indices)` (file as written in the
// JSON) instead of reading OBJ files; false means "no such mesh".
using MeshSource = std::function<bool(const std::string& file, std::vector<Vec3f>* vertices, std::vector<uint32_t>* indices)>;
SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath, const MeshSource& meshes);
// ... and images too: texture files and environment maps come from
// `images(file, key)` (file as resolved against sourcePath; key the
// texture's image::encodingName, or "environment latlong" / "environment
// equal-area") when it returns one, else from the file. The importer lends
// what it has decoded already, so that validating reads no image twice.
using ImageSource = std::function<std::shared_ptr<const image::ImageRgb>(const std::string& file, const std::string& key)>;
SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath, const MeshSource& meshes,
                            const ImageSource& images);

}  // namespace tdpm::scene
