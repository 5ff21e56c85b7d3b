// tests/test_compare.cpp — image/metrics, image/profile_plot and
// `tdpm compare`: metric values on tiny hand-made images against numbers
// worked out by hand, crops, the CSV and SVG profile, the text and JSON
// output, and every error case with its exit code and no file left behind.
#include <doctest/doctest.h>

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "image/exr.h"
#include "image/metrics.h"
#include "image/profile_plot.h"

using namespace tdpm;
using namespace tdpm::image;
using test::runTdpm;

namespace {

// 2x2 images, row-major (x, y):
//            test              reference
//  (0,0)  (1, 2, 3)          (1, 1, 1)
//  (1,0)  (0.5,0.5,0.5)      (0.5,0.5,0.5)
//  (0,1)  (0, 0, 0)          (0.1, 0, 0.2)
//  (1,1)  (2, 2, 2)          (1, 2, 4)
// Differences test - ref per channel over the 4 pixels:
//  R: 0, 0, -0.1, 1      G: 1, 0, 0, 0      B: 2, 0, -0.2, -2
ImageRgb testImage() {
  ImageRgb im(2, 2);
  im.at(0, 0) = {1, 2, 3};
  im.at(1, 0) = {0.5f, 0.5f, 0.5f};
  im.at(0, 1) = {0, 0, 0};
  im.at(1, 1) = {2, 2, 2};
  return im;
}
ImageRgb refImage() {
  ImageRgb im(2, 2);
  im.at(0, 0) = {1, 1, 1};
  im.at(1, 0) = {0.5f, 0.5f, 0.5f};
  im.at(0, 1) = {0.1f, 0, 0.2f};
  im.at(1, 1) = {1, 2, 4};
  return im;
}

// The hand-worked numbers (in double; the images hold 0.1f and 0.2f, hence
// the tolerance of the comparisons).
const double kMseR = (0.01 + 1) / 4, kMseG = 1.0 / 4, kMseB = (4 + 0.04 + 4) / 4;
const double kRelR = (0.01 / (0.11 * 0.11) + 1 / (1.01 * 1.01)) / 4;
const double kRelG = (1 / (1.01 * 1.01)) / 4;
const double kRelB = (4 / (1.01 * 1.01) + 0.04 / (0.21 * 0.21) + 4 / (4.01 * 4.01)) / 4;
const double kMaeR = 1.1 / 4, kMaeG = 1.0 / 4, kMaeB = 4.2 / 4;

doctest::Approx approx(double v) { return doctest::Approx(v).epsilon(1e-6); }

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A NaN or infinity printed into the SVG's numbers ("nan", "-nan", "inf";
// not the "nan" inside "Luminance").
bool hasNonFiniteNumber(const std::string& svg) {
  for (const char* bad : {",nan", "nan,", "\"nan", "nan\"", ",inf", "inf,", "\"inf", "inf\"", " nan", " inf", "-nan", "-inf"})
    if (svg.find(bad) != std::string::npos) return true;
  return false;
}

size_t countOf(const std::string& s, const std::string& part) {
  size_t n = 0;
  for (size_t p = s.find(part); p != std::string::npos; p = s.find(part, p + 1)) ++n;
  return n;
}

void writeColorExr(const std::string& path, const ImageRgb& im) {
  ExrFile f;
  f.color = im;
  writeExr(path, f);
}

// A directory with test.exr and ref.exr (the 2x2 images above) and a 3x2
// image other.exr, for the CLI tests.
struct CompareDir {
  std::string dir = test::makeTempDir();
  CompareDir() {
    writeColorExr(dir + "/test.exr", testImage());
    writeColorExr(dir + "/ref.exr", refImage());
    writeColorExr(dir + "/other.exr", ImageRgb(3, 2, Rgb(0.5f)));
  }
  ~CompareDir() { (void)std::system(("rm -rf '" + dir + "'").c_str()); }
  std::string operator/(const std::string& name) const { return "'" + dir + "/" + name + "'"; }
  std::string path(const std::string& name) const { return dir + "/" + name; }
  std::string pair() const { return "compare " + (*this / "test.exr") + " " + (*this / "ref.exr"); }
};

}  // namespace

