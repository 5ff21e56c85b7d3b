// scene/parse_node.h — owns the typed, located reading of one JSON value
// for the scene parser (scene/parse.cpp): type checks, finiteness, key
// tables and the "<file>:<line>: <path>: <problem>" error format. Internal to
// scene/ (it exposes nlohmann::json, which tdpm_lib links privately).
#pragma once
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "math/vec.h"
#include "scene/json_locate.h"

namespace tdpm::scene::detail {

using Json = nlohmann::json;

// Where errors point: the file as named by the user and its locator.
struct Source {
  std::string file;
  const JsonLocator* locator = nullptr;

  [[noreturn]] void fail(const std::string& path, const std::string& problem) const;
};

// "a string", "an array", "true", ... for "expected X, got <kind>".
std::string describeKind(const Json& v);
// Shortest round-trip spelling of a number for messages ("0.1", not "0.100000001").
std::string formatNumber(double v);
std::string formatRgb(const Rgb& c);
std::string formatVec(const Vec3f& v);
// "a, b, c" for the allowed-value lists in messages.
std::string joinNames(const std::vector<std::string>& names);

// One JSON value plus the path that leads to it.
class Node {
 public:
  Node(const Json& value, std::string path, const Source& source)
      : value_(&value), path_(std::move(path)), source_(&source) {}

  const Json& json() const { return *value_; }
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(const std::string& problem) const { source_->fail(path_, problem); }
  void require(bool ok, const std::string& problem) const {
    if (!ok) fail(problem);
  }

  // ---- objects
  // Fails unless this is an object whose keys all appear in `allowed`.
  void expectObject(const std::vector<std::string>& allowed) const;
  // Fails unless this is an object (keys are checked later, once known).
  void requireObject() const;
  bool has(const std::string& key) const { return value_->contains(key); }
  Node member(const std::string& key) const;    // must exist (see has/required)
  Node required(const std::string& key) const;  // "missing required key" otherwise
  // Calls f(key, node) for every member, in key order.
  template <class F>
  void forEachMember(F&& f) const {
    requireObject();
    for (const auto& item : value_->items()) f(item.key(), Node(item.value(), childPath(path_, item.key()), *source_));
  }

  // ---- arrays
  // Fails unless this is an array; `what` describes the elements in messages.
  size_t arraySize(const char* what) const;
  Node element(size_t i) const;

  // ---- scalars (all finite and representable as float / int)
  float number() const;
  int64_t integer() const;   // an integer, or a number with an integral value
  uint64_t unsignedInteger() const;
  std::string string() const;
  // A string that must be one of `choices`.
  std::string choice(const std::vector<std::string>& choices, const char* what) const;

  // ---- small vectors
  Vec2f vec2() const;  // [x, y]
  Vec3f vec3() const;  // [x, y, z]
  // A number (grey) or [r, g, b], every channel >= 0.
  Rgb color() const;
  // A number (uniform) or [x, y, z].
  Vec3f numberOrVec3() const;

 private:
  // Reads a fixed-size numeric array; `shape` is used in type messages.
  std::vector<float> numbers(size_t count, const char* shape) const;
  [[noreturn]] void wrongKind(const std::string& expected) const;

  const Json* value_;
  std::string path_;
  const Source* source_;
};

}  // namespace tdpm::scene::detail
