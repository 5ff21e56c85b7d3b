// core/atomic_file.h — all-or-nothing output files.
// Owns: AtomicFile (RAII temp file + rename), commitTogether (several files
// renamed as one: all or none), checkOutputPath (the same checks before any
// work), writeTextFileAtomic and writeTextToTemp.
// Why: a render that fails or is interrupted half-way must never leave a
// truncated EXR/PNG/CSV under the name the user asked for (a later `compare`
// would read it as a real result), nor an EXR that does not belong to its
// PNG preview. We write to a unique temporary file in the *same directory*
// (so rename(2) is atomic: same file system) and rename it over the target
// only once the writer has finished. Temporaries are registered with
// core/signals, so SIGINT/SIGTERM removes them; those a SIGKILL left are
// removed by the next AtomicFile of the same target (only exact
// ".<name>.tmp.<pid>.<n>" files of processes that no longer run). A group
// (commitTogether) is renamed under flock(2) on its directory, so runs
// that write the same pair at once never leave a mixed pair.
//
// Where the bytes go: an existing target that is a symbolic link is written
// *through* (the file it points to is replaced and the link stays, as cp and
// most editors do); a dangling link is refused. The new file keeps the mode
// (and, when run as root, the owner) of the file it replaces; a new file gets
// 0666 less the umask. Targets that exist but are not regular files
// (directories, devices, FIFOs) are refused.
#pragma once
#include <initializer_list>
#include <string>

namespace tdpm {

class AtomicFile {
 public:
  // Removes stale temporaries of the target (see above), then
  // creates an empty temporary file ".<name>.tmp.<pid>.<counter>" beside the
  // final target (<name> shortened so the temporary's name stays within the
  // file system's NAME_MAX). Throws tdpm::Error "<target>: <reason>" when the
  // target cannot be replaced (see the header comment), its name is too long,
  // or the directory is missing or not writable, so failures surface before
  // any expensive encoding work.
  explicit AtomicFile(std::string target);
  // Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Where the writer must put the bytes (any library that opens by name).
  const std::string& tempPath() const { return temp_; }
  // The path as given, and the file that will really be replaced (the
  // target of a symbolic link; else the same path).
  const std::string& targetPath() const { return target_; }
  const std::string& finalPath() const { return final_; }

  // Flushes the temp file to disk and renames it over the target (replacing
  // an existing file). Throws tdpm::Error on failure; the temp is then
  // removed by the destructor. Must be called after the writer closed it.
  void commit();
  bool committed() const { return committed_; }

 private:
  friend void commitTogether(std::initializer_list<AtomicFile*> files);
  void sync() const;

  std::string target_;
  std::string final_;
  std::string temp_;
  bool committed_ = false;
};

// Commits finished files as one: every temporary is flushed first, then
// each is renamed over its target. If anything fails, the targets renamed
// so far get their old contents back (or vanish if they did not exist), so
// every target is as it was; then tdpm::Error is thrown. SIGINT/SIGTERM
// waits until the renames are done (core/signals Deferral). With more than
// one file, the renames run under an exclusive flock on each target's
// directory (best effort: unlocked where flock fails); a reader may take
// it shared to read a consistent pair (docs/output-safety.md).
void commitTogether(std::initializer_list<AtomicFile*> files);

// Checks, before any work, that `target` can be written: everything the
// AtomicFile constructor checks, by creating its temporary and removing it
// again. Throws the same tdpm::Error.
void checkOutputPath(const std::string& target);

// True when both paths name the same existing file (after symbolic links).
bool sameFile(const std::string& a, const std::string& b);

// Writes `contents` to `path` atomically (CSV, JSON, SVG outputs).
void writeTextFileAtomic(const std::string& path, const std::string& contents);
// Writes `contents` into `file`'s temporary (not committed), for outputs
// that are committed together (commitTogether).
void writeTextToTemp(const AtomicFile& file, const std::string& contents);

}  // namespace tdpm
