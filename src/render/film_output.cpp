// render/film_output.cpp — Film -> image::ExrFile, and the EXR + PNG pair
// written as one.
#include "render/film_output.h"

#include <string>
#include <utility>

#include "core/atomic_file.h"
#include "image/png.h"

namespace tdpm {

namespace {

void addVarianceLayers(const std::vector<Rgb>& varianceOfMean, image::ExrFile& exr) {
  for (int c = 0; c < 3; ++c) {
    image::Channel ch{std::string("variance.") + "RGB"[c], {}};
    ch.values.reserve(varianceOfMean.size());
    for (const Rgb& v : varianceOfMean) ch.values.push_back(v[c]);
    exr.extra.push_back(std::move(ch));
  }
}

}  // namespace

image::ExrFile filmToExr(const Film& film) {
  image::ExrFile exr;
  exr.color.width = film.width;
  exr.color.height = film.height;
  exr.color.pixels = film.color;
  exr.extra.push_back({"spp", film.sampleCount});
  addVarianceLayers(film.varianceOfMean, exr);
  return exr;
}

image::ExrFile filmToExr(Film&& film) {
  image::ExrFile exr;
  exr.color.width = film.width;
  exr.color.height = film.height;
  exr.color.pixels = std::move(film.color);
  exr.extra.reserve(4);
  exr.extra.push_back({"spp", std::move(film.sampleCount)});
  addVarianceLayers(film.varianceOfMean, exr);
  std::vector<Rgb>().swap(film.varianceOfMean);
  return exr;
}

void writeRenderOutputs(const std::string& exrPath, const std::string& pngPath, const image::ExrFile& exr,
                        float exposureStops) {
  AtomicFile exrFile(exrPath), pngFile(pngPath);
  // The small preview first: its 8-bit buffer is freed before the EXR is
  // encoded, and a full disk then usually fails on the EXR, with the
  // preview's temporary already written: exactly the case the pair must
  // survive (tests/test_output_safety.cpp).
  image::writePngPreviewTo(pngFile.tempPath(), pngPath, exr.color, exposureStops);
  image::writeExrTo(exrFile.tempPath(), exrPath, exr);
  commitTogether({&exrFile, &pngFile});
}

}  // namespace tdpm
