// image/exr.h — OpenEXR files: the renderer's output and `compare`'s input.
// Owns: ExrFile (colour + extra per-pixel float layers + string metadata),
// writeExr, readExr. image/exr.cpp is the only file that includes OpenEXR;
// callers never see Imf/Iex types or exceptions.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "image/image.h"

namespace tdpm::image {

// One float per pixel, same layout as ImageRgb::pixels (row-major, y down).
// Names follow EXR layer conventions: "spp", "variance.R", "variance.G", ...
struct Channel {
  std::string name;
  std::vector<float> values;
  // On reading: the channel's pixel type in the file (values are converted
  // to float either way). A HALF or UINT channel does not hold the floats
  // that were written: progressive state layers must be FLOAT.
  enum class FileType { Float, Half, Uint };
  FileType fileType = FileType::Float;
};

struct ExrFile {
  ImageRgb color;
  std::vector<Channel> extra;
  // String attributes, e.g. "tdpm/scene", "tdpm/method", "tdpm/spp",
  // "tdpm/seed", "tdpm/render_seconds". On reading: every string attribute
  // of the header (also foreign ones such as "owner" or "comments").
  std::map<std::string, std::string> metadata;
  // On reading: the file's compression, by OpenEXR's name ("zip", "dwaa",
  // ...), and whether it is lossy (DWAA, DWAB, B44, B44A; PXR24 for FLOAT
  // channels): such a file's floats are not the ones that were written.
  std::string compression;
  bool lossyCompression = false;

  // The extra channel called `name`, or nullptr.
  const Channel* findChannel(const std::string& name) const;
};

// Writes 32-bit float R, G, B plus every extra channel as FLOAT, ZIP
// compressed, metadata as string attributes. Atomic: the file at `path`
// either is complete or was not touched. Throws tdpm::Error "<path>: ...".
// Inconsistent input (empty image, channel of the wrong length, duplicate
// or reserved channel names) is a bug: TDPM_ASSERT.
void writeExr(const std::string& path, const ExrFile& file);
// The same, into the file `tempPath` as it is (not atomic; errors name
// `path`): for callers that commit several outputs together
// (core/atomic_file commitTogether).
void writeExrTo(const std::string& tempPath, const std::string& path, const ExrFile& file);

// Reads the data window of a flat (scanline or tiled) EXR, first part:
//  * colour from R, G, B (any pixel type, converted to float); an image with
//    Y reads as grey (R = G = B = Y) unless X (CIE XYZ), RY/BY (luma/chroma)
//    or a partial R, G, B is present too: those sets, and files with neither
//    R, G, B nor Y, are an error naming the channels found and understood;
//  * every other full-resolution channel (HALF, FLOAT or UINT) as `extra`,
//    in the file's (alphabetical) channel order; sub-sampled channels
//    (e.g. luma/chroma RY, BY) are skipped;
//  * all string attributes as metadata.
// Admits every image tdpm writes (up to 65536 per side); what it allocates
// is bounded by the file's size (checkExrHeader) and the memory available.
// Any failure (missing or unreadable file, not an EXR, truncated or
// corrupt data, deep image, no colour channels) throws tdpm::Error
// "<path>: <reason>"; OpenEXR's own exceptions never escape.
ExrFile readExr(const std::string& path);

}  // namespace tdpm::image
