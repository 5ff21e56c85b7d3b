// import/pbrt_import.h — reading a pbrt-v3/v4 scene (the documented subset,
// docs/pbrt-import.md) into the same SceneDescription the JSON parser makes.
// Downstream nothing knows where a scene came from. What tdpm cannot express
// exactly is an error naming file:line and the statement or parameter;
// parameters that only change quality produce a one-line note instead.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "scene/description.h"

namespace tdpm::pbrt {

struct ImportResult {
  scene::SceneDescription scene;
  std::vector<std::string> notes;          // "file:line: ..." one line each (warnings, ignored parameters)
  std::optional<std::string> filmFilename;  // Film "filename", as written
};

// Reads `path`; Include/Import are resolved relative to the including file.
ImportResult importPbrtFile(const std::string& path);
// Parses text as if it were the file `path` (for tests and fuzzing).
ImportResult importPbrtText(const std::string& text, const std::string& path);

// True when the scene file should be read as pbrt (by extension, .pbrt).
bool isPbrtPath(const std::string& path);

}  // namespace tdpm::pbrt
