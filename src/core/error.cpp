// core/error.cpp — formatting of internal assertion failures.
#include "core/error.h"

#include <sstream>

namespace tdpm {

void assertionFailed(const char* expr, const char* file, int line, const std::string& what) {
  std::ostringstream os;
  os << "internal error at " << file << ":" << line << ": " << expr << " failed";
  if (!what.empty()) os << " (" << what << ")";
  throw std::logic_error(os.str());
}

}  // namespace tdpm
