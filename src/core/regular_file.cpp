// core/regular_file.cpp — openRegularInput and checkRegularFile (core/regular_file.h).
#include "core/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace tdpm {

std::FILE* openRegularInput(const std::string& path, const std::string& what, uint64_t* size) {
  // O_NONBLOCK: a FIFO without a writer would block open() itself.
  int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    int err = errno;
    // open(O_RDONLY) of a directory succeeds on Linux; EISDIR is kept for others.
    if (err == EISDIR) throw Error(path + ": is a directory, not " + what);
    throw Error(path + ": " + std::strerror(err));
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    throw Error(path + ": " + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not " + what);
    const char* kind = S_ISFIFO(st.st_mode)  ? "a FIFO (named pipe)"
                       : S_ISCHR(st.st_mode) ? "a character device"
                       : S_ISBLK(st.st_mode) ? "a block device"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw Error(path + ": is " + kind + ", not " + what + ": only regular files are read");
  }
  int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  std::FILE* f = ::fdopen(fd, "rb");
  if (!f) {
    int err = errno;
    ::close(fd);
    throw Error(path + ": " + std::strerror(err));
  }
  if (size) *size = uint64_t(st.st_size);
  return f;
}

void requireRegularInput(const std::string& path, const std::string& what) {
  std::fclose(openRegularInput(path, what));
}


// stat() without opening (pbrt Include, PLY): see the header.
RegularFileCheck checkRegularFile(const std::string& path) {
  RegularFileCheck r;
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    int err = errno;
    r.problem = err == ENOENT ? "it does not exist" : std::strerror(err);
    return r;
  }
  if (S_ISREG(st.st_mode)) {
    r.ok = true;
    r.size = uint64_t(st.st_size);
  } else if (S_ISDIR(st.st_mode)) {
    r.problem = "it is a directory";
  } else if (S_ISFIFO(st.st_mode)) {
    r.problem = "it is a FIFO (named pipe), not a regular file";
  } else if (S_ISSOCK(st.st_mode)) {
    r.problem = "it is a socket, not a regular file";
  } else if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) {
    r.problem = "it is a device, not a regular file";
  } else {
    r.problem = "it is not a regular file";
  }
  return r;
}

}  // namespace tdpm
