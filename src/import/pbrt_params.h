// import/pbrt_params.h — a statement's parameter list ("type name" value
// pairs) with typed, checked access. Every parameter a statement does not
// read is an error (checkAllUsed), so nothing in a file is silently ignored.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm::pbrt {

struct Param {
  std::string type;  // as written: float, integer, rgb, point3, string, bool, texture, ...
  std::string name;
  std::vector<double> numbers;
  std::vector<std::string> strings;  // string, texture, bool (true/false), spectrum names
  int line = 0;
  mutable bool used = false;
};

class ParamSet {
 public:
  ParamSet() = default;
  ParamSet(std::vector<Param> params, std::string file, std::string statement)
      : params_(std::move(params)), file_(std::move(file)), statement_(std::move(statement)) {}

  bool has(const std::string& name) const { return find(name) != nullptr; }
  const Param* find(const std::string& name) const;
  // Typed readers: the fallback when absent; an error naming file:line,
  // the statement and the parameter when the type or count is wrong.
  double getFloat(const std::string& name, double fallback) const;
  int getInt(const std::string& name, int fallback) const;
  bool getBool(const std::string& name, bool fallback) const;
  std::string getString(const std::string& name, const std::string& fallback) const;
  Vec3f getPoint(const std::string& name, Vec3f fallback) const;  // point3/point/vector3/vector/normal
  std::vector<double> getFloats(const std::string& name) const;   // float[] / point3[] etc. raw numbers
  std::vector<int64_t> getInts(const std::string& name) const;

  // Marks a parameter as deliberately ignored (with a note by the caller).
  void markUsed(const std::string& name) const;
  // Error for the first parameter no reader asked for.
  void checkAllUsed() const;

  [[noreturn]] void fail(const Param& p, const std::string& what) const;
  const std::string& statement() const { return statement_; }
  const std::string& file() const { return file_; }

 private:
  const Param& expect(const std::string& name, const std::vector<std::string>& types, size_t count) const;
  std::vector<Param> params_;
  std::string file_, statement_;
};

}  // namespace tdpm::pbrt
