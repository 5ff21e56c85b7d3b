// image/read_image.cpp — format detection by magic bytes and dispatch to
// the readers (see read_image.h).
#include "image/read_image.h"

#include <cctype>
#include <cstdio>
#include <cstring>
#include <new>
#include <utility>

#include "image/exr.h"
#include "image/hdr.h"
#include "image/image_limits.h"
#include "image/pfm.h"
#include "image/png.h"

namespace tdpm::image {

const char* formatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::Exr: return "OpenEXR";
    case ImageFormat::Pfm: return "PFM";
    case ImageFormat::Hdr: return "Radiance HDR";
    case ImageFormat::Png: return "PNG";
  }
  return "?";
}

namespace {

// The format a file name's extension promises, if it is one we know.
bool formatOfExtension(const std::string& path, ImageFormat& format) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return false;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == "exr") format = ImageFormat::Exr;
  else if (ext == "pfm") format = ImageFormat::Pfm;
  else if (ext == "hdr" || ext == "pic" || ext == "rgbe") format = ImageFormat::Hdr;
  else if (ext == "png") format = ImageFormat::Png;
  else return false;
  return true;
}

}  // namespace

ImageFormat detectImageFormat(const std::string& path) {
  uint64_t size = 0;
  std::FILE* f = openRegularFile(path, size);
  unsigned char m[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  const size_t n = std::fread(m, 1, 8, f);
  std::fclose(f);
  const unsigned char exr[4] = {0x76, 0x2f, 0x31, 0x01};
  const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto space = [](unsigned char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  ImageFormat content = ImageFormat::Exr;
  bool known = true;
  if (n >= 4 && std::memcmp(m, exr, 4) == 0) content = ImageFormat::Exr;
  else if (n >= 8 && std::memcmp(m, png, 8) == 0) content = ImageFormat::Png;
  else if (n >= 3 && m[0] == 'P' && (m[1] == 'F' || m[1] == 'f') && space(m[2])) content = ImageFormat::Pfm;
  else if (n >= 2 && m[0] == '#' && m[1] == '?') content = ImageFormat::Hdr;
  else known = false;

  ImageFormat named = ImageFormat::Exr;
  const bool hasExtension = formatOfExtension(path, named);
  if (!known)
    throw Error(path + ": " + (hasExtension ? std::string("not a ") + formatName(named) + " file (its first bytes are not" +
                                                  " that format's signature)"
                                            : std::string("not an image tdpm reads")) +
                "; tdpm reads OpenEXR, PFM ('PF'/'Pf'), Radiance HDR ('#?RADIANCE') and PNG, recognised by content" +
                (size == 0 ? " (the file is empty)" : ""));
  if (hasExtension && named != content)
    throw Error(path + ": the name says " + formatName(named) + " but the content is " + formatName(content) +
                "; rename the file so that its extension matches");
  return content;
}

LoadedImage readImage(const std::string& path) {
  LoadedImage out;
  out.format = detectImageFormat(path);
  try {
    switch (out.format) {
      case ImageFormat::Exr: out.color = std::move(readExr(path).color); break;
      case ImageFormat::Pfm: out.color = readPfm(path); break;
      case ImageFormat::Hdr: out.color = readHdr(path); break;
      case ImageFormat::Png: out.color = readPngLinear(path); break;
    }
  } catch (const std::bad_alloc&) {
    // The readers check the memory first; this is the case where the
    // machine's state changed in between.
    throw Error(path + ": out of memory reading the " + formatName(out.format) + " image");
  }
  return out;
}

}  // namespace tdpm::image
