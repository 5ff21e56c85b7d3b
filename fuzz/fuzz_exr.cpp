// fuzz/fuzz_exr.cpp — libFuzzer target for the EXR reader used by
// `tdpm compare`: any bytes written to a file and read with image::readExr.
// readExr promises that every failure is a tdpm::Error ("<path>: reason")
// and that OpenEXR's own exceptions never escape; anything else is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_file_input.h"
#include "image/exr.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const tdpm::fuzz::TempInputFile file("exr", ".exr");
  return tdpm::fuzz::loadFromFile(file, data, size, [](const std::string& path) { (void)tdpm::image::readExr(path); });
}
