// image/exr.cpp — the only file in tdpm that touches OpenEXR (3.1 C++ API).
// Every OpenEXR (Iex) exception is turned into tdpm::Error "<path>: <why>"
// here, so a corrupt input can never abort a `compare` run.
#include "image/exr.h"

#include <sys/stat.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfPartType.h>
#include <Imath/ImathBox.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <set>

#include "core/atomic_file.h"
#include "core/regular_file.h"
#include "image/exr_header_check.h"
#include "image/image_limits.h"

namespace tdpm::image {
namespace {

static_assert(sizeof(Rgb) == 3 * sizeof(float), "Rgb must be three packed floats: EXR slices stride over it");

bool isColorName(const std::string& n) { return n == "R" || n == "G" || n == "B"; }

// Checks the things OpenEXR reports badly (or not at all): existence,
// readability, directories, and the magic number, so the user gets
// "No such file or directory" / "not an OpenEXR file" instead of Iex text.
void precheckInput(const std::string& path) {
  // Regular files only, checked on the opened descriptor: a FIFO would
  // block open() (and OpenEXR's own open after it) for ever.
  std::FILE* f = openRegularInput(path, "an OpenEXR file");
  unsigned char magic[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  size_t n = std::fread(magic, 1, 8, f);
  // EXR magic number 20000630 = 0x01312f76, stored little-endian.
  const unsigned char expected[4] = {0x76, 0x2f, 0x31, 0x01};
  const bool isExr = n >= 4 && std::memcmp(magic, expected, 4) == 0;
  // OpenEXR trusts the header's sizes when it allocates (see
  // image/exr_header_check.h): check them first.
  const std::string bad = isExr ? checkExrHeader(f) : std::string();
  std::fclose(f);
  if (!isExr) throw Error(path + ": not an OpenEXR file (bad magic number)");
  if (!bad.empty()) throw Error(path + ": corrupt OpenEXR header: " + bad);
}

// OpenEXR's name of `c` and whether it can change what was written
// (PXR24 rounds FLOAT to 24 bits; B44 and DWA are lossy for HALF and, for
// DWA, FLOAT colour).
void compressionOf(Imf::Compression c, std::string& name, bool& lossy) {
  switch (c) {
    case Imf::NO_COMPRESSION: name = "none"; lossy = false; return;
    case Imf::RLE_COMPRESSION: name = "rle"; lossy = false; return;
    case Imf::ZIPS_COMPRESSION: name = "zips"; lossy = false; return;
    case Imf::ZIP_COMPRESSION: name = "zip"; lossy = false; return;
    case Imf::PIZ_COMPRESSION: name = "piz"; lossy = false; return;
    case Imf::PXR24_COMPRESSION: name = "pxr24"; lossy = true; return;
    case Imf::B44_COMPRESSION: name = "b44"; lossy = true; return;
    case Imf::B44A_COMPRESSION: name = "b44a"; lossy = true; return;
    case Imf::DWAA_COMPRESSION: name = "dwaa"; lossy = true; return;
    case Imf::DWAB_COMPRESSION: name = "dwab"; lossy = true; return;
    default: name = "unknown (" + std::to_string(int(c)) + ")"; lossy = true; return;
  }
}

}  // namespace

const Channel* ExrFile::findChannel(const std::string& name) const {
  for (const Channel& c : extra)
    if (c.name == name) return &c;
  return nullptr;
}

// ---- writing ----

void writeExr(const std::string& path, const ExrFile& file) {
  // Created first: a missing or read-only directory fails here, in our words.
  AtomicFile out(path);
  writeExrTo(out.tempPath(), path, file);
  out.commit();
}

void writeExrTo(const std::string& tempPath, const std::string& path, const ExrFile& file) {
  const ImageRgb& img = file.color;
  TDPM_ASSERT(!img.empty(), "writeExr: empty image");
  TDPM_ASSERT(img.pixels.size() == img.pixelCount(), "writeExr: pixel count does not match size");
  std::set<std::string> names{"R", "G", "B"};
  for (const Channel& c : file.extra) {
    TDPM_ASSERT(!c.name.empty(), "writeExr: unnamed extra channel");
    TDPM_ASSERT(names.insert(c.name).second, "writeExr: duplicate channel name " + c.name);
    TDPM_ASSERT(c.values.size() == img.pixelCount(), "writeExr: channel " + c.name + " has the wrong length");
  }

  try {
    Imf::Header header(img.width, img.height);
    header.compression() = Imf::ZIP_COMPRESSION;  // lossless, ~2x on renders
    header.lineOrder() = Imf::INCREASING_Y;       // row 0 = top, as ImageRgb
    for (const auto& [key, value] : file.metadata) header.insert(key, Imf::StringAttribute(value));

    Imf::FrameBuffer fb;
    const size_t rgbX = sizeof(Rgb), rgbY = sizeof(Rgb) * size_t(img.width);
    // OpenEXR's Slice wants a non-const pointer even for writing; it only reads.
    char* base = reinterpret_cast<char*>(const_cast<Rgb*>(img.pixels.data()));
    const char* rgbNames[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(rgbNames[c], Imf::Channel(Imf::FLOAT));
      fb.insert(rgbNames[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), rgbX, rgbY));
    }
    for (const Channel& c : file.extra) {
      header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
      char* p = reinterpret_cast<char*>(const_cast<float*>(c.values.data()));
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, p, sizeof(float), sizeof(float) * size_t(img.width)));
    }
    {
      // Scope: the OutputFile destructor writes the line offset table, so it
      // must be closed before the rename.
      Imf::OutputFile exr(tempPath.c_str(), header);
      exr.setFrameBuffer(fb);
      exr.writePixels(img.height);
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path + ": cannot write OpenEXR file: " + e.what());
  }
}

