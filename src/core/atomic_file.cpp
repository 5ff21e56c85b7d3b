// core/atomic_file.cpp — target resolution, temp file creation,
// rename-on-commit (single and grouped, with rollback), cleanup.
#include "core/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>  // kill(pid, 0)
#include <limits.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/file.h>  // flock
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "core/signals.h"

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

// The longest file name the directory's file system accepts.
size_t nameMax(const std::string& dir) {
  long n = ::pathconf(dir.empty() ? "." : dir.c_str(), _PC_NAME_MAX);
  return n > 0 ? size_t(n) : size_t(NAME_MAX);
}

// ".<name>.tmp.<pid>.<n>" in `dir`, with <name> cut (at a UTF-8 character
// boundary) so the whole name fits in `limit` bytes.
std::string tempName(const std::string& dir, const std::string& name, size_t limit, unsigned long long n,
                     long long pid = ::getpid()) {
  const std::string suffix = ".tmp." + std::to_string(pid) + "." + std::to_string(n);
  size_t keep = name.size();
  if (1 + keep + suffix.size() > limit) {
    keep = limit > 1 + suffix.size() ? limit - 1 - suffix.size() : 0;
    while (keep > 0 && (static_cast<unsigned char>(name[keep]) & 0xC0) == 0x80) --keep;
  }
  return dir + "." + name.substr(0, keep) + suffix;
}

// A run of ASCII digits, the whole of [b, e), as a number (false: not one,
// or more than 18 digits).
bool digitsValue(const std::string& s, size_t b, size_t e, long long& v) {
  if (b >= e || e - b > 18) return false;
  v = 0;
  for (size_t i = b; i < e; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10 + (s[i] - '0');
  }
  return true;
}

// A temporary name's process id, whatever target it belongs to.
struct Leftover {
  std::string entry;
  long long pid, n;
};

// The leftovers in `dir` whose process was gone when the directory was read.
std::vector<Leftover> scanLeftovers(const std::string& dir) {
  std::vector<Leftover> out;
  DIR* d = ::opendir(dir.empty() ? "." : dir.c_str());
  if (!d) return out;
  const long long self = ::getpid();
  while (const struct dirent* e = ::readdir(d)) {
    const std::string entry = e->d_name;
    if (entry.size() < 8 || entry[0] != '.') continue;
    const size_t dot = entry.find_last_of('.');
    if (dot == std::string::npos || dot < 5) continue;
    const size_t tmp = entry.rfind(".tmp.", dot - 1);
    long long pid = 0, n = 0;
    if (tmp == std::string::npos || tmp + 5 > dot) continue;
    if (!digitsValue(entry, tmp + 5, dot, pid) || !digitsValue(entry, dot + 1, entry.size(), n)) continue;
    if (pid <= 0 || pid == self || pid > INT_MAX) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge (EPERM)
    out.push_back({entry, pid, n});
  }
  ::closedir(d);
  return out;
}

std::mutex gLeftoverMutex;
std::map<std::string, std::vector<Leftover>> gLeftovers;  // directory -> leftovers not yet removed

// Removes the temporaries of `name` in `dir` that a killed run left (issue
// 27 item 13: SIGKILL leaves them, 32 MB each, and nothing else removes
// them). Only files named exactly as tempName names them for this target
// (".<name>.tmp.<pid>.<n>", <name> cut as it would be), whose process is
// gone (kill(pid, 0) fails with ESRCH): a live run's temporary, another
// target's, or any other file is never touched. PIDs are this machine's:
// two hosts writing one network directory could see each other's live
// temporaries as dead (docs/output-safety.md).
void removeStaleTemporaries(const std::string& dir, const std::string& name, size_t limit) {
  // Each directory is read once per process: an animation writes thousands
  // of frames into one directory, and reading it for every file would cost
  // frames^2 directory entries.
  std::lock_guard<std::mutex> lock(gLeftoverMutex);
  auto it = gLeftovers.find(dir);
  if (it == gLeftovers.end()) it = gLeftovers.emplace(dir, scanLeftovers(dir)).first;
  std::vector<Leftover>& list = it->second;
  for (size_t i = 0; i < list.size();) {
    const Leftover& l = list[i];
    const std::string path = dir + l.entry;
    if (path != tempName(dir, name, limit, (unsigned long long)l.n, l.pid)) {  // another target's, or not exactly ours
      ++i;
      continue;
    }
    struct stat st;
    if (::kill(pid_t(l.pid), 0) != 0 && errno == ESRCH && ::lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode))
      ::unlink(path.c_str());
    list.erase(list.begin() + long(i));
  }
}

