// cli/path_names.h — the few path-string helpers the subcommands share
// (output checks, default output names, frame patterns): pure string
// functions, no file system access.
#pragma once
#include <string>

namespace tdpm::cli {

// "a/b/c.exr" -> "a/b"; "c.exr" -> "."; "/c.exr" -> "/".
inline std::string directoryOf(const std::string& path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// "scenes/glass-ball.json" -> "glass-ball" (a leading dot is part of the name).
inline std::string stemOf(const std::string& path) {
  size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

inline bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace tdpm::cli