TEST_CASE("metrics: per channel and overall against hand-computed values") {
  ImageMetrics m = compareImages(testImage(), refImage());
  CHECK(m.pixelCount == 4);
  CHECK(m.region.x == 0);
  CHECK(m.region.w == 2);
  CHECK(m.region.h == 2);
  const double mse[3] = {kMseR, kMseG, kMseB}, rel[3] = {kRelR, kRelG, kRelB}, mae[3] = {kMaeR, kMaeG, kMaeB};
  const double maxAbs[3] = {1, 1, 2};
  const double meanTest[3] = {3.5 / 4, 4.5 / 4, 5.5 / 4}, meanRef[3] = {2.6 / 4, 3.5 / 4, 5.7 / 4};
  for (int c = 0; c < 3; ++c) {
    CAPTURE(c);
    CHECK(m.channel[c].mse == approx(mse[c]));
    CHECK(m.channel[c].rmse == approx(std::sqrt(mse[c])));
    CHECK(m.channel[c].relMse == approx(rel[c]));
    CHECK(m.channel[c].mae == approx(mae[c]));
    CHECK(m.channel[c].maxAbs == approx(maxAbs[c]));
    CHECK(m.channel[c].meanTest == approx(meanTest[c]));
    CHECK(m.channel[c].meanRef == approx(meanRef[c]));
  }
  // Overall: RMSE over all 12 values at once; relMSE, MAE, means: mean of the
  // channels (as pbrt's imgtool reports error.Average()); max: the largest.
  CHECK(m.overall.mse == approx((kMseR + kMseG + kMseB) / 3));
  CHECK(m.overall.rmse == approx(std::sqrt((0.01 + 1 + 1 + 4 + 0.04 + 4) / 12)));
  CHECK(m.overall.relMse == approx((kRelR + kRelG + kRelB) / 3));
  CHECK(m.overall.mae == approx((1.1 + 1.0 + 4.2) / 12));
  CHECK(m.overall.maxAbs == approx(2));
  CHECK(m.overall.meanTest == approx(13.5 / 12));
  CHECK(m.overall.meanRef == approx(11.8 / 12));
  REQUIRE(m.relativeMeanDifference().has_value());
  CHECK(*m.relativeMeanDifference() == approx((13.5 - 11.8) / 11.8));
  CHECK(m.nonFiniteTest == 0);
  CHECK(m.nonFiniteRef == 0);
}

TEST_CASE("metrics: relative MSE uses pbrt-v4's (ref + 0.01)^2 denominator") {
  // One pixel, one value: test 1 against reference 0 gives 1 / 0.01^2 =
  // 10000 in pbrt-v4's MRSE (not 1 / (0 + 0.01) = 100, the r^2 + 0.01 form).
  ImageRgb t(1, 1, Rgb(1, 0, 0)), r(1, 1, Rgb(0, 0, 0));
  ImageMetrics m = compareImages(t, r);
  CHECK(m.channel[0].relMse == approx(10000));
  CHECK(m.channel[1].relMse == 0);
  CHECK(m.overall.relMse == approx(10000.0 / 3));
  CHECK_FALSE(m.relativeMeanDifference().has_value());  // black reference
}

TEST_CASE("metrics: identical images give exactly zero error") {
  ImageRgb a = testImage();
  ImageMetrics m = compareImages(a, a);
  for (int c = 0; c < 3; ++c) {
    CHECK(m.channel[c].mse == 0);
    CHECK(m.channel[c].rmse == 0);
    CHECK(m.channel[c].relMse == 0);
    CHECK(m.channel[c].mae == 0);
    CHECK(m.channel[c].maxAbs == 0);
    CHECK(m.channel[c].meanTest == m.channel[c].meanRef);
  }
  CHECK(m.overall.rmse == 0);
  CHECK(m.overall.relMse == 0);
  CHECK(*m.relativeMeanDifference() == 0);
}

