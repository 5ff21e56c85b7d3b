// import/ply_reader.cpp — PLY header parsing and the ASCII / binary bodies.
#include "import/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/regular_file.h"
#include "scene/limits.h"

namespace tdpm::pbrt {

namespace {

// An element's count must fit the 32-bit vertex indices tdpm's meshes use.
constexpr uint64_t kMaxPlyElementCount = uint64_t(0xffffffffu);

enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

size_t sizeOf(Type t) {
  switch (t) {
    case Type::Int8: case Type::UInt8: return 1;
    case Type::Int16: case Type::UInt16: return 2;
    case Type::Int32: case Type::UInt32: case Type::Float32: return 4;
    case Type::Float64: return 8;
  }
  return 1;
}

bool typeFrom(const std::string& s, Type* t) {
  static const struct { const char* a; const char* b; Type t; } kTypes[] = {
      {"char", "int8", Type::Int8},        {"uchar", "uint8", Type::UInt8},   {"short", "int16", Type::Int16},
      {"ushort", "uint16", Type::UInt16},  {"int", "int32", Type::Int32},     {"uint", "uint32", Type::UInt32},
      {"float", "float32", Type::Float32}, {"double", "float64", Type::Float64}};
  for (const auto& k : kTypes)
    if (s == k.a || s == k.b) {
      *t = k.t;
      return true;
    }
  return false;
}

struct Property {
  std::string name;
  Type type = Type::Float32;
  bool list = false;
  Type countType = Type::UInt8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

enum class Format { Ascii, Little, Big };

// Reads values one at a time from the body, in the file's format.
class Body {
 public:
  Body(const std::string& bytes, size_t pos, Format f, const std::string& name) : b_(bytes), pos_(pos), f_(f), name_(name) {}

  double read(Type t) {
    if (f_ == Format::Ascii) return readAscii(t);
    size_t n = sizeOf(t);
    if (pos_ + n > b_.size()) fail("the file ends in the middle of the data (truncated)");
    unsigned char raw[8];
    std::memcpy(raw, b_.data() + pos_, n);
    pos_ += n;
    bool hostLittle = [] { uint16_t one = 1; unsigned char c; std::memcpy(&c, &one, 1); return c == 1; }();
    if ((f_ == Format::Little) != hostLittle)
      for (size_t i = 0; i < n / 2; ++i) std::swap(raw[i], raw[n - 1 - i]);
    switch (t) {
      case Type::Int8: { int8_t v; std::memcpy(&v, raw, 1); return v; }
      case Type::UInt8: return raw[0];
      case Type::Int16: { int16_t v; std::memcpy(&v, raw, 2); return v; }
      case Type::UInt16: { uint16_t v; std::memcpy(&v, raw, 2); return v; }
      case Type::Int32: { int32_t v; std::memcpy(&v, raw, 4); return v; }
      case Type::UInt32: { uint32_t v; std::memcpy(&v, raw, 4); return v; }
      case Type::Float32: { float v; std::memcpy(&v, raw, 4); return v; }
      case Type::Float64: { double v; std::memcpy(&v, raw, 8); return v; }
    }
    return 0;
  }
  size_t remaining() const { return b_.size() - pos_; }
  [[noreturn]] void fail(const std::string& what) const { throw Error(name_ + ": " + what); }

