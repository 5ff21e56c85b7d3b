// core/atomic_file.h — all-or-nothing output files.
// Owns: AtomicFile (RAII temp file + rename) and writeTextFileAtomic.
// Why: a render that fails or is interrupted half-way must never leave a
// truncated EXR/PNG/CSV under the name the user asked for (a later `compare`
// would read it as a real result). We write to a unique temporary file in the
// *same directory* (so rename(2) is atomic: same file system) and rename it
// over the target only once the writer has finished.
#pragma once
#include <string>

namespace tdpm {

class AtomicFile {
 public:
  // Creates an empty temporary file ".<name>.tmp.<pid>.<counter>" beside
  // `target`. Throws tdpm::Error "<target>: <reason>" (with strerror) when the
  // directory is missing or not writable, so failures surface before any
  // expensive encoding work.
  explicit AtomicFile(std::string target);
  // Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Where the writer must put the bytes (any library that opens by name).
  const std::string& tempPath() const { return temp_; }
  const std::string& targetPath() const { return target_; }

  // Flushes the temp file to disk and renames it over the target (replacing
  // an existing file). Throws tdpm::Error on failure; the temp is then
  // removed by the destructor. Must be called after the writer closed it.
  void commit();
  bool committed() const { return committed_; }

 private:
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

// Writes `contents` to `path` atomically (CSV, JSON, SVG outputs).
void writeTextFileAtomic(const std::string& path, const std::string& contents);

}  // namespace tdpm