TEST_CASE("metrics: a crop measures only its rectangle") {
  // Column x = 1: pixels (1,0) and (1,1). Differences R 0, 1; G 0, 0; B 0, -2.
  ImageMetrics m = compareImages(testImage(), refImage(), PixelRect{1, 0, 1, 2});
  CHECK(m.pixelCount == 2);
  CHECK(m.channel[0].mse == approx(0.5));
  CHECK(m.channel[1].mse == 0);
  CHECK(m.channel[2].mse == approx(2));
  CHECK(m.channel[0].relMse == approx(1 / (1.01 * 1.01) / 2));
  CHECK(m.channel[2].relMse == approx(4 / (4.01 * 4.01) / 2));
  CHECK(m.channel[2].mae == approx(1));
  CHECK(m.overall.maxAbs == approx(2));
  CHECK(m.overall.rmse == approx(std::sqrt(5.0 / 6)));
  CHECK(m.channel[0].meanTest == approx(1.25));
  CHECK(m.channel[2].meanRef == approx(2.25));
  // A one-pixel crop of identical pixels: zero.
  ImageMetrics same = compareImages(testImage(), refImage(), PixelRect{1, 0, 1, 1});
  CHECK(same.overall.mse == 0);
}

TEST_CASE("metrics: cropInside") {
  CHECK(cropInside({0, 0, 2, 2}, 2, 2));
  CHECK(cropInside({1, 1, 1, 1}, 2, 2));
  CHECK_FALSE(cropInside({1, 1, 2, 1}, 2, 2));
  CHECK_FALSE(cropInside({0, 0, 0, 1}, 2, 2));
  CHECK_FALSE(cropInside({-1, 0, 1, 1}, 2, 2));
  CHECK_FALSE(cropInside({0, 2, 1, 1}, 2, 2));
  CHECK_FALSE(cropInside({2147483000, 0, 2147483000, 1}, 2, 2));  // no int overflow
}

TEST_CASE("metrics: non-finite values count as 0 and are reported") {
  ImageRgb t = testImage(), r = refImage();
  t.at(0, 0).r = std::numeric_limits<float>::quiet_NaN();
  r.at(1, 1).b = std::numeric_limits<float>::infinity();
  ImageMetrics m = compareImages(t, r);
  CHECK(m.nonFiniteTest == 1);
  CHECK(m.nonFiniteRef == 1);
  CHECK(std::isfinite(m.overall.rmse));
  CHECK(std::isfinite(m.overall.relMse));
  // R at (0,0) is now 0 against 1: squared errors 1, 0, 0.01, 1.
  CHECK(m.channel[0].mse == approx(2.01 / 4));
}

TEST_CASE("profile: CSV columns and values, SVG structure") {
  RowProfile p = extractRowProfile(testImage(), refImage(), 1, 0, 2);
  CHECK(p.y == 1);
  CHECK(p.test.size() == 2);
  std::string csv = profileCsv(p);
  std::istringstream in(csv);
  std::string header, line0, line1;
  std::getline(in, header);
  std::getline(in, line0);
  std::getline(in, line1);
  CHECK(header == "x,test_r,test_g,test_b,ref_r,ref_g,ref_b,test_lum,ref_lum");
  std::vector<double> v;
  std::istringstream l0(line0);
  for (std::string cell; std::getline(l0, cell, ',');) v.push_back(std::stod(cell));
  REQUIRE(v.size() == 9);
  CHECK(v[0] == 0);
  CHECK(v[1] == 0);
  CHECK(v[4] == approx(0.1));
  CHECK(v[6] == approx(0.2));
  CHECK(v[8] == approx(0.2126 * 0.1 + 0.0722 * 0.2));
  CHECK(line1.rfind("1,2,2,2,1,2,4,", 0) == 0);

  // Columns from x0: a crop's profile starts at its left edge.
  RowProfile q = extractRowProfile(testImage(), refImage(), 0, 1, 1);
  CHECK(profileCsv(q).find("\n1,0.5,") != std::string::npos);

  std::string svg = profileSvg(p, "a&b.exr", "<ref>.exr");
  CHECK(svg.rfind("<svg", 0) == 0);
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(countOf(svg, "<polyline") == 2);
  CHECK(contains(svg, "a&amp;b.exr"));
  CHECK(contains(svg, "&lt;ref&gt;.exr"));
  CHECK_FALSE(contains(svg, "<ref>"));
  CHECK(contains(svg, "Luminance along row 1"));
  // One-column profiles and all-black rows still make a drawable chart.
  std::string one = profileSvg(q, "t", "r");
  CHECK(countOf(one, "<polyline") == 2);
  CHECK_FALSE(hasNonFiniteNumber(one));
  RowProfile black = extractRowProfile(ImageRgb(4, 1), ImageRgb(4, 1), 0, 0, 4);
  CHECK_FALSE(hasNonFiniteNumber(profileSvg(black, "t", "r")));
  CHECK_FALSE(hasNonFiniteNumber(svg));
}

