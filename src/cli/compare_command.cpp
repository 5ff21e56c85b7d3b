// cli/compare_command.cpp — the compare subcommand: flags, validation (every
// check before any output is written), metrics printout, profile files.
#include "cli/compare_command.h"
#include "cli/path_names.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "image/image_header.h"
#include "image/read_image.h"
#include "image/metrics.h"
#include "image/profile_plot.h"

namespace tdpm::cli {

namespace {

using image::ImageMetrics;
using image::PixelRect;

// "x,y,w,h" -> rect; an empty string on success, else what is wrong. Only the
// syntax and signs are checked here (a usage error, exit 2); whether the
// rectangle fits the images is known once they are read (exit 1).
std::string parseCrop(const std::string& text, PixelRect& r) {
  std::istringstream in(text);
  long long v[4];
  char sep = 0;
  for (int i = 0; i < 4; ++i) {
    if (!(in >> v[i])) return "expected x,y,w,h (four integers, e.g. 100,50,64,32), got '" + text + "'";
    if (i < 3 && (!(in >> sep) || sep != ','))
      return "expected x,y,w,h (four integers separated by commas), got '" + text + "'";
  }
  if (in >> sep) return "expected x,y,w,h (four integers), got '" + text + "' (trailing characters)";
  if (v[0] < 0 || v[1] < 0) return "x and y must be >= 0, got '" + text + "'";
  if (v[2] < 1 || v[3] < 1) return "w and h must be >= 1, got '" + text + "'";
  for (long long x : v)
    if (x > 1 << 20) return "values must be at most 1048576, got '" + text + "'";
  r = {int(v[0]), int(v[1]), int(v[2]), int(v[3])};
  return "";
}

void checkWritable(const std::string& flag, const std::string& path) {
  std::string dir = directoryOf(path);
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(flag + ": cannot write to directory '" + dir + "' (" + std::strerror(errno) + ")");
}

std::string sizeText(const image::ImageRgb& im) { return std::to_string(im.width) + "x" + std::to_string(im.height); }

std::string rectText(const PixelRect& r) {
  return "x " + std::to_string(r.x) + ".." + std::to_string(int64_t(r.x) + r.w - 1) + ", y " + std::to_string(r.y) +
         ".." + std::to_string(int64_t(r.y) + r.h - 1);
}

// Profile summary: where each curve peaks and its mean luminance, so a
// caustic that lost energy or moved shows without opening the plot.
struct ProfileSummary {
  int testPeakX = 0, refPeakX = 0;
  double testPeak = 0, refPeak = 0, testMean = 0, refMean = 0;
};

ProfileSummary summarize(const image::RowProfile& p) {
  ProfileSummary s;
  s.testPeak = s.refPeak = -1e300;
  for (size_t i = 0; i < p.test.size(); ++i) {
    double t = p.test[i].luminance(), r = p.ref[i].luminance();
    if (!std::isfinite(t)) t = 0;
    if (!std::isfinite(r)) r = 0;
    if (t > s.testPeak) s.testPeak = t, s.testPeakX = p.x0 + int(i);
    if (r > s.refPeak) s.refPeak = r, s.refPeakX = p.x0 + int(i);
    s.testMean += t / double(p.test.size());
    s.refMean += r / double(p.test.size());
  }
  return s;
}

// ordered_json: keys print in the order written (r, g, b, overall), for people reading it.
nlohmann::ordered_json channelsJson(const ImageMetrics& m, double image::ChannelMetrics::*field) {
  return {{"r", m.channel[0].*field}, {"g", m.channel[1].*field}, {"b", m.channel[2].*field}, {"overall", m.overall.*field}};
}

void printText(const CompareArgs& a, const image::LoadedImage& testFile, const image::LoadedImage& refFile,
               const ImageMetrics& m, const std::optional<image::RowProfile>& profile,
               const std::optional<image::SaltMetrics>& salt) {
  const image::ImageRgb& test = testFile.color;
  std::printf("test:      %s (%s, %s)\n", a.test.c_str(), sizeText(test).c_str(), image::formatName(testFile.format));
  std::printf("reference: %s (%s, %s)\n", a.reference.c_str(), sizeText(test).c_str(),
              image::formatName(refFile.format));
  if (m.nonFiniteTest || m.nonFiniteRef)
    std::printf("non-finite: %zu values in test, %zu in reference (measured as 0, --allow-nonfinite)\n",
                m.nonFiniteTest, m.nonFiniteRef);
  if (a.crop)
    std::printf("region:    crop %d,%d,%d,%d (%s), %zu pixels\n", m.region.x, m.region.y, m.region.w, m.region.h,
                rectText(m.region).c_str(), m.pixelCount);
  else
    std::printf("region:    whole image, %zu pixels\n", m.pixelCount);
  std::printf("\n%-12s %14s %14s %14s %14s\n", "", "R", "G", "B", "overall");
  struct Row {
    const char* name;
    double image::ChannelMetrics::*field;
  };
  for (Row row : {Row{"RMSE", &image::ChannelMetrics::rmse}, Row{"relMSE", &image::ChannelMetrics::relMse},
                  Row{"MAE", &image::ChannelMetrics::mae}, Row{"max |error|", &image::ChannelMetrics::maxAbs},
                  Row{"mean test", &image::ChannelMetrics::meanTest},
                  Row{"mean ref", &image::ChannelMetrics::meanRef}}) {
    std::printf("%-12s", row.name);
    for (int c = 0; c < 3; ++c) std::printf(" %14.6g", m.channel[c].*row.field);
    std::printf(" %14.6g\n", m.overall.*row.field);
  }
  if (auto d = m.relativeMeanDifference())
    std::printf("\nmean difference: %+.3f%% (test %s than reference)\n", 100.0 * *d,
                *d < 0 ? "darker" : *d > 0 ? "brighter" : "no brighter or darker");
  else
    std::printf("\nmean difference: n/a (reference is black)\n");
  std::printf("relMSE = mean (test - ref)^2 / (ref + 0.01)^2, as pbrt-v4's MRSE\n");
  if (salt)
    std::printf("salt: %zu pixels (%.4f%%) above 3x both 5x5 medians (reference's and test's)\n", salt->count,
                100.0 * salt->share);
  if (profile) {
    ProfileSummary s = summarize(*profile);
    std::printf("\nprofile row %d, x %d..%d: peak luminance test %.6g at x=%d, ref %.6g at x=%d; mean test %.6g, ref %.6g\n",
                profile->y, profile->x0, profile->x0 + int(profile->test.size()) - 1, s.testPeak, s.testPeakX, s.refPeak,
                s.refPeakX, s.testMean, s.refMean);
    if (a.csv) std::printf("profile csv:  %s\n", a.csv->c_str());
    if (a.plot) std::printf("profile plot: %s\n", a.plot->c_str());
  }
}

void printJson(const CompareArgs& a, const image::LoadedImage& testFile, const image::LoadedImage& refFile,
               const ImageMetrics& m, const std::optional<image::RowProfile>& profile,
               const std::optional<image::SaltMetrics>& salt) {
  using json = nlohmann::ordered_json;
  using CM = image::ChannelMetrics;
  const image::ImageRgb& test = testFile.color;
  json j;
  j["test"] = a.test;
  j["reference"] = a.reference;
  j["test_format"] = image::formatName(testFile.format);
  j["reference_format"] = image::formatName(refFile.format);
  j["width"] = test.width;
  j["height"] = test.height;
  j["region"] = {{"x", m.region.x}, {"y", m.region.y}, {"w", m.region.w}, {"h", m.region.h}, {"cropped", bool(a.crop)}};
  j["pixels"] = m.pixelCount;
  j["rmse"] = channelsJson(m, &CM::rmse);
  j["mse"] = channelsJson(m, &CM::mse);
  j["rel_mse"] = channelsJson(m, &CM::relMse);
  j["mae"] = channelsJson(m, &CM::mae);
  j["max_abs_error"] = channelsJson(m, &CM::maxAbs);
  j["mean_test"] = channelsJson(m, &CM::meanTest);
  j["mean_reference"] = channelsJson(m, &CM::meanRef);
  auto d = m.relativeMeanDifference();
  j["relative_mean_difference"] = d ? json(*d) : json(nullptr);
  j["nonfinite_values"] = {{"test", m.nonFiniteTest}, {"reference", m.nonFiniteRef}};
  j["rel_mse_definition"] = "mean over pixels of (test - ref)^2 / (ref + 0.01)^2 per channel (pbrt-v4 MRSE)";
  if (salt)
    j["salt"] = {{"count", salt->count},
                 {"share", salt->share},
                 {"definition", "pixels whose luminance is above 3x both the reference's and the test's own 5x5 median"}};
  if (profile) {
    ProfileSummary s = summarize(*profile);
    j["profile"] = {{"row", profile->y},
                    {"x0", profile->x0},
                    {"width", profile->test.size()},
                    {"test_peak", {{"x", s.testPeakX}, {"luminance", s.testPeak}}},
                    {"ref_peak", {{"x", s.refPeakX}, {"luminance", s.refPeak}}},
                    {"test_mean_luminance", s.testMean},
                    {"ref_mean_luminance", s.refMean},
                    {"csv", a.csv ? json(*a.csv) : json(nullptr)},
                    {"plot", a.plot ? json(*a.plot) : json(nullptr)}};
  }
  std::printf("%s\n", j.dump(2).c_str());
}

}  // namespace

CLI::App* addCompareCommand(CLI::App& app, CompareArgs& a) {
  CLI::App* c = app.add_subcommand(
      "compare",
      "Error of a test image against a reference (RMSE, relative MSE as pbrt-v4's MRSE, MAE, max error, means; "
      "per channel and overall), and line profiles through one row");
  c->add_option("test", a.test, "Test image: OpenEXR, PFM, Radiance HDR or PNG (8-bit sRGB decoded to linear)")
      ->required();
  c->add_option("reference", a.reference, "Reference image, same size, in any of those formats")->required();
  c->add_flag("--json", a.json, "Print the metrics as one JSON object instead of a table");
  c->add_flag("--salt", a.salt,
              "Also count salt: pixels whose luminance is above 3x both the reference's and the test's own 5x5 "
              "median (count and share of the region's pixels; in --json as \"salt\")");
  c->add_flag("--allow-nonfinite", a.allowNonFinite,
              "Measure images with NaN or infinite values (counted as 0 and reported per image) instead of "
              "refusing them");
  c->add_option("--crop", a.crop, "Measure only the rectangle x,y,w,h (pixels; 0,0 is the top left)")
      ->check(CLI::Validator(
          [](std::string& s) {
            PixelRect r;
            return parseCrop(s, r);
          },
          "X,Y,W,H"));
  CLI::Option* row =
      c->add_option("--profile-row", a.profileRow, "Image row (0 = top) for a line profile of both images")
          ->check(CLI::Range(0, 1 << 20));
  c->add_option("--csv", a.csv, "Write the profile as CSV: x,test_r,test_g,test_b,ref_r,ref_g,ref_b,test_lum,ref_lum")
      ->needs(row);
  c->add_option("--plot", a.plot, "Write the profile's luminance as an SVG line chart (test over reference)")
      ->needs(row);
  return c;
}

namespace {

// Outputs first: a wrong path must not cost reading two large EXRs. By
// file identity (st_dev/st_ino), not by name: a link to an input, or another
// spelling of its path, would overwrite it just the same.
void checkCompareOutputs(const CompareArgs& a) {
  if (a.plot && !endsWith(*a.plot, ".svg")) throw Error("--plot: '" + *a.plot + "' must end in .svg (it is an SVG file)");
  auto same = [](const std::string& x, const std::string& y) { return x == y || sameFile(x, y); };
  if (a.csv && a.plot && same(*a.csv, *a.plot)) throw Error("--csv and --plot name the same file '" + *a.csv + "'");
  for (const auto& [flag, out] : {std::pair{"--csv", a.csv}, std::pair{"--plot", a.plot}}) {
    if (!out) continue;
    for (const std::string* in : {&a.test, &a.reference})
      if (same(*out, *in))
        throw Error(std::string(flag) + ": '" + *out + "' is the input image '" + *in + "'" +
                    (*out == *in ? "" : " (the same file)") + "; refusing to overwrite it");
    checkWritable(flag, *out);
  }
}

// `read(path)` with the image's role in front of the reader's error (which
// already names the file).
template <class Read>
auto readAs(const char* role, const std::string& path, Read read) {
  try {
    return read(path);
  } catch (const Error& e) {
    throw Error(std::string(role) + ": " + e.what());
  }
}

// Both images, sizes compared from their headers before either is decoded
// (a small PNG can claim 20000x20000; a header too damaged to tell is left
// to the reader), and again after decoding.
void readComparedImages(const CompareArgs& a, image::LoadedImage& test, image::LoadedImage& ref) {
  std::optional<image::ImageHeader> th = readAs("test image", a.test, image::readImageHeader);
  std::optional<image::ImageHeader> rh = readAs("reference image", a.reference, image::readImageHeader);
  if (th && rh && (th->width != rh->width || th->height != rh->height))
    throw Error("image sizes differ: " + a.test + " is " + std::to_string(th->width) + "x" + std::to_string(th->height) +
                " but " + a.reference + " is " + std::to_string(rh->width) + "x" + std::to_string(rh->height) +
                " (compare needs two images of the same size; read from their headers)");
  test = readAs("test image", a.test, image::readImage);
  ref = readAs("reference image", a.reference, image::readImage);
  if (test.color.width != ref.color.width || test.color.height != ref.color.height)
    throw Error("image sizes differ: " + a.test + " is " + sizeText(test.color) + " but " + a.reference + " is " +
                sizeText(ref.color) + " (compare needs two images of the same size)");
}

std::optional<PixelRect> cropFor(const CompareArgs& a, const image::ImageRgb& im) {
  if (!a.crop) return std::nullopt;
  PixelRect r;
  std::string why = parseCrop(*a.crop, r);
  if (!why.empty()) throw Error("--crop: " + why);  // CLI11 checked already; kept for direct callers
  if (!image::cropInside(r, im.width, im.height))
    throw Error("--crop " + *a.crop + ": the rectangle (" + rectText(r) + ") is not inside the " + sizeText(im) +
                " images (columns 0.." + std::to_string(im.width - 1) + ", rows 0.." + std::to_string(im.height - 1) +
                ")");
  return r;
}

// With --crop the profile covers the crop's columns, and its row must be
// one of the crop's rows: everything reported is about that rectangle.
std::optional<image::RowProfile> profileFor(const CompareArgs& a, const image::ImageRgb& test, const image::ImageRgb& ref,
                                            const std::optional<PixelRect>& crop) {
  if (!a.profileRow) return std::nullopt;
  int y = *a.profileRow;
  if (y < 0 || y >= test.height)
    throw Error("--profile-row " + std::to_string(y) + ": outside the " + sizeText(test) + " images (rows 0.." +
                std::to_string(test.height - 1) + ")");
  if (crop && (y < crop->y || y >= crop->y + crop->h))
    throw Error("--profile-row " + std::to_string(y) + ": outside --crop " + *a.crop + " (rows " +
                std::to_string(crop->y) + ".." + std::to_string(crop->y + crop->h - 1) + ")");
  return crop ? image::extractRowProfile(test, ref, y, crop->x, crop->w)
              : image::extractRowProfile(test, ref, y, 0, test.width);
}

// NaN or Inf would count as 0: an Inf where the reference is 0 would score
// no error. Refused unless asked for, before any output.
void refuseNonFinite(const CompareArgs& a, const image::ImageRgb& test, const image::ImageRgb& ref, const PixelRect& region) {
  if (a.allowNonFinite) return;
  for (const auto& [role, path, im] :
       {std::tuple{"test image", &a.test, &test}, std::tuple{"reference image", &a.reference, &ref}}) {
    image::NonFiniteValues bad = image::findNonFinite(*im, region);
    if (bad.count)
      throw Error(std::string(role) + ": " + *path + ": " + std::to_string(bad.count) + " NaN or infinite values" +
                  (a.crop ? " inside --crop" : "") + ", the first at pixel (" + std::to_string(bad.x) + ", " +
                  std::to_string(bad.y) + ") channel " + "RGB"[bad.channel] +
                  "; --allow-nonfinite measures them as 0 and reports their counts");
  }
}

// Both profile files or neither, committed together: on any failure the
// previous pair (if any) stays as it was.
void writeProfileFiles(const CompareArgs& a, const image::RowProfile& profile) {
  std::optional<AtomicFile> csvFile, plotFile;
  if (a.csv) {
    csvFile.emplace(*a.csv);
    writeTextToTemp(*csvFile, image::profileCsv(profile));
  }
  if (a.plot) {
    plotFile.emplace(*a.plot);
    writeTextToTemp(*plotFile, image::profileSvg(profile, a.test, a.reference));
  }
  if (csvFile && plotFile) commitTogether({&*csvFile, &*plotFile});
  else if (csvFile) csvFile->commit();
  else if (plotFile) plotFile->commit();
}

}  // namespace

// One level: check the outputs, read both images, measure, write, print.
// Nothing is written unless everything before it succeeded.
int runCompare(const CompareArgs& a) {
  checkCompareOutputs(a);
  image::LoadedImage test, ref;
  readComparedImages(a, test, ref);
  const std::optional<PixelRect> crop = cropFor(a, test.color);
  const std::optional<image::RowProfile> profile = profileFor(a, test.color, ref.color, crop);
  const PixelRect region = crop.value_or(PixelRect{0, 0, test.color.width, test.color.height});
  refuseNonFinite(a, test.color, ref.color, region);

  ImageMetrics m = image::compareImages(test.color, ref.color, crop);
  std::optional<image::SaltMetrics> salt;
  if (a.salt) salt = image::countSalt(test.color, ref.color, region);
  if (profile) writeProfileFiles(a, *profile);

  if (m.nonFiniteTest || m.nonFiniteRef)
    std::fprintf(stderr, "tdpm: warning: %zu non-finite values in %s and %zu in %s were counted as 0\n",
                 m.nonFiniteTest, a.test.c_str(), m.nonFiniteRef, a.reference.c_str());
  if (a.json) printJson(a, test, ref, m, profile, salt);
  else printText(a, test, ref, m, profile, salt);
  return 0;
}

}  // namespace tdpm::cli
