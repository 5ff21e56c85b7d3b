// fuzz/fuzz_exr.cpp — libFuzzer target for the EXR reader used by
// `tdpm compare`: any bytes written to a file and read with image::readExr.
// readExr promises that every failure is a tdpm::Error ("<path>: reason")
// and that OpenEXR's own exceptions never escape; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "image/exr.h"

namespace {

// One file per process (libFuzzer runs inputs one after another in a
// process), in the temporary directory; removed at exit.
struct TempFile {
  std::string path;
  TempFile() {
    const char* dir = std::getenv("TMPDIR");
    path = std::string(dir && *dir ? dir : "/tmp") + "/tdpm-fuzz-exr-" + std::to_string(getpid()) + ".exr";
  }
  ~TempFile() { std::remove(path.c_str()); }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static TempFile file;
  FILE* f = std::fopen(file.path.c_str(), "wb");
  if (!f) return 0;
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    tdpm::image::ExrFile exr = tdpm::image::readExr(file.path);
    (void)exr;
  } catch (const tdpm::Error&) {
    // expected for malformed files
  }
  return 0;
}
