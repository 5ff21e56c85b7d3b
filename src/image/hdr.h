// image/hdr.h — Radiance HDR (RGBE, ".hdr"/".pic") files. Owns readHdr and
// writeHdr.
//
// Format (Greg Ward, "Real Pixels", Graphics Gems II, and Radiance's
// color.c): a text header starting "#?RADIANCE" (or "#?RGBE"), lines such
// as FORMAT=32-bit_rle_rgbe and EXPOSURE=..., an empty line, a resolution
// line ("-Y H +X W" is the usual top-to-bottom, left-to-right; all eight
// orientations are read), then scanlines of 4-byte RGBE pixels, each either
// new-style run-length encoded (2, 2, length, then the four components
// separately), flat, or flat with old-style repeat codes (1, 1, 1, n).
// Debian's small option, stb_image, reads only "-Y +X", does not check the
// declared size against the file and does no PFM; OpenImageIO and FreeImage
// would be large new dependencies: hence this small strict reader.
#pragma once
#include <string>

#include "image/image.h"

namespace tdpm::image {

// Reads an RGBE Radiance file into linear RGB, row 0 at the top, each
// value divided by the product of the header's EXPOSURE values (Radiance's
// definition: EXPOSURE is a factor already applied to the pixels).
// FORMAT=32-bit_rle_xyze (CIE XYZ) is refused; PRIMARIES and COLORCORR
// lines are ignored (pixels are taken as the same RGB as the other image). Scanlines are decoded into
// a buffer that grows only with decoded data, so a short file never makes
// it allocate the declared size; the declared size is checked against the
// memory available before decoding. Throws tdpm::Error "<path>: <reason>",
// naming the scanline for damaged pixel data.
ImageRgb readHdr(const std::string& path);

// Writes `image` as "-Y H +X W" RGBE with new-style run-length encoded
// scanlines when width is in 8..32767 (Radiance's rule), else flat. RGBE
// keeps 8 mantissa bits: relative error up to 2^-8 of the largest channel.
// Atomic; throws tdpm::Error. For tests and for handing images to Radiance
// tools.
void writeHdr(const std::string& path, const ImageRgb& image, bool runLengthEncode = true);

}  // namespace tdpm::image