// Follows `target` if it is a symbolic link; fills `st` and returns true if
// the final file exists. Throws for what cannot be replaced.
bool resolveTarget(const std::string& target, std::string& final, struct stat& st) {
  final = target;
  if (::lstat(target.c_str(), &st) != 0) {
    int err = errno;
    if (err == ENOENT) return false;  // a missing directory is reported when the temp is created
    throw Error(target + ": " + osReason(err));
  }
  if (S_ISLNK(st.st_mode)) {
    char* real = ::realpath(target.c_str(), nullptr);
    if (!real) {
      int err = errno;
      char link[PATH_MAX];
      ssize_t n = ::readlink(target.c_str(), link, sizeof link - 1);
      std::string to = n > 0 ? std::string(link, size_t(n)) : std::string("?");
      throw Error(target + ": is a symbolic link to '" + to + "', which cannot be written through (" +
                  osReason(err) + ")");
    }
    final = real;
    std::free(real);
    if (::stat(final.c_str(), &st) != 0) {
      int err = errno;
      throw Error(target + ": " + osReason(err));
    }
  }
  if (S_ISDIR(st.st_mode)) throw Error(target + ": is a directory");
  if (!S_ISREG(st.st_mode)) throw Error(target + ": exists and is not a regular file");
  return true;
}

}  // namespace

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
  std::string dir, name;
  splitPath(target_, dir, name);
  if (name.empty() || name == "." || name == "..")
    throw Error(target_ + ": not a file name");

  auto checkLength = [&] {
    const size_t limit = nameMax(dir);
    if (name.size() > limit)
      throw Error(target_ + ": the file name is " + std::to_string(name.size()) +
                  " bytes long, more than the file system allows (" + std::to_string(limit) + ")");
    return limit;
  };
  checkLength();
  // The target must be something rename can replace: rename would fail
  // only at the very end, after all the work.
  struct stat st;
  resolveTarget(target_, final_, st);
  splitPath(final_, dir, name);
  const size_t limit = checkLength();
  removeStaleTemporaries(dir, name, limit);

  // O_EXCL makes the name ours even if a stale temp of a crashed run with the
  // same pid exists; then we just take the next counter value. Mode 0666
  // (minus umask) so the final file has normal permissions, unlike mkstemp's
  // 0600; a replaced file's mode is kept.
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string candidate = tempName(dir, name, limit, gTempCounter.fetch_add(1));
    int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      signals::addTemporary(candidate.c_str());
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
  if (!committed_ && !temp_.empty()) {
    ::unlink(temp_.c_str());
    signals::removeTemporary(temp_.c_str());
  }
}

// fsync before rename: otherwise a crash right after could leave the new
// name pointing at an empty file on some file systems.
void AtomicFile::sync() const {
  int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    int err = errno;
    throw Error(target_ + ": temporary file " + temp_ + " vanished: " + osReason(err));
  }
  int rc = ::fsync(fd);
  int err = errno;
  // The replaced file's mode (and owner, if we may) carry over. Set only
  // now: a read-only mode on the temporary would stop its writer.
  struct stat old;
  if (::stat(final_.c_str(), &old) == 0 && S_ISREG(old.st_mode)) {
    if (::geteuid() == 0 && (old.st_uid != 0 || old.st_gid != 0) && ::fchown(fd, old.st_uid, old.st_gid) != 0) {
      // Best effort: the content matters more than the owner.
    }
    if (::fchmod(fd, old.st_mode & 07777) != 0) {
      // Best effort, as for the owner.
    }
  }
  ::close(fd);
  if (rc != 0 && err != EINVAL && err != EROFS)  // EINVAL/EROFS: no fsync on this file system
    throw Error(target_ + ": cannot flush the finished file to disk: " + osReason(err));
}

void AtomicFile::commit() { commitTogether({this}); }

