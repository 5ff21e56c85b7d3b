// core/error.h — the two kinds of failure in tdpm.
//  * tdpm::Error: bad input from the user (scene file, flags, files). The
//    message is complete and user-facing; the CLI prints it and exits 1.
//  * TDPM_ASSERT: a broken internal invariant (a bug), with file and line.
#pragma once
#include <stdexcept>
#include <string>

namespace tdpm {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

[[noreturn]] void assertionFailed(const char* expr, const char* file, int line, const std::string& what);

}  // namespace tdpm

#define TDPM_ASSERT(cond, what)                                                 \
  do {                                                                          \
    if (!(cond)) ::tdpm::assertionFailed(#cond, __FILE__, __LINE__, (what));    \
  } while (0)
