// image/profile_plot.cpp — row profiles as CSV and as a hand-written SVG chart.
#include "image/profile_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"

namespace tdpm::image {

namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// Text content and attribute values: file names may contain & < > " '.
std::string xmlEscape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  return out;
}

float lumOrZero(const Rgb& c) {
  float l = c.luminance();
  return std::isfinite(l) ? l : 0.0f;
}

// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `target`
// intervals over `range`, so tick labels read like 0, 0.5, 1, 1.5 ...
double niceStep(double range, int target) {
  double raw = range / target;
  double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double f = raw / mag;
  double nice = f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10;
  return nice * mag;
}

// Tick label without float noise ("0.30000000000000004" -> "0.3").
std::string tickLabel(double v, double step) {
  if (std::abs(v) < step * 1e-6) v = 0;
  return fmt("%.6g", v);
}

}  // namespace

RowProfile extractRowProfile(const ImageRgb& test, const ImageRgb& reference, int y, int x0, int w) {
  TDPM_ASSERT(test.width == reference.width && test.height == reference.height, "profile: image sizes differ");
  TDPM_ASSERT(y >= 0 && y < test.height && x0 >= 0 && w >= 1 && x0 + w <= test.width, "profile: outside the image");
  RowProfile p;
  p.y = y;
  p.x0 = x0;
  for (int x = x0; x < x0 + w; ++x) {
    p.test.push_back(test.at(x, y));
    p.ref.push_back(reference.at(x, y));
  }
  return p;
}

std::string profileCsv(const RowProfile& p) {
  std::string s = "x,test_r,test_g,test_b,ref_r,ref_g,ref_b,test_lum,ref_lum\n";
  for (size_t i = 0; i < p.test.size(); ++i) {
    const Rgb& t = p.test[i];
    const Rgb& r = p.ref[i];
    s += std::to_string(p.x0 + int(i));
    for (float v : {t.r, t.g, t.b, r.r, r.g, r.b, t.luminance(), r.luminance()}) s += "," + fmt("%.9g", v);
    s += "\n";
  }
  return s;
}

