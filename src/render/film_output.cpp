// render/film_output.cpp — Film -> image::ExrFile.
#include "render/film_output.h"

#include <string>

namespace tdpm {

image::ExrFile filmToExr(const Film& film) {
  image::ExrFile exr;
  exr.color.width = film.width;
  exr.color.height = film.height;
  exr.color.pixels = film.color;
  exr.extra.push_back({"spp", film.sampleCount});
  for (int c = 0; c < 3; ++c) {
    image::Channel ch{std::string("variance.") + "RGB"[c], {}};
    ch.values.reserve(film.varianceOfMean.size());
    for (const Rgb& v : film.varianceOfMean) ch.values.push_back(v[c]);
    exr.extra.push_back(std::move(ch));
  }
  return exr;
}

}  // namespace tdpm
