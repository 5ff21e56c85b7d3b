// tests/test_salt.cpp — image::countSalt and `tdpm compare --salt` (issue
// 24) on synthetic images: isolated bright pixels are salt; a bright
// feature the reference has too is not, nor a wide error (bright in the
// test's own median), nor a pixel 2.9x its neighbours; count and share in
// the text and JSON output, with and without --crop.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_harness.h"
#include "image/exr.h"
#include "image/metrics.h"

using namespace tdpm;
using namespace tdpm::image;

namespace {

// 40x30, value 1 everywhere, and a bright region x >= 28 of 10 in both (a
// real feature). The test adds 4 isolated salt pixels of 10 (one in a
// corner, one beside the feature's edge), a pixel of 2.9 (below 3x), a pixel
// of 25 inside the feature (2.5x its bright neighbours), and a test-only
// band of 8 over columns 14-18, every row (a wide error: each of its pixels'
// 5x5 windows is at least 3/5 band, so the test's own median is 8). A small
// blob would not do: a corner's window holds 9 of 25 bright pixels, below
// the median, so a bright rectangle's corners are salt by this definition.
struct Pair {
  ImageRgb test{40, 30, Rgb(1.0f)}, ref{40, 30, Rgb(1.0f)};
  Pair() {
    for (int y = 0; y < 30; ++y)
      for (int x = 28; x < 40; ++x) test.at(x, y) = ref.at(x, y) = Rgb(10.0f);
    test.at(0, 0) = Rgb(10.0f);
    test.at(27, 15) = Rgb(10.0f);
    test.at(10, 20) = Rgb(10.0f);
    test.at(5, 5) = Rgb(10.0f);
    test.at(12, 12) = Rgb(2.9f);
    test.at(33, 8) = Rgb(25.0f);
    for (int y = 0; y < 30; ++y)
      for (int x = 14; x <= 18; ++x) test.at(x, y) = Rgb(8.0f);
  }
};

}  // namespace

TEST_CASE("salt: isolated bright pixels count, features and wide errors do not") {
  Pair p;
  SaltMetrics s = countSalt(p.test, p.ref, {0, 0, 40, 30});
  CHECK(s.count == 4);
  CHECK(s.share == doctest::Approx(4.0 / 1200.0));
  // A region: only the pixels inside count, their windows reach outside.
  SaltMetrics c = countSalt(p.test, p.ref, {0, 0, 20, 30});
  CHECK(c.count == 3);
  CHECK(c.share == doctest::Approx(3.0 / 600.0));
  // The reference against itself: its feature is no salt.
  CHECK(countSalt(p.ref, p.ref, {0, 0, 40, 30}).count == 0);
  // Factor: 2.8 makes the 2.9 pixel salt too.
  CHECK(countSalt(p.test, p.ref, {0, 0, 40, 30}, 2.8).count == 5);
  // A black reference and black neighbourhood: any light is salt; a black
  // test pixel never is.
  ImageRgb black(5, 5), one(5, 5);
  one.at(2, 2) = Rgb(1e-3f);
  CHECK(countSalt(one, black, {0, 0, 5, 5}).count == 1);
  CHECK(countSalt(black, black, {0, 0, 5, 5}).count == 0);
}

TEST_CASE("salt: tdpm compare --salt prints the count and share, in --json as salt") {
  Pair p;
  std::string dir = test::makeTempDir();
  ExrFile t, r;
  t.color = p.test;
  r.color = p.ref;
  writeExr(dir + "/t.exr", t);
  writeExr(dir + "/r.exr", r);
  auto text = test::runTdpm("compare " + dir + "/t.exr " + dir + "/r.exr --salt");
  CHECK(text.exitCode == 0);
  CHECK(text.output.find("salt: 4 pixels (0.3333%)") != std::string::npos);
  auto js = test::runTdpm("compare " + dir + "/t.exr " + dir + "/r.exr --salt --json");
  REQUIRE(js.exitCode == 0);
  auto j = nlohmann::json::parse(js.output);
  CHECK(j["salt"]["count"] == 4);
  CHECK(j["salt"]["share"].get<double>() == doctest::Approx(4.0 / 1200.0));
  auto crop = test::runTdpm("compare " + dir + "/t.exr " + dir + "/r.exr --salt --json --crop 0,0,20,30");
  REQUIRE(crop.exitCode == 0);
  CHECK(nlohmann::json::parse(crop.output)["salt"]["count"] == 3);
  // Without --salt, no salt field (the JSON others read is unchanged).
  auto plain = test::runTdpm("compare " + dir + "/t.exr " + dir + "/r.exr --json");
  CHECK(!nlohmann::json::parse(plain.output).contains("salt"));
  (void)std::system(("rm -rf '" + dir + "'").c_str());
}