TEST_CASE("cli compare: text output") {
  CompareDir d;
  auto r = runTdpm(d.pair());
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  for (const char* word : {"RMSE", "relMSE", "MAE", "max |error|", "mean test", "mean ref", "overall", "2x2"})
    CHECK_MESSAGE(contains(r.output, word), word);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", std::sqrt(kMseB));  // B RMSE
  CHECK(contains(r.output, buf));
  std::snprintf(buf, sizeof buf, "%.6g", (kRelR + kRelG + kRelB) / 3);
  CHECK(contains(r.output, buf));
  CHECK(contains(r.output, "test brighter than reference"));
  auto help = runTdpm("compare --help");
  CHECK(help.exitCode == 0);
  for (const char* flag : {"--json", "--crop", "--profile-row", "--csv", "--plot"}) CHECK(contains(help.output, flag));
  CHECK(contains(runTdpm("--help").output, "compare"));
}

TEST_CASE("cli compare: --json parses and carries the numbers") {
  CompareDir d;
  auto r = runTdpm(d.pair() + " --json");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  nlohmann::json j = nlohmann::json::parse(r.output);
  CHECK(j["width"] == 2);
  CHECK(j["height"] == 2);
  CHECK(j["pixels"] == 4);
  CHECK(j["region"]["cropped"] == false);
  CHECK(j["rmse"]["r"].get<double>() == approx(std::sqrt(kMseR)));
  CHECK(j["rmse"]["b"].get<double>() == approx(std::sqrt(kMseB)));
  CHECK(j["rmse"]["overall"].get<double>() == approx(std::sqrt((kMseR + kMseG + kMseB) / 3)));
  CHECK(j["rel_mse"]["g"].get<double>() == approx(kRelG));
  CHECK(j["rel_mse"]["overall"].get<double>() == approx((kRelR + kRelG + kRelB) / 3));
  CHECK(j["mae"]["b"].get<double>() == approx(kMaeB));
  CHECK(j["max_abs_error"]["overall"].get<double>() == approx(2));
  CHECK(j["mean_test"]["overall"].get<double>() == approx(13.5 / 12));
  CHECK(j["mean_reference"]["r"].get<double>() == approx(0.65));
  CHECK(j["relative_mean_difference"].get<double>() == approx((13.5 - 11.8) / 11.8));
  CHECK(j["nonfinite_values"]["test"] == 0);
  CHECK_FALSE(j.contains("profile"));

  // With a crop: the same numbers as the library's crop test.
  auto c = runTdpm(d.pair() + " --json --crop 1,0,1,2");
  INFO(c.output);
  REQUIRE(c.exitCode == 0);
  nlohmann::json jc = nlohmann::json::parse(c.output);
  CHECK(jc["pixels"] == 2);
  CHECK(jc["region"]["x"] == 1);
  CHECK(jc["region"]["cropped"] == true);
  CHECK(jc["mse"]["r"].get<double>() == approx(0.5));
  CHECK(jc["rmse"]["overall"].get<double>() == approx(std::sqrt(5.0 / 6)));
}