// ---- reading ----

// OpenEXR sizes its line and tile buffers from the header before anything
// else is checked: a damaged 1 kB file declaring a 4-million-pixel-wide
// data window made InputFile's constructor allocate hundreds of MB
// (fuzz_exr). Its own guard is these limits (0 = unlimited by default);
// 65536 per side is also the largest image tdpm renders.
void limitOpenExrSizes() {
  static const bool once = [] {
    Imf::Header::setMaxImageSize(int(kMaxImageSide), int(kMaxImageSide));
    Imf::Header::setMaxTileSize(8192, 8192);
    return true;
  }();
  (void)once;
}

ExrFile readExr(const std::string& path) {
  precheckInput(path);
  limitOpenExrSizes();
  ExrFile result;
  try {
    Imf::InputFile in(path.c_str());
    const Imf::Header& header = in.header();
    if (header.hasType() && Imf::isDeepData(header.type()))
      throw Error(path + ": deep OpenEXR images are not supported");

    const Imath::Box2i dw = header.dataWindow();
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0) throw Error(path + ": empty data window");
    if (w > kMaxImageSide || h > kMaxImageSide)  // checkExrHeader said so already; kept for the reasoning
      throw Error(path + ": image too large (" + std::to_string(w) + "x" + std::to_string(h) + ")");
    const size_t npix = size_t(w) * size_t(h);
    // Before allocating: a truncated file of a few bytes can declare a
    // data window of 2^27 pixels (fuzz_exr: 1 kB inputs allocated up to
    // gigabytes, then failed here anyway).
    if (!in.isComplete()) throw Error(path + ": truncated OpenEXR file (missing pixel data)");

    // Which channels we can read: full resolution only, and only sets whose
    // meaning is clear. X/Y/Z, luma/chroma (Y, RY, BY) or a lone R are not
    // grey or colour: refused, never guessed.
    const Imf::ChannelList& channels = header.channels();
    auto fullRes = [&](const char* name) {
      const Imf::Channel* c = channels.findChannel(name);
      return c && c->xSampling == 1 && c->ySampling == 1;
    };
    const bool hasRgb = fullRes("R") && fullRes("G") && fullRes("B");
    bool hasY = false;
    if (!hasRgb) {
      // Grey: Y at full resolution, and no channel that would make Y part
      // of another colour space: X (CIE XYZ), RY/BY (luma/chroma) or a
      // partial R, G, B. (Z alone is EXR's depth channel; other names are
      // extra data.)
      bool onlyGrey = fullRes("Y");
      std::string present;
      for (auto it = channels.begin(); it != channels.end(); ++it) {
        const std::string name = it.name();
        present += std::string(present.empty() ? "" : ", ") + name;
        if (isColorName(name) || name == "X" || name == "RY" || name == "BY") onlyGrey = false;
      }
      if (!onlyGrey)
        throw Error(path + ": channels not understood: the file has " + (present.empty() ? "none" : present) +
                    "; tdpm reads R, G, B (colour) or Y without X, RY, BY or a partial R, G, B (grey), "
                    "at full resolution; other channels are extra data");
      hasY = true;
    }
    // The decoded image and every extra channel, as floats.
    size_t extraCount = 0;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      const std::string name = it.name();
      if (hasRgb ? isColorName(name) : name == "Y") continue;
      if (it.channel().xSampling == 1 && it.channel().ySampling == 1) ++extraCount;
    }
    checkDecodedImageFits(path, "OpenEXR", w, h, sizeof(Rgb) + sizeof(float) * extraCount);

    result.color = ImageRgb(int(w), int(h));
    Imf::FrameBuffer fb;
    // Slice::Make offsets the base pointer by the data window origin, so a
    // window not starting at (0,0) (crops from other tools) lands at index 0.
    char* base = reinterpret_cast<char*>(result.color.pixels.data());
    const size_t rgbX = sizeof(Rgb), rgbY = sizeof(Rgb) * size_t(w);
    if (hasRgb) {
      const char* rgbNames[3] = {"R", "G", "B"};
      for (int c = 0; c < 3; ++c)
        fb.insert(rgbNames[c], Imf::Slice::Make(Imf::FLOAT, base + c * sizeof(float), dw, rgbX, rgbY));
    } else {
      // Y into the red slot (no grey buffer the size of the image), copied
      // to green and blue below.
      fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, base, dw, rgbX, rgbY));
    }
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      const std::string name = it.name();
      if (hasRgb ? isColorName(name) : name == "Y") continue;
      const Imf::Channel& ch = it.channel();
      if (ch.xSampling != 1 || ch.ySampling != 1) continue;
      result.extra.push_back(Channel{name, std::vector<float>(npix)});
      result.extra.back().fileType = ch.type == Imf::HALF   ? Channel::FileType::Half
                                     : ch.type == Imf::UINT ? Channel::FileType::Uint
                                                            : Channel::FileType::Float;
    }
    // Insert after the vector stopped growing: pointers must stay valid.
    for (Channel& c : result.extra)
      fb.insert(c.name, Imf::Slice::Make(Imf::FLOAT, c.values.data(), dw, sizeof(float), sizeof(float) * size_t(w)));

    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    compressionOf(header.compression(), result.compression, result.lossyCompression);

    if (hasY)
      for (Rgb& p : result.color.pixels) p = Rgb(p.r);

    for (auto it = header.begin(); it != header.end(); ++it)
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        result.metadata[it.name()] = s->value();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": out of memory reading OpenEXR file");
  } catch (const std::exception& e) {
    throw Error(path + ": cannot read OpenEXR file: " + e.what());
  } catch (...) {
    throw Error(path + ": cannot read OpenEXR file (unknown error)");
  }
  return result;
}

}  // namespace tdpm::image
