// scene/parse_node.cpp — typed, located reading of JSON values (see
// parse_node.h). Every check here produces one specific message; the scene
// parser adds the range checks that depend on meaning.
#include "scene/parse_node.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace tdpm::scene::detail {

void Source::fail(const std::string& path, const std::string& problem) const {
  int line = locator ? locator->line(path) : 1;
  throw Error(file + ":" + std::to_string(line) + ": " + displayPath(path) + ": " + problem);
}

std::string describeKind(const Json& v) {
  switch (v.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case Json::value_t::string: return "a string";
    case Json::value_t::array:
      return v.empty() ? "an empty array" : "an array of " + std::to_string(v.size()) + " element" + (v.size() == 1 ? "" : "s");
    case Json::value_t::object: return "an object";
    default: return "a number";
  }
}

std::string formatNumber(double v) {
  char buf[32];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (float(std::strtod(buf, nullptr)) == float(v)) break;
  }
  return buf;
}

std::string formatRgb(const Rgb& c) {
  return "[" + formatNumber(c.r) + ", " + formatNumber(c.g) + ", " + formatNumber(c.b) + "]";
}

std::string formatVec(const Vec3f& v) {
  return "[" + formatNumber(v.x) + ", " + formatNumber(v.y) + ", " + formatNumber(v.z) + "]";
}

std::string joinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Levenshtein distance, for "did you mean" hints on misspelt keys.
static size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

static std::string closestName(const std::string& key, const std::vector<std::string>& names) {
  std::string best;
  size_t bestDistance = std::max<size_t>(2, key.size() / 3) + 1;  // only near misses
  for (const auto& n : names) {
    size_t d = editDistance(key, n);
    if (d < bestDistance) { best = n; bestDistance = d; }
  }
  return best;
}

void Node::wrongKind(const std::string& expected) const {
  fail("expected " + expected + ", got " + describeKind(*value_));
}

void Node::requireObject() const {
  if (!value_->is_object()) wrongKind("an object");
}

void Node::expectObject(const std::vector<std::string>& allowed) const {
  requireObject();
  for (const auto& item : value_->items()) {
    if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
    std::vector<std::string> sorted = allowed;
    std::sort(sorted.begin(), sorted.end());
    std::string hint = closestName(item.key(), allowed);
    source_->fail(childPath(path_, item.key()),
                  "unknown key \"" + item.key() + "\"" + (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                      "; allowed keys: " + joinNames(sorted));
  }
}

Node Node::member(const std::string& key) const { return Node((*value_)[key], childPath(path_, key), *source_); }

Node Node::required(const std::string& key) const {
  if (!has(key)) fail("missing required key \"" + key + "\"");
  return member(key);
}

size_t Node::arraySize(const char* what) const {
  if (!value_->is_array()) wrongKind(std::string("an array of ") + what);
  return value_->size();
}

Node Node::element(size_t i) const { return Node((*value_)[i], elementPath(path_, i), *source_); }

float Node::number() const {
  if (!value_->is_number()) wrongKind("a number");
  double d = value_->get<double>();
  // JSON has no NaN literal and nlohmann rejects overflowing literals, but a
  // finite double can still overflow a float (1e39).
  if (!std::isfinite(d) || std::fabs(d) > double(FLT_MAX))
    fail("number " + formatNumber(d) + " is not finite as a 32-bit float");
  return float(d);
}

int64_t Node::integer() const {
  if (value_->is_number_integer() && !value_->is_number_unsigned()) return value_->get<int64_t>();
  if (value_->is_number_unsigned()) {
    uint64_t u = value_->get<uint64_t>();
    if (u > uint64_t(INT64_MAX)) fail("integer " + std::to_string(u) + " is too large");
    return int64_t(u);
  }
  if (!value_->is_number()) wrongKind("an integer");
  double d = value_->get<double>();
  // Accept 16.0 or 1e3, which JSON tools write; reject 1.5.
  if (!std::isfinite(d) || d != std::floor(d) || std::fabs(d) > 9007199254740992.0)
    fail("expected an integer, got " + formatNumber(d));
  return int64_t(d);
}

uint64_t Node::unsignedInteger() const {
  if (value_->is_number_unsigned()) return value_->get<uint64_t>();
  int64_t v = integer();
  if (v < 0) fail("expected a non-negative integer, got " + std::to_string(v));
  return uint64_t(v);
}

std::string Node::string() const {
  if (!value_->is_string()) wrongKind("a string");
  return value_->get<std::string>();
}

std::string Node::choice(const std::vector<std::string>& choices, const char* what) const {
  std::string s = string();
  if (std::find(choices.begin(), choices.end(), s) == choices.end())
    fail(std::string("unknown ") + what + " \"" + s + "\"; expected one of " + joinNames(choices));
  return s;
}

std::vector<float> Node::numbers(size_t count, const char* shape) const {
  if (!value_->is_array() || value_->size() != count) wrongKind(shape);
  std::vector<float> out(count);
  for (size_t i = 0; i < count; ++i) out[i] = element(i).number();
  return out;
}

Vec2f Node::vec2() const {
  auto v = numbers(2, "an array of 2 numbers");
  return {v[0], v[1]};
}

Vec3f Node::vec3() const {
  auto v = numbers(3, "an array of 3 numbers");
  return {v[0], v[1], v[2]};
}

Rgb Node::color() const {
  Rgb c;
  if (value_->is_number()) {
    c = Rgb(number());
  } else {
    if (!value_->is_array() || value_->size() != 3) wrongKind("a number or an array of 3 numbers [r, g, b]");
    auto v = numbers(3, "an array of 3 numbers");
    c = {v[0], v[1], v[2]};
  }
  require(c.r >= 0 && c.g >= 0 && c.b >= 0, "must be non-negative in every channel, got " + formatRgb(c));
  return c;
}

Vec3f Node::numberOrVec3() const {
  if (value_->is_number()) return Vec3f(number());
  if (!value_->is_array() || value_->size() != 3) wrongKind("a number or an array of 3 numbers [x, y, z]");
  return vec3();
}

}  // namespace tdpm::scene::detail