std::string profileSvg(const RowProfile& p, const std::string& testName, const std::string& refName) {
  TDPM_ASSERT(!p.test.empty() && p.test.size() == p.ref.size(), "profileSvg: empty or uneven profile");
  // Layout in SVG user units (pixels at 100 %).
  const double W = 900, H = 480, left = 80, right = 24, top = 56, bottom = 64;
  const double pw = W - left - right, ph = H - top - bottom;

  // Data ranges. x: pixel columns (a single column gets a unit-wide axis).
  const int n = int(p.test.size());
  double xMin = p.x0, xMax = p.x0 + n - 1;
  if (n == 1) xMin -= 0.5, xMax += 0.5;
  // y: from 0 (or below, for signed estimators) to the highest value,
  // extended to whole tick steps so the curves never touch the frame.
  double lo = 0, hi = 0;
  for (int i = 0; i < n; ++i)
    for (float v : {lumOrZero(p.test[i]), lumOrZero(p.ref[i])}) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
  if (hi - lo <= 0) hi = lo + 1;  // all black: still draw a readable axis
  const double yStep = niceStep(hi - lo, 5);
  const double yMin = std::floor(lo / yStep) * yStep, yMax = std::ceil(hi / yStep) * yStep;
  const double xStep = std::max(1.0, niceStep(xMax - xMin, 8));  // pixel columns are integers

  auto sx = [&](double x) { return left + (x - xMin) / (xMax - xMin) * pw; };
  auto sy = [&](double y) { return top + (1 - (y - yMin) / (yMax - yMin)) * ph; };

  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fmt("%g", W) + "\" height=\"" + fmt("%g", H) +
       "\" viewBox=\"0 0 " + fmt("%g", W) + " " + fmt("%g", H) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect x=\"0\" y=\"0\" width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + fmt("%g", left + pw / 2) + "\" y=\"28\" text-anchor=\"middle\" font-size=\"15\">Luminance along row " +
       std::to_string(p.y) + ": " + xmlEscape(testName) + " vs " + xmlEscape(refName) + "</text>\n";

  // Grid and y ticks.
  s += "<g stroke=\"#dddddd\" stroke-width=\"1\">\n";
  for (double v = yMin; v <= yMax + yStep * 1e-6; v += yStep)
    s += "<line x1=\"" + fmt("%.2f", left) + "\" y1=\"" + fmt("%.2f", sy(v)) + "\" x2=\"" + fmt("%.2f", left + pw) +
         "\" y2=\"" + fmt("%.2f", sy(v)) + "\"/>\n";
  s += "</g>\n<g text-anchor=\"end\">\n";
  for (double v = yMin; v <= yMax + yStep * 1e-6; v += yStep)
    s += "<line x1=\"" + fmt("%.2f", left - 5) + "\" y1=\"" + fmt("%.2f", sy(v)) + "\" x2=\"" + fmt("%.2f", left) +
         "\" y2=\"" + fmt("%.2f", sy(v)) + "\" stroke=\"black\"/><text x=\"" + fmt("%.2f", left - 8) + "\" y=\"" +
         fmt("%.2f", sy(v) + 4) + "\">" + tickLabel(v, yStep) + "</text>\n";
  s += "</g>\n<g text-anchor=\"middle\">\n";
  // x ticks at multiples of the step inside the range.
  for (double v = std::ceil(xMin / xStep) * xStep; v <= xMax + 1e-9; v += xStep)
    s += "<line x1=\"" + fmt("%.2f", sx(v)) + "\" y1=\"" + fmt("%.2f", top + ph) + "\" x2=\"" + fmt("%.2f", sx(v)) +
         "\" y2=\"" + fmt("%.2f", top + ph + 5) + "\" stroke=\"black\"/><text x=\"" + fmt("%.2f", sx(v)) + "\" y=\"" +
         fmt("%.2f", top + ph + 19) + "\">" + tickLabel(v, xStep) + "</text>\n";
  s += "</g>\n";

  // Axes (frame) and their labels.
  s += "<rect x=\"" + fmt("%.2f", left) + "\" y=\"" + fmt("%.2f", top) + "\" width=\"" + fmt("%.2f", pw) +
       "\" height=\"" + fmt("%.2f", ph) + "\" fill=\"none\" stroke=\"black\"/>\n";
  s += "<text x=\"" + fmt("%.2f", left + pw / 2) + "\" y=\"" + fmt("%.2f", H - 18) +
       "\" text-anchor=\"middle\">x (pixel column)</text>\n";
  s += "<text transform=\"translate(20," + fmt("%.2f", top + ph / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">luminance (linear, Rec. 709)</text>\n";

  // Curves: reference underneath, test on top.
  auto polyline = [&](const std::vector<Rgb>& v, const char* colour, double width, const char* id) {
    std::string pts;
    for (int i = 0; i < n; ++i) {
      double x = n == 1 ? (xMin + xMax) / 2 : double(p.x0 + i);
      pts += (i ? " " : "") + fmt("%.2f", sx(x)) + "," + fmt("%.2f", sy(lumOrZero(v[i])));
    }
    if (n == 1) pts += " " + fmt("%.2f", sx(xMax)) + "," + fmt("%.2f", sy(lumOrZero(v[0])));  // a visible segment
    return "<polyline id=\"" + std::string(id) + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"" +
           fmt("%g", width) + "\" stroke-linejoin=\"round\" points=\"" + pts + "\"/>\n";
  };
  s += polyline(p.ref, "#222222", 2.5, "reference");
  s += polyline(p.test, "#d62728", 1.5, "test");

  // Legend, top right inside the plot.
  // Its width follows the longer label (about 7 units per character at 12 px).
  const size_t longest = std::max(testName.size() + 6, refName.size() + 11);
  const double legendW = std::min(pw - 16, 52 + 7.0 * double(longest));
  const double lx = left + pw - legendW, ly = top + 12;  // box ends 8 units inside the frame
  s += "<rect x=\"" + fmt("%.2f", lx - 8) + "\" y=\"" + fmt("%.2f", ly - 4) + "\" width=\"" + fmt("%.2f", legendW) +
       "\" height=\"44\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#999999\"/>\n";
  s += "<line x1=\"" + fmt("%.2f", lx) + "\" y1=\"" + fmt("%.2f", ly + 8) + "\" x2=\"" + fmt("%.2f", lx + 28) +
       "\" y2=\"" + fmt("%.2f", ly + 8) + "\" stroke=\"#d62728\" stroke-width=\"1.5\"/><text x=\"" +
       fmt("%.2f", lx + 36) + "\" y=\"" + fmt("%.2f", ly + 12) + "\">test: " + xmlEscape(testName) + "</text>\n";
  s += "<line x1=\"" + fmt("%.2f", lx) + "\" y1=\"" + fmt("%.2f", ly + 28) + "\" x2=\"" + fmt("%.2f", lx + 28) +
       "\" y2=\"" + fmt("%.2f", ly + 28) + "\" stroke=\"#222222\" stroke-width=\"2.5\"/><text x=\"" +
       fmt("%.2f", lx + 36) + "\" y=\"" + fmt("%.2f", ly + 32) + "\">reference: " + xmlEscape(refName) + "</text>\n";
  s += "</svg>\n";
  return s;
}

}  // namespace tdpm::image
