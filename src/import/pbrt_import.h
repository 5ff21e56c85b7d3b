// import/pbrt_import.h — reading a pbrt-v3/v4 scene (the documented subset,
// docs/pbrt-import.md) into the same SceneDescription the JSON parser makes.
// Downstream nothing knows where a scene came from. What tdpm cannot express
// exactly is an error naming file:line and the statement or parameter;
// parameters that only change quality produce a one-line note instead.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scene/description.h"

namespace tdpm::pbrt {

struct ImportResult {
  scene::SceneDescription scene;
  std::vector<std::string> notes;          // "file:line: ..." one line each (warnings, ignored parameters)
  std::optional<std::string> filmFilename;  // Film "filename", as written
  // For messages about a render setting the import derived: render key
  // ("photons") -> "file:line: the pbrt statement and parameters".
  std::map<std::string, std::string> settingSources;
  // Every file the import read (the scene, its Includes, PLY meshes), for
  // refusing outputs that would overwrite an input (tdpm convert).
  std::vector<std::string> inputFiles;
};

// Reads `path`; Include/Import are resolved relative to the including file.
ImportResult importPbrtFile(const std::string& path);
// Parses text as if it were the file `path` (for tests and fuzzing).
// `maxTriangles` (0: scene::limits::kMaxPbrtTriangles) lets a test reach
// the triangle budget with a small scene.
ImportResult importPbrtText(const std::string& text, const std::string& path, uint64_t maxTriangles = 0);

// True when the scene file should be read as pbrt (by extension, .pbrt).
bool isPbrtPath(const std::string& path);

}  // namespace tdpm::pbrt
