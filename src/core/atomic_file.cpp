// core/atomic_file.cpp — temp file creation, rename-on-commit, cleanup.
#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace tdpm {
namespace {

// Process-wide counter: several outputs (EXR, PNG, CSV) of one run, possibly
// written from different threads, each get their own temp name.
std::atomic<unsigned> gTempCounter{0};

std::string osReason(int err) { return std::strerror(err); }

// Splits "dir/name" into ("dir/", "name"); "name" into ("", "name").
void splitPath(const std::string& path, std::string& dir, std::string& name) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) {
    dir.clear();
    name = path;
  } else {
    dir = path.substr(0, slash + 1);
    name = path.substr(slash + 1);
  }
}

}  // namespace

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
  std::string dir, name;
  splitPath(target_, dir, name);
  if (name.empty() || name == "." || name == "..")
    throw Error(target_ + ": not a file name");

  // The target itself must not be a directory: rename would fail only at the
  // very end, after all the work.
  struct stat st;
  if (::stat(target_.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw Error(target_ + ": is a directory");

  // O_EXCL makes the name ours even if a stale temp of a crashed run with the
  // same pid exists; then we just take the next counter value. Mode 0666
  // (minus umask) so the final file has normal permissions, unlike mkstemp's
  // 0600.
  const std::string prefix = dir + "." + name + ".tmp." + std::to_string(::getpid()) + ".";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string candidate = prefix + std::to_string(gTempCounter.fetch_add(1));
    int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      temp_ = std::move(candidate);
      return;
    }
    if (errno != EEXIST) {
      int err = errno;
      throw Error(target_ + ": cannot create a file in directory '" + (dir.empty() ? "." : dir) +
                  "': " + osReason(err));
    }
  }
  throw Error(target_ + ": cannot create a unique temporary file beside it");
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !temp_.empty()) ::unlink(temp_.c_str());
}

void AtomicFile::commit() {
  TDPM_ASSERT(!committed_, "AtomicFile::commit called twice");
  // fsync before rename: otherwise a crash right after could leave the new
  // name pointing at an empty file on some file systems.
  int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    int err = errno;
    throw Error(target_ + ": temporary file " + temp_ + " vanished: " + osReason(err));
  }
  ::fsync(fd);
  ::close(fd);
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    int err = errno;
    throw Error(target_ + ": cannot rename the finished file into place: " + osReason(err));
  }
  committed_ = true;
}

void writeTextFileAtomic(const std::string& path, const std::string& contents) {
  AtomicFile file(path);
  std::FILE* f = std::fopen(file.tempPath().c_str(), "wb");
  if (!f) {
    int err = errno;
    throw Error(path + ": " + osReason(err));
  }
  size_t written = std::fwrite(contents.data(), 1, contents.size(), f);
  int writeErr = std::ferror(f) ? errno : 0;
  if (std::fclose(f) != 0 && writeErr == 0) writeErr = errno;
  if (written != contents.size() || writeErr != 0)
    throw Error(path + ": write failed: " + osReason(writeErr ? writeErr : EIO));
  file.commit();
}

}  // namespace tdpm
