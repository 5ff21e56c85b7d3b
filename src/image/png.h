// image/png.h — the 8-bit sRGB PNG preview written beside every EXR, and
// the path rule that puts it there. image/png.cpp is the only user of libpng.
// The preview is for eyes only: every measurement reads the EXR.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/image.h"

namespace tdpm::image {

// An 8-bit RGB raster (row-major, y down, 3 bytes per pixel).
struct ImageRgb8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3
};

// sRGB opto-electronic transfer function (IEC 61966-2-1) on [0,1].
float srgbEncode(float linear);
// Display encoding of one linear value: NaN and negatives -> 0, values >= 1
// clamp to 255, then the sRGB OETF and rounding to nearest.
uint8_t toSrgb8(float linear);

// Tone maps (scale by 2^exposureStops, clamp, sRGB OETF) to 8 bits.
ImageRgb8 toPreview(const ImageRgb& image, float exposureStops);

// Writes toPreview(image, exposureStops) as an 8-bit RGB PNG with an sRGB
// chunk, atomically. Throws tdpm::Error "<path>: <reason>".
void writePngPreview(const std::string& path, const ImageRgb& image, float exposureStops);
// The same, into the file `tempPath` as it is (not atomic; errors name
// `path`): for callers that commit several outputs together.
void writePngPreviewTo(const std::string& tempPath, const std::string& path, const ImageRgb& image,
                       float exposureStops);

// Reads any PNG as 8-bit RGB (tests, and a preview check). Throws
// tdpm::Error "<path>: <reason>".
ImageRgb8 readPng(const std::string& path);

// sRGB electro-optical transfer function (IEC 61966-2-1): code value in
// [0,1] to linear.
float srgbDecode(float encoded);

// Reads any PNG (grey, RGB, palette, with or without alpha; 1- to 16-bit)
// as linear RGB for `compare`, through libpng's simplified API, which also
// applies the file's gAMA/sRGB/cHRM information:
//  * 8-bit and lower files are read as 8-bit sRGB codes and decoded exactly
//    with srgbDecode (so values are the 256 sRGB levels);
//  * 16-bit files are read as libpng's 16-bit linear values (v / 65535);
//    note libpng's rule that a 16-bit file without gAMA or sRGB chunk is
//    already linear. libpng associates alpha in linear output; it is
//    divided out again (colour where alpha is 0 reads as black).
// Alpha is not applied: colour is PNG's straight (unassociated) colour.
// Each side at most 65536, and width * height bounded by what the file's
// size can hold (deflate's 1032:1 at 1 bit per pixel); throws tdpm::Error
// "<path>: <reason>".
ImageRgb readPngLinear(const std::string& path);

// The preview's path for an output path: the extension of the last path
// component replaced by ".png" ("out.exr" -> "out.png", "dir.v2/out" ->
// "dir.v2/out.png", ".hidden" -> ".hidden.png"). If the output itself ends
// in ".png" the preview becomes "<stem>.preview.png", never the same file.
std::string previewPathFor(const std::string& outputPath);

}  // namespace tdpm::image
