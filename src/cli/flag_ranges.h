// cli/flag_ranges.h — CLI11 validators for the ranges of scene/limits.h, so
// a flag and its scene key accept the same values. The float check is ours,
// not CLI::Range: NaN compares false and slipped through CLI::Range, and
// CLI::Range prints float bounds as "0.000000".
#pragma once
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "scene/limits.h"

namespace tdpm::cli {

inline std::string formatG(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

inline CLI::Range rangeOf(scene::limits::IntRange r) { return CLI::Range(r.lo, r.hi); }

// The value is checked as the float the option stores (and the scene key
// reads): compared in double, "0.001" was below its own bound 1e-3f.
inline CLI::Validator rangeOf(scene::limits::FloatRange r) {
  std::string range = scene::limits::rangeText(r);
  return CLI::Validator(
      [r, range](std::string& text) -> std::string {
        char* end = nullptr;
        double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return "expected a number, got '" + text + "'";
        float f = float(v);
        if (!(f >= r.lo && f <= r.hi)) return "Value " + text + " not in range " + range;
        return "";
      },
      "FLOAT in [" + range + "]");
}

}  // namespace tdpm::cli
