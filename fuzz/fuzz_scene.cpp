// fuzz/fuzz_scene.cpp — libFuzzer target for the scene loader: any bytes as
// a scene file through scene::parseScene. A bad scene must be a located
// tdpm::Error; anything else escaping (another exception, a crash, a
// sanitizer report, a hang) is a finding. Meshes resolve against scenes/,
// so the seed corpus (scenes/*.json) exercises the OBJ reader too.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "scene/parse.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    tdpm::scene::SceneDescription d = tdpm::scene::parseScene(text, TDPM_SOURCE_DIR "/scenes/fuzz-input.json");
    (void)d;
  } catch (const tdpm::Error&) {
    // the expected outcome for most inputs: a located, user-facing error
  }
  return 0;
}