 private:
  double readAscii(Type t) {
    while (pos_ < b_.size() && std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    if (pos_ >= b_.size()) fail("the file ends in the middle of the data (truncated)");
    size_t start = pos_;
    while (pos_ < b_.size() && !std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    std::string tok = b_.substr(start, pos_ - start);
    char* end = nullptr;
    double v = std::strtod(tok.c_str(), &end);
    if (end != tok.c_str() + tok.size()) fail("'" + tok + "' is not a number");
    bool integral = t != Type::Float32 && t != Type::Float64;
    if (integral && v != std::floor(v)) fail("'" + tok + "' is not an integer");
    return v;
  }
  const std::string& b_;
  size_t pos_;
  Format f_;
  const std::string& name_;
};

}  // namespace

PlyMesh parsePly(const std::string& bytes, const std::string& name) {
  auto fail = [&](const std::string& what) -> void { throw Error(name + ": " + what); };
  size_t end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0) fail("not a PLY file (it does not start with \"ply\")");
  if (end == std::string::npos || end > (1 << 20)) fail("no end_header within the first MiB: not a valid PLY header");
  size_t bodyStart = bytes.find('\n', end);
  if (bodyStart == std::string::npos) fail("the file ends after end_header (no data)");
  ++bodyStart;
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  std::getline(header, line);  // "ply"
  Format format = Format::Ascii;
  bool haveFormat = false;
  std::vector<Element> elements;
  while (std::getline(header, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream w(line);
    std::string key;
    if (!(w >> key) || key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      std::string f, version;
      w >> f >> version;
      if (f == "ascii") format = Format::Ascii;
      else if (f == "binary_little_endian") format = Format::Little;
      else if (f == "binary_big_endian") format = Format::Big;
      else fail("unknown format '" + f + "'");
      if (version != "1.0") fail("unsupported PLY version '" + version + "'");
      haveFormat = true;
    } else if (key == "element") {
      Element e;
      std::string count;
      if (!(w >> e.name >> count) || count.empty() || count.find_first_not_of("0123456789") != std::string::npos)
        fail("malformed line '" + line + "'");
      // Vertices are indexed by 32-bit integers: a larger count is refused
      // as such (not as a malformed line), whatever the file holds.
      size_t digits = count.find_first_not_of('0') == std::string::npos ? 0 : count.size() - count.find_first_not_of('0');
      if (digits > 10 || std::stoull(count) > kMaxPlyElementCount)
        fail("element \"" + e.name + "\" claims " + count + " entries, more than tdpm's limit of " +
             std::to_string(kMaxPlyElementCount));
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) fail("a property before any element");
      Property p;
      std::string t;
      if (!(w >> t)) fail("malformed line '" + line + "'");
      if (t == "list") {
        std::string ct, it;
        p.list = true;
        if (!(w >> ct >> it >> p.name) || !typeFrom(ct, &p.countType) || !typeFrom(it, &p.type))
          fail("malformed list property '" + line + "'");
        if (p.countType == Type::Float32 || p.countType == Type::Float64) fail("a list count must be an integer type");
      } else if (!typeFrom(t, &p.type) || !(w >> p.name)) {
        fail("malformed property '" + line + "'");
      }
      elements.back().props.push_back(p);
    } else {
      fail("unknown header line '" + line + "'");
    }
  }
  if (!haveFormat) fail("the header has no format line");

