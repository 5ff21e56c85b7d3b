// image/profile_plot.h — line profiles: the pixel values of one image row of
// a test and a reference image, as CSV text and as an SVG line chart of
// luminance (the test curve drawn over the reference curve), like the
// intensity graphs through the caustic in Cammarano & Jensen's paper.
// Owns: RowProfile, extractRowProfile, profileCsv, profileSvg. Pure text
// producers: writing the files (atomically) is the caller's job.
// The SVG is written by hand (a few dozen elements) rather than through a
// plotting library, so the project has no dependency for one chart.
#pragma once
#include <string>
#include <vector>

#include "image/image.h"

namespace tdpm::image {

struct RowProfile {
  int y = 0;              // the image row
  int x0 = 0;             // column of test[0] / ref[0]
  std::vector<Rgb> test;  // columns x0 .. x0 + size() - 1
  std::vector<Rgb> ref;
};

// Row `y`, columns [x0, x0 + w). Same-size images, y and the columns inside
// them (the caller validates with flag names; a violation is a bug).
RowProfile extractRowProfile(const ImageRgb& test, const ImageRgb& reference, int y, int x0, int w);

// Header "x,test_r,test_g,test_b,ref_r,ref_g,ref_b,test_lum,ref_lum", then one
// line per column; values with 9 significant digits (float round trip);
// luminance is Rec. 709 (Rgb::luminance) of the linear values.
std::string profileCsv(const RowProfile& profile);

// An SVG line chart of luminance against x: axes with ticks and labels, a
// light grid, a legend naming both files, and the title
// "Luminance along row <y>: <testName> vs <refName>". The reference is drawn
// first (wide, dark) and the test on top (thin, red), each as one
// <polyline>. Non-finite values are drawn as 0.
std::string profileSvg(const RowProfile& profile, const std::string& testName, const std::string& refName);

}  // namespace tdpm::image