TEST_CASE("cli compare: --profile-row writes CSV and SVG") {
  CompareDir d;
  auto r = runTdpm(d.pair() + " --profile-row 1 --csv " + (d / "row.csv") + " --plot " + (d / "row.svg") + " --json");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  nlohmann::json j = nlohmann::json::parse(r.output);
  CHECK(j["profile"]["row"] == 1);
  CHECK(j["profile"]["width"] == 2);
  CHECK(j["profile"]["ref_peak"]["x"] == 1);
  std::string csv = readText(d.path("row.csv"));
  CHECK(csv.rfind("x,test_r,test_g,test_b,ref_r,ref_g,ref_b,test_lum,ref_lum\n", 0) == 0);
  CHECK(countOf(csv, "\n") == 3);
  CHECK(contains(csv, "\n1,2,2,2,1,2,4,"));
  std::string svg = readText(d.path("row.svg"));
  CHECK(svg.rfind("<svg", 0) == 0);
  CHECK(countOf(svg, "<polyline") == 2);
  CHECK(contains(svg, "test.exr"));
  CHECK(contains(svg, "ref.exr"));
  CHECK(test::countEntries(d.dir) == 5);  // no temporary files left

  // Text mode names the outputs; only --plot is fine too.
  auto t = runTdpm(d.pair() + " --profile-row 0 --plot " + (d / "only.svg"));
  CHECK(t.exitCode == 0);
  CHECK(contains(t.output, "only.svg"));
  CHECK(test::fileExists(d.path("only.svg")));
}

TEST_CASE("cli compare: errors name the problem, exit 1 or 2, leave no files") {
  CompareDir d;
  test::writeFile(d.path("text.exr"), "this is not an EXR file\n");
  const std::string outs = " --csv " + (d / "out.csv") + " --plot " + (d / "out.svg");
  struct Case {
    std::string args;
    int code;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {"compare " + (d / "missing.exr") + " " + (d / "ref.exr") + " --profile-row 0" + outs, 1, {"missing.exr", "test image"}},
      {"compare " + (d / "test.exr") + " " + (d / "text.exr") + " --profile-row 0" + outs, 1, {"text.exr", "reference image"}},
      {"compare " + (d / "test.exr") + " " + (d / "other.exr") + " --profile-row 0" + outs, 1, {"2x2", "3x2", "other.exr"}},
      {d.pair() + " --crop 1,1,2,1 --profile-row 1" + outs, 1, {"--crop", "not inside", "2x2"}},
      {d.pair() + " --crop 1,1,2" + " --profile-row 1" + outs, 2, {"--crop", "x,y,w,h"}},
      {d.pair() + " --crop 0,0,0,1" + " --profile-row 0" + outs, 2, {"--crop", "w and h"}},
      {d.pair() + " --crop a,b,c,d" + " --profile-row 0" + outs, 2, {"--crop"}},
      {d.pair() + " --profile-row 2" + outs, 1, {"--profile-row", "rows 0..1"}},
      {d.pair() + " --profile-row -1" + outs, 2, {"--profile-row"}},
      {d.pair() + " --crop 0,0,1,1 --profile-row 1" + outs, 1, {"--profile-row", "--crop"}},
      {d.pair() + " --csv " + (d / "out.csv"), 2, {"--csv", "--profile-row"}},
      {d.pair() + " --plot " + (d / "out.svg"), 2, {"--plot", "--profile-row"}},
      {d.pair() + " --profile-row 0 --plot " + (d / "out.png"), 1, {"--plot", ".svg"}},
      {d.pair() + " --profile-row 0 --csv " + (d / "nodir/out.csv"), 1, {"--csv", "nodir"}},
      {d.pair() + " --profile-row 0 --csv " + (d / "ref.exr"), 1, {"--csv", "input"}},
      {"compare " + (d / "test.exr"), 2, {"reference"}},
  };
  for (const Case& c : cases) {
    auto r = runTdpm(c.args);
    INFO(c.args);
    INFO(r.output);
    CHECK(r.exitCode == c.code);
    for (const std::string& w : c.words) CHECK_MESSAGE(contains(r.output, w), w);
    CHECK(test::countEntries(d.dir) == 4);  // test, ref, other, text: nothing new
  }

  // The plot cannot be written (its name is a directory) after the CSV was:
  // the CSV is removed again, both outputs or neither.
  REQUIRE(::mkdir(d.path("taken.svg").c_str(), 0755) == 0);
  auto r = runTdpm(d.pair() + " --profile-row 0 --csv " + (d / "out.csv") + " --plot " + (d / "taken.svg"));
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(contains(r.output, "taken.svg"));
  CHECK_FALSE(test::fileExists(d.path("out.csv")));
  CHECK(test::countEntries(d.dir) == 5);
}
