// core/regular_file.h — "is this name a regular file, and how big is it?",
// answered by stat() before anything opens the file. open() on a FIFO
// blocks until a writer appears (for ever, for a hostile input), and a
// device such as /dev/zero never ends, so every reader of user-named input
// files asks here first and refuses anything else with a clear reason.
#pragma once
#include <cstdint>
#include <string>

namespace tdpm {

struct RegularFileCheck {
  bool ok = false;
  uint64_t size = 0;   // bytes, when ok
  std::string problem;  // when not ok: "it does not exist", "it is a directory", "it is a FIFO (named pipe)", ...
};

// stat()s `path` (following symlinks) without opening it.
RegularFileCheck checkRegularFile(const std::string& path);

}  // namespace tdpm
