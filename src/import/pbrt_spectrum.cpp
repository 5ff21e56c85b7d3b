// import/pbrt_spectrum.cpp — pbrt's spectral parameter values as tdpm's
// RGB: "spectrum" (inline wavelength/value pairs, a pbrt-v4 constant, an
// .spd file, a named spectrum) and "blackbody". Each is reduced once, at
// load, with import/spectrum.h, the way the pbrt version that wrote the file
// turns it into a colour (docs/pbrt-import.md, "Spectra"):
//   pbrt-v3 (RGB build): XYZ against equal-energy white (FromSampled), the
//     end values held outside the data; "blackbody" [T scale] pairs.
//   pbrt-v4: a light's spectrum ("L", "I") is normalised to luminance 1
//     (lights divide by SpectrumToPhotometric), any other one is seen lit by
//     D65 (the sRGB colour space's illuminant, which its RGB lights emit);
//     zero outside the data; "blackbody" T.
// The version: a blackbody with two values is pbrt-v3's; otherwise the film
// decides (Film "image" is pbrt-v3's), and without a film pbrt-v4.
#include <cctype>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/regular_file.h"
#include "import/pbrt_importer.h"
#include "import/spectrum.h"
#include "scene/limits.h"

namespace tdpm::pbrt::detail {

namespace {

// A .spd file: a regular file (a FIFO or a device is refused before it can
// block or never end), at most as large as one pbrt file may be.
std::string readWholeFile(const std::string& path, const std::string& where) {
  uint64_t size = 0;
  std::FILE* f = nullptr;
  try {
    f = openRegularInput(path, "a spectrum (.spd) file", &size);
  } catch (const Error& e) {
    throw Error(where + e.what());
  }
  if (size > scene::limits::kMaxPbrtFileBytes) {
    std::fclose(f);
    throw Error(where + path + ": spectrum file is too large (" + std::to_string(size) + " bytes; at most " +
                std::to_string(scene::limits::kMaxPbrtFileBytes >> 20) + " MiB)");
  }
  std::string text(size_t(size), '\0');
  size_t got = size ? std::fread(&text[0], 1, text.size(), f) : 0;
  bool bad = std::ferror(f) != 0;
  std::fclose(f);
  if (bad || got != text.size()) throw Error(where + path + ": error while reading spectrum file");
  return text;
}

bool isLightSpectrum(const Param& p) { return p.name == "L" || p.name == "I"; }

// Schott N-BK7's Sellmeier formula (Schott data sheet coefficients;
// wavelength in micrometres). Gives n_d = 1.5168 at 587.56 nm, the catalogue
// value (tests/test_spectrum.cpp).
double bk7(double nm) {
  double l2 = (nm * 1e-3) * (nm * 1e-3);
  double n2 = 1 + 1.03961212 * l2 / (l2 - 0.00600069867) + 0.231792344 * l2 / (l2 - 0.0200179144) +
              1.01046945 * l2 / (l2 - 103.560653);
  return std::sqrt(n2);
}

// pbrt-v4's named metal spectra, reduced once to RGB (linear sRGB, seen
// under D65 as pbrt-v4 sees non-light spectra) with import/spectrum.h's
// matching functions. The data are pbrt-v4's tables (src/pbrt/util/
// spectrum.cpp: Ag, Al, Au, Cu on one 298.8-885.6 nm grid, the measured
// optical constants pbrt-v3 also ships; MgO, TiO2), read, integrated over
// 360-830 nm at 1 nm and kept here as the triples only. Reducing the same Cu
// and Au data against equal-energy white instead gives (0.2010, 0.9238,
// 1.1023)/(3.913, 2.453, 2.142) and (0.1430, 0.3753, 1.4422)/(3.983, 2.386,
// 1.603), the RGB values pbrt-v3-era scenes use for copper and gold to 5e-4.
struct NamedRgb {
  const char* name;
  Rgb rgb;
};
const NamedRgb kNamedMetals[] = {
    {"metal-Ag-eta", {0.128478f, 0.123535f, 0.150894f}},   {"metal-Ag-k", {4.064805f, 3.286218f, 2.391785f}},
    {"metal-Al-eta", {1.407383f, 0.926656f, 0.584076f}},   {"metal-Al-k", {7.740226f, 6.602473f, 5.360401f}},
    {"metal-Au-eta", {0.079954f, 0.405088f, 1.560861f}},   {"metal-Au-k", {3.390203f, 2.503536f, 1.771026f}},
    {"metal-Cu-eta", {0.105133f, 0.977933f, 1.204671f}},   {"metal-Cu-k", {3.273486f, 2.592516f, 2.369186f}},
    {"metal-MgO-eta", {1.733677f, 1.740950f, 1.753548f}},  {"metal-MgO-k", {0.0f, 0.0f, 0.0f}},
    {"metal-TiO2-eta", {2.860379f, 2.956533f, 3.185532f}}, {"metal-TiO2-k", {0.000091f, 0.0f, 0.000566f}},
};

bool looksNamed(const std::string& s) {
  for (const char* prefix : {"metal-", "glass-", "stdillum-", "illum-", "canon_", "nikon_", "sony_", "ciexyz"})
    if (s.rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace

// A spectrum parameter as wavelength/value pairs (or a pbrt-v4 constant:
// then `constant` is set and the pairs are empty).
static spectrum::Piecewise readPairs(const ParamSet& ps, const Param& p, bool v3, const std::string& mainDir,
                                     bool* constant, double* constantValue) {
  spectrum::Piecewise s;
  s.clampOutside = v3;
  std::vector<double> nums;
  std::string where;  // "file.spd:LINE: " for values from a file
  std::vector<int> lines;
  if (!p.strings.empty()) {
    if (p.strings.size() != 1) ps.fail(p, "expected one spectrum name or .spd file");
    const std::string& name = p.strings[0];
    if (name == "stdillum-D65") {
      for (int i = 0; i < spectrum::detail::kCieRows; ++i) {
        s.lambda.push_back(360 + 5 * i);
        s.value.push_back(spectrum::detail::kCie[i].d65);
      }
      return s;
    }
    if (name == "glass-BK7") {
      for (int nm = 360; nm <= 830; nm += 5) {
        s.lambda.push_back(nm);
        s.value.push_back(bk7(nm));
      }
      return s;
    }
    if (looksNamed(name))
      ps.fail(p, "named spectrum \"" + name + "\" is not available in tdpm (it has stdillum-D65, glass-BK7, glass-BAF10 " +
                     "and metal-{Ag,Al,Au,Cu,MgO,TiO2}-{eta,k}; no trustworthy table for the others): give an rgb value instead");
    std::string path = resolvePath(name, ps.file(), mainDir);
    std::string text = readWholeFile(path, ps.file() + ":" + std::to_string(p.line) + ": " + ps.statement() +
                                               ": parameter \"" + p.type + " " + p.name + "\": ");
    int line = 1;
    for (size_t i = 0; i < text.size();) {
      char c = text[i];
      if (c == '\n') { ++line; ++i; continue; }
      if (c == '#') { while (i < text.size() && text[i] != '\n') ++i; continue; }
      if (std::isspace(static_cast<unsigned char>(c)) || c == ',') { ++i; continue; }
      size_t end = i;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])) && text[end] != '#' &&
             text[end] != ',')
        ++end;
      std::string tok = text.substr(i, end - i);
      char* stop = nullptr;
      double v = std::strtod(tok.c_str(), &stop);
      if (stop != tok.c_str() + tok.size() || !std::isfinite(v))
        ps.fail(p, path + ":" + std::to_string(line) + ": expected a number, got \"" + tok + "\"");
      nums.push_back(v);
      lines.push_back(line);
      i = end;
    }
    where = path;
    if (nums.empty()) ps.fail(p, path + ": no wavelength/value pairs");
    if (nums.size() % 2) ps.fail(p, path + ": an odd count of numbers (" + std::to_string(nums.size()) + "): expected wavelength/value pairs");
  } else {
    nums = p.numbers;
    if (nums.size() == 1 && !v3) {
      *constant = true;
      *constantValue = nums[0];
      return s;
    }
    if (nums.empty() || nums.size() % 2)
      ps.fail(p, "expected wavelength/value pairs, got " + std::to_string(nums.size()) + " numbers");
  }
  for (size_t i = 0; i + 1 < nums.size(); i += 2) {
    double l = nums[i];
    std::string at = where.empty() ? "" : where + ":" + std::to_string(lines[i]) + ": ";
    if (!(l > 0)) ps.fail(p, at + "wavelength " + fmtNum(l) + " nm is not positive");
    if (!s.lambda.empty() && !(l > s.lambda.back()))
      ps.fail(p, at + "wavelengths must increase: " + fmtNum(l) + " nm follows " + fmtNum(s.lambda.back()) + " nm (pair " +
                     std::to_string(i / 2 + 1) + ")");
    s.lambda.push_back(l);
    s.value.push_back(nums[i + 1]);
  }
  return s;
}

