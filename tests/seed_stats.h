// tests/seed_stats.h — what the animation suites compare over seeds: the
// mean red of a film (or of a pixel rectangle), and the mean and standard
// error of a value over independent realisations.
#pragma once
#include <cmath>
#include <vector>

#include "render/film.h"

namespace tdpm::test {

// Mean red over pixels [x0, x1) x [y0, y1).
inline double meanRed(const Film& f, int x0, int y0, int x1, int y1) {
  double s = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += f.color[f.index(x, y)].r;
  return s / double((x1 - x0) * (y1 - y0));
}
inline double meanRed(const Film& f) { return meanRed(f, 0, 0, f.width, f.height); }

struct MeanAndError {
  double mean = 0, se = 0;
};
// The mean of v and its standard error (v: one value per realisation).
inline MeanAndError overSeeds(const std::vector<double>& v) {
  const double n = double(v.size());
  MeanAndError r;
  for (double x : v) r.mean += x / n;
  double ss = 0;
  for (double x : v) ss += (x - r.mean) * (x - r.mean);
  r.se = std::sqrt(ss / (n - 1.0) / n);
  return r;
}

}  // namespace tdpm::test