  PlyMesh mesh;
  Body body(bytes, bodyStart, format, name);
  bool sawVertices = false;
  for (const Element& e : elements) {
    // Every element takes at least one byte (binary) or two characters
    // (ASCII) per property: a count the file cannot hold is refused before
    // anything is allocated.
    uint64_t minPer = 0;
    for (const Property& p : e.props) minPer += format == Format::Ascii ? 2 : (p.list ? sizeOf(p.countType) : sizeOf(p.type));
    if (minPer > 0 && e.count > body.remaining() / minPer)
      body.fail("element \"" + e.name + "\" claims " + std::to_string(e.count) + " entries, more than the file can hold");
    if (e.name == "vertex") {
      int ix = -1, iy = -1, iz = -1, iu = -1, iv = -1, inx = -1, iny = -1, inz = -1;
      for (size_t i = 0; i < e.props.size(); ++i) {
        const Property& p = e.props[i];
        if (p.list) body.fail("vertex property \"" + p.name + "\" is a list");
        if (p.name == "x") ix = int(i);
        else if (p.name == "y") iy = int(i);
        else if (p.name == "z") iz = int(i);
        else if (p.name == "nx") inx = int(i);
        else if (p.name == "ny") iny = int(i);
        else if (p.name == "nz") inz = int(i);
        // pbrt reads u/v, s/t or texture_u/texture_v (and _s/_t) as the uv.
        else if (iu < 0 && (p.name == "u" || p.name == "s" || p.name == "texture_u" || p.name == "texture_s")) iu = int(i);
        else if (iv < 0 && (p.name == "v" || p.name == "t" || p.name == "texture_v" || p.name == "texture_t")) iv = int(i);
        else mesh.ignoredProperties.push_back(p.name);
      }
      if (ix < 0 || iy < 0 || iz < 0) body.fail("the vertex element lacks x, y or z");
      const bool normals = inx >= 0 && iny >= 0 && inz >= 0;  // pbrt reads them only as a triple
      if (!normals)
        for (int i : {inx, iny, inz})
          if (i >= 0) mesh.ignoredProperties.push_back(e.props[size_t(i)].name);
      mesh.vertices.reserve(size_t(e.count));
      std::vector<double> v(e.props.size());
      for (uint64_t k = 0; k < e.count; ++k) {
        for (size_t i = 0; i < e.props.size(); ++i) v[i] = body.read(e.props[i].type);
        Vec3f p{float(v[size_t(ix)]), float(v[size_t(iy)]), float(v[size_t(iz)])};
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          body.fail("vertex " + std::to_string(k) + " is not finite");
        mesh.vertices.push_back(p);
        if (iu >= 0 && iv >= 0) {
          Vec2f uv{float(v[size_t(iu)]), float(v[size_t(iv)])};
          if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) body.fail("vertex " + std::to_string(k) + "'s (u, v) is not finite");
          mesh.uvs.push_back(uv);
        }
        if (normals) {
          Vec3f n{float(v[size_t(inx)]), float(v[size_t(iny)]), float(v[size_t(inz)])};
          if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
            body.fail("vertex " + std::to_string(k) + "'s normal (nx, ny, nz) is not finite");
          mesh.normals.push_back(n);
        }
      }
      if (iu >= 0 && iv < 0) mesh.ignoredProperties.push_back(e.props[size_t(iu)].name);
      if (iv >= 0 && iu < 0) mesh.ignoredProperties.push_back(e.props[size_t(iv)].name);
      sawVertices = true;
    } else if (e.name == "face") {
      for (uint64_t k = 0; k < e.count; ++k) {
        bool sawIndices = false;
        for (const Property& p : e.props) {
          bool indices = p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
          size_t n = p.list ? size_t(body.read(p.countType)) : 1;
          if (p.list && n > 1024) body.fail("face " + std::to_string(k) + " has " + std::to_string(n) + " corners");
          std::vector<uint32_t> corners;
          for (size_t i = 0; i < n; ++i) {
            double x = body.read(p.type);
            if (!indices) continue;
            if (!(x >= 0) || x >= double(UINT32_MAX)) body.fail("face " + std::to_string(k) + " has the invalid index " + std::to_string(x));
            corners.push_back(uint32_t(x));
          }
          if (!indices) continue;
          sawIndices = true;
          if (n == 3) mesh.triangles.insert(mesh.triangles.end(), corners.begin(), corners.end());
          else if (n == 4) mesh.quads.insert(mesh.quads.end(), corners.begin(), corners.end());
          else body.fail("face " + std::to_string(k) + " has " + std::to_string(n) + " corners (only triangles and quads)");
        }
        if (!sawIndices) body.fail("the face element has no vertex_indices list");
      }
    } else {
      for (uint64_t k = 0; k < e.count; ++k)
        for (const Property& p : e.props) {
          size_t n = p.list ? size_t(body.read(p.countType)) : 1;
          if (n > (1u << 20)) body.fail("element \"" + e.name + "\": a list of " + std::to_string(n) + " entries");
          for (size_t i = 0; i < n; ++i) body.read(p.type);
        }
    }
  }
  if (!sawVertices) throw Error(name + ": the file has no vertex element");
  for (uint32_t i : mesh.triangles)
    if (i >= mesh.vertices.size()) throw Error(name + ": a face uses vertex " + std::to_string(i) + " but there are " + std::to_string(mesh.vertices.size()));
  for (uint32_t i : mesh.quads)
    if (i >= mesh.vertices.size()) throw Error(name + ": a face uses vertex " + std::to_string(i) + " but there are " + std::to_string(mesh.vertices.size()));
  if (mesh.triangles.empty() && mesh.quads.empty()) throw Error(name + ": the file has no faces");
  return mesh;
}

PlyMesh readPly(const std::string& path) {
  // stat before open: a FIFO would block open() for ever.
  RegularFileCheck f = checkRegularFile(path);
  if (!f.ok) throw Error(path + ": cannot read PLY file: " + f.problem);
  if (f.size > scene::limits::kMaxMeshFileBytes)
    throw Error(path + ": PLY file is too large (" + std::to_string(f.size) + " bytes; at most " +
                std::to_string(scene::limits::kMaxMeshFileBytes >> 20) + " MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read PLY file (" + std::strerror(errno) + ")");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw Error(path + ": error while reading PLY file");
  return parsePly(s.str(), path);
}

}  // namespace tdpm::pbrt
