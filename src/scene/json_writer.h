// scene/json_writer.h — SceneDescription -> tdpm's JSON scene format, the parser's inverse
// (docs/scene-format.md), for `tdpm convert`. Meshes go to OBJ files beside
// the JSON. Parsing the written JSON gives the same description: numbers are
// written so they read back to the same floats, and rotations and
// directions are first put in the form the JSON parser itself produces
// (canonicalRotation / canonicalDirection), so they survive bit for bit.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "math/transform.h"
#include "scene/description.h"

namespace tdpm::pbrt {

struct SceneJson {
  std::string json;
  std::vector<std::pair<std::string, std::string>> meshFiles;  // path (beside the JSON), OBJ text
};

// `jsonPath` names the output; mesh files are "<stem>.mesh<i>.obj" beside it.
// Without meshText, meshFiles carry the paths only (empty texts): for
// validating the JSON with the meshes still in memory (scene::MeshSource).
SceneJson sceneToJson(const scene::SceneDescription& scene, const std::string& jsonPath, bool meshText = true);
// Writes the meshes and then the JSON, each atomically.
void writeSceneJson(const scene::SceneDescription& scene, const std::string& jsonPath);

// The quaternion the JSON parser makes of {"axis": axis, "angle": degrees}.
Quaternion rotationAsParsed(Vec3f axis, float degrees);
// The axis and angle the writer writes for q.
void axisAngleOf(const Quaternion& q, Vec3f* axis, float* degrees);
// q, nudged to the rotation that writing and parsing reproduce exactly
// (within float rounding of q otherwise).
Quaternion canonicalRotation(const Quaternion& q);
// A unit direction that the parser's normalisation leaves unchanged.
Vec3f canonicalDirection(Vec3f d);

}  // namespace tdpm::pbrt
