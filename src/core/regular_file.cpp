// core/regular_file.cpp — stat() before open(): see regular_file.h.
#include "core/regular_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace tdpm {

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
