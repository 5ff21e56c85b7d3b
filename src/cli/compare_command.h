// cli/compare_command.h — `tdpm compare TEST REF`: error metrics of a test
// image against a reference (text or JSON), optionally over a crop, and a
// line profile through one row as CSV and as an SVG plot. Either image may
// be OpenEXR, PFM, Radiance HDR or PNG (image/read_image.h).
// Exit codes: 0 measured; 1 bad input (missing or unreadable file, sizes
// that differ, NaN/Inf values without --allow-nonfinite, crop or row
// outside the images, unwritable output); 2 usage (malformed --crop,
// --csv/--plot without --profile-row).
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace tdpm::cli {

struct CompareArgs {
  std::string test;
  std::string reference;
  bool json = false;
  bool allowNonFinite = false;
  std::optional<std::string> crop;  // "x,y,w,h"
  std::optional<int> profileRow;
  std::optional<std::string> csv;
  std::optional<std::string> plot;
  bool salt = false;  // --salt: isolated bright outliers (image::countSalt)
};

CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args);
int runCompare(const CompareArgs& args);

}  // namespace tdpm::cli
