// fuzz/fuzz_image.cpp — libFuzzer target for the format dispatcher used by
// `tdpm compare` (image::readImage): any bytes written to a file without an
// extension, so the content picks the reader (PFM, Radiance HDR, PNG or
// OpenEXR). readImage promises that every failure is a tdpm::Error and that
// no declared size is allocated before it is checked against the file;
// anything else (a crash, a sanitizer report, a foreign exception, an
// allocation over -rss_limit_mb) is a finding. The header-only size reader
// compare runs first (image::readImageHeader) gets the same bytes.
// Seeds: fuzz/corpus/{pfm,hdr,png}/.
#include <cstddef>
#include <cstdint>

#include "fuzz_file_input.h"
#include "image/image_header.h"
#include "image/read_image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const tdpm::fuzz::TempInputFile file("image", "");
  return tdpm::fuzz::loadFromFile(file, data, size, [](const std::string& path) {
    (void)tdpm::image::readImageHeader(path);
    (void)tdpm::image::readImage(path);
  });
}
