// tests/error_capture.h — the message of the tdpm::Error a call throws, so
// that bad-input tests can check what the user is told in one line.
#pragma once
#include <string>
#include <utility>

#include "core/error.h"

namespace tdpm::test {

// What `f()` throws as tdpm::Error, or "(no error)" when it returns.
template <class F>
std::string errorMessageOf(F&& f) {
  try {
    std::forward<F>(f)();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace tdpm::test