namespace {

// flock(2) on the directories of a group's targets, held while the group is
// renamed: two runs committing the same pair (six `--resume a.exr -o s.exr`
// at once) would otherwise interleave their renames and leave one run's EXR
// beside another's PNG (issue 27 item 12). The directory is locked, not a
// lock file beside the outputs: nothing is left behind, and the kernel
// drops the lock when the process dies, even by SIGKILL. Directories are
// locked in (device, inode) order, so two groups never wait on each other.
// Best effort: a file system without flock (ENOLCK, some network file
// systems) is committed unlocked, as before.
class DirectoryLocks {
 public:
  explicit DirectoryLocks(const std::vector<std::string>& finals) {
    std::vector<std::pair<std::pair<dev_t, ino_t>, std::string>> dirs;
    for (const std::string& f : finals) {
      std::string dir, name;
      splitPath(f, dir, name);
      if (dir.empty()) dir = ".";
      struct stat st;
      if (::stat(dir.c_str(), &st) != 0) continue;
      dirs.push_back({{st.st_dev, st.st_ino}, dir});
    }
    std::sort(dirs.begin(), dirs.end());
    for (size_t i = 0; i < dirs.size(); ++i) {
      if (i > 0 && dirs[i].first == dirs[i - 1].first) continue;
      int fd = ::open(dirs[i].second.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;
      int rc;
      while ((rc = ::flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
      }
      if (rc != 0) {
        ::close(fd);
        continue;
      }
      fds_.push_back(fd);
    }
  }
  ~DirectoryLocks() {
    for (size_t i = fds_.size(); i-- > 0;) ::close(fds_[i]);  // closing releases the lock
  }
  DirectoryLocks(const DirectoryLocks&) = delete;
  DirectoryLocks& operator=(const DirectoryLocks&) = delete;

 private:
  std::vector<int> fds_;
};

}  // namespace

void commitTogether(std::initializer_list<AtomicFile*> list) {
  const std::vector<AtomicFile*> files(list);
  for (const AtomicFile* f : files) TDPM_ASSERT(!f->committed_, "AtomicFile committed twice");
  for (const AtomicFile* f : files) f->sync();  // may throw: nothing renamed yet

  // How to undo one rename: the target did not exist (remove it), the old
  // file was swapped into the temporary's name (swap back), or the old file
  // has a second hard link (rename it back).
  enum class Undo { Remove, Swap, Relink };
  struct Done {
    Undo undo;
    std::string backup;
  };
  std::vector<Done> done;
  // A group (an EXR and its PNG) is renamed under the lock; taken before
  // the deferral, so a signal while waiting for it acts at once.
  std::vector<std::string> finals;
  if (files.size() > 1)
    for (const AtomicFile* f : files) finals.push_back(f->final_);
  DirectoryLocks locked(finals);
  signals::Deferral noSignalsUntilDone;

  auto rollback = [&] {
    for (size_t j = done.size(); j-- > 0;) {
      const AtomicFile& f = *files[j];
      if (done[j].undo == Undo::Swap)
        ::renameat2(AT_FDCWD, f.temp_.c_str(), AT_FDCWD, f.final_.c_str(), RENAME_EXCHANGE);
      else if (done[j].undo == Undo::Relink)
        ::rename(done[j].backup.c_str(), f.final_.c_str());
      else
        ::unlink(f.final_.c_str());
    }
  };

  for (size_t i = 0; i < files.size(); ++i) {
    const AtomicFile& f = *files[i];
    const bool last = i + 1 == files.size();  // nothing after it can fail: no undo needed
    struct stat st;
    const bool exists = ::lstat(f.final_.c_str(), &st) == 0;
    Done step{Undo::Remove, {}};
    int rc = -1;
    if (exists && !last) {
      rc = ::renameat2(AT_FDCWD, f.temp_.c_str(), AT_FDCWD, f.final_.c_str(), RENAME_EXCHANGE);
      if (rc == 0) {
        step.undo = Undo::Swap;
      } else if (errno == EINVAL || errno == ENOSYS || errno == ENOTSUP) {
        // A file system without RENAME_EXCHANGE: keep the old file under a
        // second name until the group is done.
        std::string dir, name;
        splitPath(f.final_, dir, name);
        step.backup = tempName(dir, name, nameMax(dir), gTempCounter.fetch_add(1));
        if (::link(f.final_.c_str(), step.backup.c_str()) == 0) step.undo = Undo::Relink;
        else step.backup.clear();  // no way back for this one; the renames rarely fail here
        rc = ::rename(f.temp_.c_str(), f.final_.c_str());
      }
    } else {
      rc = ::rename(f.temp_.c_str(), f.final_.c_str());
    }
    if (rc != 0) {
      int err = errno;
      if (!step.backup.empty()) ::unlink(step.backup.c_str());
      rollback();
      throw Error(f.target_ + ": cannot rename the finished file into place: " + osReason(err) +
                  (i > 0 ? " (the other outputs were left as they were)" : ""));
    }
    done.push_back(step);
  }
  for (size_t i = 0; i < files.size(); ++i) {
    AtomicFile& f = *files[i];
    if (done[i].undo == Undo::Swap) ::unlink(f.temp_.c_str());  // now the old file
    if (done[i].undo == Undo::Relink) ::unlink(done[i].backup.c_str());
    signals::removeTemporary(f.temp_.c_str());
    f.committed_ = true;
  }
}

void checkOutputPath(const std::string& target) { AtomicFile probe(target); }

bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

void writeTextFileAtomic(const std::string& path, const std::string& contents) {
  AtomicFile file(path);
  writeTextToTemp(file, contents);
  file.commit();
}

void writeTextToTemp(const AtomicFile& file, const std::string& contents) {
  const std::string& path = file.targetPath();
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
}

}  // namespace tdpm
