// fuzz/fuzz_file_input.h — for the fuzz targets whose loaders read a file by
// name (EXR through OpenEXR, compare's format dispatcher): the input bytes
// are written to one temporary file per process (libFuzzer runs inputs one
// after another in a process), removed at exit, and the loader reads it.
// Only tdpm::Error may leave the loader; anything else is a finding.
#pragma once
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"

namespace tdpm::fuzz {

class TempInputFile {
 public:
  // "<TMPDIR or /tmp>/tdpm-fuzz-<name>-<pid><suffix>"
  TempInputFile(const char* name, const char* suffix) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/tdpm-fuzz-" + name + "-" + std::to_string(getpid()) + suffix;
  }
  ~TempInputFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Writes the input to `file` and calls load(path); a tdpm::Error is the
// expected outcome for malformed input.
template <class Load>
int loadFromFile(const TempInputFile& file, const uint8_t* data, size_t size, Load&& load) {
  std::FILE* f = std::fopen(file.path().c_str(), "wb");
  if (!f) return 0;
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    load(file.path());
  } catch (const tdpm::Error&) {
  }
  return 0;
}

}  // namespace tdpm::fuzz
