// core/regular_file.h — open an input file only if it is a regular file.
// Owns: openRegularInput (and checkRegularFile, its stat()-only form), the one way tdpm opens a file it reads by name
// when a FIFO, a device or a socket must not be read (issue 27 item 6).
// Why: stat() then open() still blocks for ever when the name is a FIFO
// with no writer (open(O_RDONLY) waits for one), and a device such as
// /dev/zero reads for ever. open(O_NONBLOCK) returns at once for every
// kind of file; fstat() on that descriptor then says what was opened (no
// window in which the name can be swapped), and only a regular file is
// kept, switched back to blocking reads.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

namespace tdpm {

// Opens `path` for reading and returns it as a FILE* (the caller closes
// it), with its size in `size` when that is not null. Throws tdpm::Error
//   "<path>: <system reason>"                         missing, unreadable, ...
//   "<path>: is a directory, not <what>"
//   "<path>: is a FIFO (named pipe), not <what>: only regular files are read"
//   (likewise "a character device", "a block device", "a socket")
// `what` names what was expected, for example "an OpenEXR file".
std::FILE* openRegularInput(const std::string& path, const std::string& what, uint64_t* size = nullptr);

// The same check without keeping the file open (it is opened and closed):
// for readers that open the file by name themselves (OpenEXR).
void requireRegularInput(const std::string& path, const std::string& what);

// The answer of stat() alone, for readers that open the file themselves
// (std::ifstream: pbrt Include, PLY) and want its size for a budget first.
// stat() follows symlinks and never blocks; a name swapped for a FIFO
// between this check and the open is not caught (openRegularInput is).
struct RegularFileCheck {
  bool ok = false;
  uint64_t size = 0;   // bytes, when ok
  std::string problem;  // when not ok: "it does not exist", "it is a directory", "it is a FIFO (named pipe)", ...
};

// stat()s `path` (following symlinks) without opening it.
RegularFileCheck checkRegularFile(const std::string& path);

}  // namespace tdpm
