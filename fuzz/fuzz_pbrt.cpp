// fuzz/fuzz_pbrt.cpp — libFuzzer target for the pbrt import: any bytes as a
// .pbrt file through pbrt::importPbrtText (tokenizer, statements, graphics
// state, mapping, and the PLY reader through plymesh). A bad scene must be
// a located tdpm::Error; anything else escaping (another exception, a crash,
// a sanitizer report, a hang) is a finding. Relative Include/plymesh paths
// resolve against fuzz/corpus/pbrt/, whose seeds include each other and a
// PLY file.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "import/pbrt_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    tdpm::pbrt::ImportResult r = tdpm::pbrt::importPbrtText(text, TDPM_SOURCE_DIR "/fuzz/corpus/pbrt/fuzz-input.pbrt");
    (void)r;
  } catch (const tdpm::Error&) {
    // the expected outcome for most inputs: a located, user-facing error
  }
  return 0;
}
