// tests/test_spectrum.cpp — spectra reduced to linear sRGB at load
// (import/spectrum.h, import/pbrt_spectrum.cpp): the CIE integration against
// published chromaticities (Planckian locus at 2856 K = illuminant A and at
// 6504 K, D65, equal-energy white), BK7's catalogue index, and the pbrt
// import: constant .spd files equal their value (pbrt-v4 grey under D65,
// pbrt-v3 equal-energy luminance), blackbody lights, located errors for
// unsorted wavelengths and for named spectra tdpm has no data for.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_harness.h"
#include "core/error.h"
#include "import/pbrt_import.h"
#include "import/spectrum.h"

using namespace tdpm;

namespace {

spectrum::Xyz xy(const spectrum::Xyz& c) { return spectrum::chromaticity(c); }

std::string importError(const std::string& file) {
  try {
    pbrt::importPbrtFile(file);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

std::string write(const std::string& dir, const std::string& name, const std::string& text) {
  std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("spectrum: Planckian chromaticities from the CIE 1931 integration") {
  // Illuminant A is a black body at 2856 K: x = 0.44758, y = 0.40745 (CIE 015).
  spectrum::Xyz a = xy(spectrum::xyzEqualEnergy(spectrum::blackbody(2856)));
  CHECK(a.x == doctest::Approx(0.44758).epsilon(0.0005));
  CHECK(a.y == doctest::Approx(0.40745).epsilon(0.0005));
  // 6504 K on the Planckian locus: x = 0.3135, y = 0.3236.
  spectrum::Xyz d = xy(spectrum::xyzEqualEnergy(spectrum::blackbody(6504)));
  CHECK(d.x == doctest::Approx(0.3135).epsilon(0.001));
  CHECK(d.y == doctest::Approx(0.3236).epsilon(0.001));
  // The D65 table: x = 0.31272, y = 0.32903 (CIE 015 with the 2° observer).
  spectrum::Xyz w = xy(spectrum::xyzOfD65());
  CHECK(w.x == doctest::Approx(0.31272).epsilon(0.0003));
  CHECK(w.y == doctest::Approx(0.32903).epsilon(0.0003));
  // Equal energy is the centre of the diagram.
  spectrum::Piecewise flat{{300, 900}, {1, 1}, false};
  spectrum::Xyz e = spectrum::xyzEqualEnergy(flat);
  CHECK(e.y == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(xy(e).x == doctest::Approx(1.0 / 3).epsilon(0.0005));
  CHECK(xy(e).y == doctest::Approx(1.0 / 3).epsilon(0.0005));
  // Wien: the normalised black body peaks at 1.
  CHECK(spectrum::planck(spectrum::planckPeakNm(5000), 5000) >= spectrum::planck(spectrum::planckPeakNm(5000) + 1, 5000));
}

TEST_CASE("spectrum: sRGB of D65 is grey; a 6500 K black body of luminance 1 is near white") {
  Rgb w = spectrum::xyzToLinearSrgb(spectrum::xyzOfD65());
  CHECK(w.r == doctest::Approx(1.0).epsilon(1e-5));
  CHECK(w.g == doctest::Approx(1.0).epsilon(1e-5));
  CHECK(w.b == doctest::Approx(1.0).epsilon(1e-5));
  spectrum::Xyz c = spectrum::xyzEqualEnergy(spectrum::blackbody(6500));
  Rgb b = spectrum::xyzToLinearSrgb({c.x / c.y, 1.0, c.z / c.y});
  CHECK(b.luminance() == doctest::Approx(1.0).epsilon(1e-4));
  // Slightly off D65 toward magenta-blue (the locus passes below D65): within 5%.
  CHECK(b.r == doctest::Approx(1.0).epsilon(0.05));
  CHECK(b.g == doctest::Approx(1.0).epsilon(0.05));
  CHECK(b.b == doctest::Approx(1.0).epsilon(0.05));
  // 2856 K is orange: r > g > b.
  spectrum::Xyz a = spectrum::xyzEqualEnergy(spectrum::blackbody(2856));
  Rgb o = spectrum::xyzToLinearSrgb(a);
  CHECK(o.r > o.g);
  CHECK(o.g > o.b);
}

TEST_CASE("spectrum: pbrt .spd files, inline spectra and blackbody values become RGB") {
  std::string dir = test::makeTempDir();
  write(dir, "flat.spd", "# a flat reflectance\n300 0.4\n500 0.4 # middle\n900 0.4\n");
  write(dir, "unsorted.spd", "400 0.5\n500 0.5\n450 0.5\n");
  write(dir, "odd.spd", "400 0.5 500\n");

  // pbrt-v4 (no Film "image"): a reflectance is seen under D65, so a constant one is grey.
  std::string v4 = write(dir, "v4.pbrt",
                         "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"flat.spd\"\n"
                         "Shape \"sphere\"\nMaterial \"diffuse\" \"spectrum reflectance\" [300 0.25 900 0.25]\n"
                         "Shape \"sphere\"\n");
  auto r4 = pbrt::importPbrtFile(v4).scene;
  REQUIRE(r4.materials.size() == 2);
  for (int i = 0; i < 2; ++i) {
    Rgb c = r4.materials[size_t(i)].albedo.color;
    float want = i == 0 ? 0.4f : 0.25f;
    CHECK(c.r == doctest::Approx(want).epsilon(1e-4));
    CHECK(c.g == doctest::Approx(want).epsilon(1e-4));
    CHECK(c.b == doctest::Approx(want).epsilon(1e-4));
  }
  // pbrt-v3 (Film "image"): XYZ against equal-energy white; luminance Y equals the value.
  std::string v3 = write(dir, "v3.pbrt",
                         "Film \"image\"\nWorldBegin\nMaterial \"matte\" \"spectrum Kd\" \"flat.spd\"\nShape \"sphere\"\n");
  Rgb c3 = pbrt::importPbrtFile(v3).scene.materials[0].albedo.color;
  CHECK(c3.luminance() == doctest::Approx(0.4).epsilon(2e-3));
  CHECK(c3.r > c3.g);  // equal-energy white is pinkish in sRGB
  CHECK(c3.g > c3.b);

  // Blackbody lights: pbrt-v4 [T] normalised to luminance 1; pbrt-v3 [T scale] peak 1 times scale.
  std::string bb4 = write(dir, "bb4.pbrt", "WorldBegin\nLightSource \"point\" \"blackbody I\" [2856]\n");
  std::string bb3 = write(dir, "bb3.pbrt", "Film \"image\"\nWorldBegin\nLightSource \"point\" \"blackbody I\" [2856 2]\n");
  Rgb p4 = pbrt::importPbrtFile(bb4).scene.lights.at(0).power;
  Rgb p3 = pbrt::importPbrtFile(bb3).scene.lights.at(0).power;
  Rgb a = spectrum::xyzToLinearSrgb(spectrum::xyzEqualEnergy(spectrum::blackbody(2856)));
  CHECK(p4.r / p4.g == doctest::Approx(a.r / a.g).epsilon(1e-4));
  CHECK(p4.b / p4.g == doctest::Approx(a.b / a.g).epsilon(1e-4));
  CHECK(p3.r / p3.g == doctest::Approx(a.r / a.g).epsilon(1e-4));
  // Same light, same shape: the v3 one is 2 x (Y of the peak-normalised A) / 1 as bright.
  double yA = spectrum::xyzEqualEnergy(spectrum::blackbody(2856)).y;
  CHECK(p3.luminance() / p4.luminance() == doctest::Approx(2 * yA).epsilon(1e-3));

  // Errors: located, naming the file, the line in it and the problem.
  std::string bad = write(dir, "bad.pbrt", "WorldBegin\n\nMaterial \"diffuse\" \"spectrum reflectance\" \"unsorted.spd\"\n");
  std::string e = importError(bad);
  CHECK(e.find(bad + ":3: ") == 0);
  CHECK(e.find("unsorted.spd:3: wavelengths must increase: 450 nm follows 500 nm") != std::string::npos);
  std::string odd = write(dir, "odd.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"odd.spd\"\n");
  CHECK(importError(odd).find("odd.spd: an odd count of numbers (3)") != std::string::npos);
  std::string inl = write(dir, "inline.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" [500 .5 400 .5]\n");
  CHECK(importError(inl).find(inl + ":2: ") == 0);
  CHECK(importError(inl).find("wavelengths must increase: 400 nm follows 500 nm (pair 2)") != std::string::npos);
  std::string metal = write(dir, "metal.pbrt", "WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-CuZn-eta\" \"spectrum k\" \"metal-CuZn-k\"\n");
  CHECK(importError(metal).find(metal + ":2: ") == 0);
  CHECK(importError(metal).find("named spectrum \"metal-CuZn-eta\" is not available") != std::string::npos);
  std::string missing = write(dir, "missing.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"nope.spd\"\n");
  CHECK(importError(missing).find("nope.spd") != std::string::npos);
  std::filesystem::remove_all(dir);
}

namespace {
// Copper's optical constants on pbrt's grid, 354-886 nm (the data behind
// pbrt-v3's copper default and pbrt-v4's metal-Cu): eta, then k.
const double kCuNm[] = {354.240509, 359.374420, 364.659332, 370.102020, 375.709625, 381.489777, 387.450562, 393.600555,
                        399.948975, 406.505493, 413.280579, 420.285339, 427.531647, 435.032196, 442.800629, 450.851562,
                        459.200653, 467.864838, 476.862213, 486.212463, 495.936707, 506.057861, 516.600769, 527.592224,
                        539.061646, 551.040771, 563.564453, 576.670593, 590.400818, 604.800842, 619.920898, 635.816284,
                        652.548279, 670.184753, 688.800964, 708.481018, 729.318665, 751.419250, 774.901123, 799.897949,
                        826.561157, 855.063293, 885.601257};
const double kCuEta[] = {1.290000, 1.281563, 1.270000, 1.249062, 1.225000, 1.200000, 1.180000, 1.174375, 1.175000,
                         1.177500, 1.180000, 1.178125, 1.175000, 1.172812, 1.170000, 1.165312, 1.160000, 1.155312,
                         1.150000, 1.142812, 1.135000, 1.131562, 1.120000, 1.092437, 1.040000, 0.950375, 0.826000,
                         0.645875, 0.468000, 0.351250, 0.272000, 0.230813, 0.214000, 0.209250, 0.213000, 0.216250,
                         0.223000, 0.236500, 0.250000, 0.254188, 0.260000, 0.280000, 0.300000};
const double kCuK[] = {1.916000, 1.931688, 1.950000, 1.972438, 2.015000, 2.121562, 2.210000, 2.177188, 2.130000,
                       2.160063, 2.210000, 2.249938, 2.289000, 2.326000, 2.362000, 2.397625, 2.433000, 2.469187,
                       2.504000, 2.535875, 2.564000, 2.589625, 2.605000, 2.595562, 2.583000, 2.576500, 2.599000,
                       2.678062, 2.809000, 3.010750, 3.240000, 3.458187, 3.670000, 3.863125, 4.050000, 4.239563,
                       4.430000, 4.619563, 4.817000, 5.034125, 5.260000, 5.485625, 5.717000};
std::string spd(const double* v) {
  std::string s;
  for (size_t i = 0; i < sizeof(kCuNm) / sizeof(kCuNm[0]); ++i) s += std::to_string(kCuNm[i]) + " " + std::to_string(v[i]) + "\n";
  return s;
}
float r0(float eta, float k) { return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k); }
// A conductor's normal-incidence reflectance from its imported eta and k.
Rgb reflectanceOf(const scene::MaterialDesc& m) {
  return {r0(m.eta.r, m.k.r), r0(m.eta.g, m.k.g), r0(m.eta.b, m.k.b)};
}
}  // namespace

TEST_CASE("spectrum: copper from its optical constants, as pbrt-v3 and pbrt-v4 colour it") {
  std::string dir = test::makeTempDir();
  write(dir, "Cu.eta.spd", spd(kCuEta));
  write(dir, "Cu.k.spd", spd(kCuK));
  // pbrt-v3: equal-energy XYZ. The RGB copper of pbrt-v3-era scenes (and of
  // Mitsuba 0.5's presets) is eta (0.200438, 0.924033, 1.10221), k (3.91295,
  // 2.45285, 2.14219); tdpm's integration lands within 1e-3 of it, and the
  // default metal (no eta, no k) is the same copper.
  std::string v3 = write(dir, "cu3.pbrt", "Film \"image\"\nWorldBegin\nMaterial \"metal\" \"spectrum eta\" \"Cu.eta.spd\" "
                                          "\"spectrum k\" \"Cu.k.spd\" \"float roughness\" 0\nShape \"sphere\"\n"
                                          "Material \"metal\" \"float roughness\" 0\nShape \"sphere\"\n");
  auto d3 = pbrt::importPbrtFile(v3).scene;
  const float eta3[3] = {0.200438f, 0.924033f, 1.10221f}, k3[3] = {3.91295f, 2.45285f, 2.14219f};
  for (int i = 0; i < 3; ++i) {
    CAPTURE(i);
    float want = r0(eta3[i], k3[i]);
    CHECK(reflectanceOf(d3.materials.at(0))[i] == doctest::Approx(want).epsilon(1e-3));
    CHECK(d3.materials.at(0).eta[i] == doctest::Approx(eta3[i]).epsilon(1e-3));
    CHECK(reflectanceOf(d3.materials.at(1))[i] == doctest::Approx(want).epsilon(1e-3));
  }
  // pbrt-v4: the same data under D65 equals the named metal-Cu triples and the default conductor.
  std::string v4 = write(dir, "cu4.pbrt", "WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"Cu.eta.spd\" "
                                          "\"spectrum k\" \"Cu.k.spd\"\nShape \"sphere\"\n"
                                          "Material \"conductor\" \"spectrum eta\" \"metal-Cu-eta\" \"spectrum k\" \"metal-Cu-k\"\n"
                                          "Shape \"sphere\"\nMaterial \"conductor\"\nShape \"sphere\"\n");
  auto d4 = pbrt::importPbrtFile(v4).scene;
  REQUIRE(d4.materials.size() == 3);
  for (int i = 0; i < 3; ++i) {
    CAPTURE(i);
    CHECK(reflectanceOf(d4.materials[1])[i] == doctest::Approx(reflectanceOf(d4.materials[0])[i]).epsilon(1e-4));
    CHECK(reflectanceOf(d4.materials[2])[i] == doctest::Approx(reflectanceOf(d4.materials[0])[i]).epsilon(1e-4));
  }
  // Copper-coloured: red reflects most.
  CHECK(reflectanceOf(d4.materials[0]).r > reflectanceOf(d4.materials[0]).g + 0.2f);
  // Gold: named, r > g > b.
  std::string au = write(dir, "au.pbrt", "WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-Au-eta\" "
                                         "\"spectrum k\" \"metal-Au-k\"\nShape \"sphere\"\n");
  Rgb g = reflectanceOf(pbrt::importPbrtFile(au).scene.materials.at(0));
  CHECK(g.r > g.g);
  CHECK(g.g > g.b + 0.3f);
  std::filesystem::remove_all(dir);
}

TEST_CASE("spectrum: glass-BK7 is Schott N-BK7 (n_d = 1.5168) and becomes one ior") {
  std::string dir = test::makeTempDir();
  std::string f = write(dir, "g.pbrt", "WorldBegin\nMaterial \"dielectric\" \"spectrum eta\" \"glass-BK7\"\nShape \"sphere\"\n");
  auto d = pbrt::importPbrtFile(f).scene;
  // y-bar weighted mean over 360-830 nm: between n(486 nm) = 1.5224 and n(656 nm) = 1.5143.
  CHECK(d.materials.at(0).ior > 1.5143f);
  CHECK(d.materials.at(0).ior < 1.5224f);
  std::string b = write(dir, "b.pbrt", "WorldBegin\nMaterial \"dielectric\" \"spectrum eta\" \"glass-BAF10\"\nShape \"sphere\"\n");
  CHECK(pbrt::importPbrtFile(b).scene.materials.at(0).ior == doctest::Approx(1.67259f));
  std::filesystem::remove_all(dir);
}
