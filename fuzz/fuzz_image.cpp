// fuzz/fuzz_image.cpp — libFuzzer target for the format dispatcher used by
// `tdpm compare` (image::readImage): any bytes written to a file without an
// extension, so the content picks the reader (PFM, Radiance HDR, PNG or
// OpenEXR). readImage promises that every failure is a tdpm::Error and that
// no declared size is allocated before it is checked against the file;
// anything else (a crash, a sanitizer report, a foreign exception, an
// allocation over -rss_limit_mb) is a finding. Seeds: fuzz/corpus/{pfm,hdr,png}/.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "image/read_image.h"

namespace {

// One file per process, in the temporary directory; removed at exit.
struct TempFile {
  std::string path;
  TempFile() {
    const char* dir = std::getenv("TMPDIR");
    path = std::string(dir && *dir ? dir : "/tmp") + "/tdpm-fuzz-image-" + std::to_string(getpid());
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
    tdpm::image::LoadedImage image = tdpm::image::readImage(file.path);
    (void)image;
  } catch (const tdpm::Error&) {
    // expected for malformed files
  }
  return 0;
}
