// import/pbrt_params.cpp — typed access to a statement's parameters.
#include "import/pbrt_params.h"

#include <cmath>

#include "core/error.h"

namespace tdpm::pbrt {

namespace {

std::string joinTypes(const std::vector<std::string>& types) {
  std::string s;
  for (const auto& t : types) s += (s.empty() ? "" : " or ") + t;
  return s;
}

}  // namespace

const Param* ParamSet::find(const std::string& name) const {
  for (const Param& p : params_)
    if (p.name == name) return &p;
  return nullptr;
}

void ParamSet::fail(const Param& p, const std::string& what) const {
  throw Error(file_ + ":" + std::to_string(p.line) + ": " + statement_ + ": parameter \"" + p.type + " " + p.name +
              "\": " + what);
}

const Param& ParamSet::expect(const std::string& name, const std::vector<std::string>& types, size_t count) const {
  const Param* p = find(name);
  p->used = true;
  bool typeOk = false;
  for (const auto& t : types) typeOk = typeOk || p->type == t;
  if (!typeOk) fail(*p, "expected type " + joinTypes(types));
  bool textual = p->type == "string" || p->type == "bool" || p->type == "texture";
  if (textual && !p->numbers.empty()) fail(*p, "expected a quoted string, got a number");
  if (!textual && !p->strings.empty()) fail(*p, "expected numbers, got \"" + p->strings[0] + "\"");
  size_t have = p->numbers.size() + p->strings.size();
  if (count && have != count)
    fail(*p, "expected " + std::to_string(count) + " value" + (count > 1 ? "s" : "") + ", got " + std::to_string(have));
  return *p;
}

double ParamSet::getFloat(const std::string& name, double fallback) const {
  if (!has(name)) return fallback;
  return expect(name, {"float"}, 1).numbers.at(0);
}

int ParamSet::getInt(const std::string& name, int fallback) const {
  if (!has(name)) return fallback;
  const Param& p = expect(name, {"integer"}, 1);
  double v = p.numbers.at(0);
  if (v != std::floor(v) || std::fabs(v) > 2147483647.0) fail(p, "expected an integer, got " + std::to_string(v));
  return int(v);
}

bool ParamSet::getBool(const std::string& name, bool fallback) const {
  if (!has(name)) return fallback;
  const Param& p = expect(name, {"bool"}, 1);
  if (p.strings.empty() || (p.strings[0] != "true" && p.strings[0] != "false")) fail(p, "expected true or false");
  return p.strings[0] == "true";
}

std::string ParamSet::getString(const std::string& name, const std::string& fallback) const {
  if (!has(name)) return fallback;
  const Param& p = expect(name, {"string"}, 1);
  if (p.strings.empty()) fail(p, "expected a string");
  return p.strings[0];
}

Vec3f ParamSet::getPoint(const std::string& name, Vec3f fallback) const {
  if (!has(name)) return fallback;
  const Param& p = expect(name, {"point3", "point", "vector3", "vector", "normal3", "normal"}, 3);
  if (p.numbers.size() != 3) fail(p, "expected 3 numbers");
  return {float(p.numbers[0]), float(p.numbers[1]), float(p.numbers[2])};
}

std::vector<double> ParamSet::getFloats(const std::string& name) const {
  const Param* p = find(name);
  if (!p) return {};
  p->used = true;
  if (!p->strings.empty()) fail(*p, "expected numbers, got a string");
  return p->numbers;
}

std::vector<int64_t> ParamSet::getInts(const std::string& name) const {
  const Param* p = find(name);
  if (!p) return {};
  const Param& q = expect(name, {"integer"}, 0);
  std::vector<int64_t> out;
  out.reserve(q.numbers.size());
  for (double v : q.numbers) {
    if (v != std::floor(v) || v < 0 || v > 4294967295.0) fail(q, "expected non-negative integers, got " + std::to_string(v));
    out.push_back(int64_t(v));
  }
  (void)p;
  return out;
}

void ParamSet::markUsed(const std::string& name) const {
  if (const Param* p = find(name)) p->used = true;
}

void ParamSet::checkAllUsed() const {
  for (const Param& p : params_)
    if (!p.used) fail(p, "not supported by tdpm's pbrt import (see docs/pbrt-import.md)");
}

}  // namespace tdpm::pbrt