Rgb Importer::spectrumColor(const ParamSet& ps, const Param& p) const {
  p.used = true;
  if (p.strings.size() == 1)
    for (const NamedRgb& n : kNamedMetals)
      if (p.strings[0] == n.name) return n.rgb;
  bool filmV3 = film_.given && film_.type == "image";
  bool v3 = filmV3;
  spectrum::Piecewise s;
  double scale = 1;
  if (p.type == "blackbody") {
    if (p.numbers.size() == 2) v3 = true;
    else if (p.numbers.size() == 1) v3 = false;
    else ps.fail(p, "expected a temperature (pbrt-v4) or one [temperature scale] pair (pbrt-v3), got " +
                        std::to_string(p.numbers.size()) + " numbers");
    double kelvin = p.numbers[0];
    if (!(kelvin > 0 && kelvin <= 1e6)) ps.fail(p, "temperature must be in (0, 1e6] kelvin, got " + fmtNum(kelvin));
    if (v3) scale = p.numbers[1];
    s = spectrum::blackbody(kelvin);
  } else {
    bool constant = false;
    double value = 0;
    s = readPairs(ps, p, v3, mainDir, &constant, &value);
    if (constant) {
      if (!isLightSpectrum(p)) return Rgb(float(value));  // pbrt-v4: a constant reflectance is grey under D65
      s = spectrum::Piecewise{{360, 830}, {value, value}, true};
    }
  }
  spectrum::Xyz c;
  if (v3) c = spectrum::xyzEqualEnergy(s);
  else if (isLightSpectrum(p)) {
    c = spectrum::xyzEqualEnergy(s);
    if (!(c.y > 0)) ps.fail(p, "pbrt-v4 normalises a light's spectrum to luminance 1, and this one has none");
    c = {c.x / c.y, 1.0, c.z / c.y};
  } else c = spectrum::xyzUnderD65(s);
  Rgb rgb = spectrum::xyzToLinearSrgb(c);
  return rgb * float(scale);
}

double Importer::spectrumFloat(const ParamSet& ps, const Param& p) const {
  p.used = true;
  if (p.strings.empty() && p.numbers.size() == 1) return p.numbers[0];  // v4: a constant
  // glass-BAF10: pbrt-v4's table (refractiveindex.info, CC0), its y-bar
  // weighted mean computed as below, once.
  if (p.strings.size() == 1 && p.strings[0] == "glass-BAF10") return 1.67259;
  bool v3 = film_.given && film_.type == "image";
  bool constant = false;
  double value = 0;
  spectrum::Piecewise s = readPairs(ps, p, v3, mainDir, &constant, &value);
  if (constant) return value;
  // One number for a spectrum (tdpm's dielectric has one ior: no
  // dispersion): its mean weighted by the luminous efficiency y-bar.
  return spectrum::xyzEqualEnergy(s).y;
}

}  // namespace tdpm::pbrt::detail
