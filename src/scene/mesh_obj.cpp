// scene/mesh_obj.cpp — OBJ loading for mesh shapes (see mesh_obj.h).
// tinyobjloader is lenient: it reads "nan", "inf", "abc" or "0x10" as some
// number, a missing coordinate as 0 and "1.5" or an overflowing index as
// some index. So every v/vn/vt/f line is first checked strictly here (with
// its line number), then tinyobjloader reads the file. Its triangulation
// silently drops faces whose indices are out of range, so we read raw
// polygons, check every index ourselves and fan-triangulate (exact for
// triangles and convex polygons).
#include "scene/mesh_obj.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include <tiny_obj_loader.h>

#include "scene/limits.h"

namespace tdpm::scene {

namespace {

std::string firstLine(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == '.' || line.back() == ' ')) line.pop_back();
  return line;
}

bool readable(const std::string& path, std::string* why) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) { *why = "does not exist"; return false; }
  if (!std::filesystem::is_regular_file(path, ec)) { *why = "is not a regular file"; return false; }
  uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits::kMaxMeshFileBytes) {
    *why = "is too large (" + std::to_string(size) + " bytes; at most " +
           std::to_string(limits::kMaxMeshFileBytes >> 20) + " MiB)";
    return false;
  }
  if (!std::ifstream(path, std::ios::binary)) { *why = "cannot be opened for reading"; return false; }
  return true;
}

// ---------------------------------------------------------------- strict pre-check

// Whitespace-separated words of one line, a '#' comment removed.
std::vector<std::string> wordsOf(const std::string& line) {
  std::vector<std::string> words;
  size_t end = line.find('#');
  if (end == std::string::npos) end = line.size();
  size_t i = 0;
  while (i < end) {
    while (i < end && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' || line[i] == '\v')) ++i;
    size_t start = i;
    while (i < end && !(line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' || line[i] == '\v')) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// A decimal number as OBJ writers spell it: [+-] digits [. digits] [e [+-] digits]
// (no hex, inf, nan or trailing characters).
bool isDecimal(const std::string& w) {
  size_t i = 0, n = w.size();
  if (i < n && (w[i] == '+' || w[i] == '-')) ++i;
  size_t digits = 0;
  while (i < n && isDigit(w[i])) { ++i; ++digits; }
  if (i < n && w[i] == '.') {
    ++i;
    while (i < n && isDigit(w[i])) { ++i; ++digits; }
  }
  if (digits == 0) return false;
  if (i < n && (w[i] == 'e' || w[i] == 'E')) {
    ++i;
    if (i < n && (w[i] == '+' || w[i] == '-')) ++i;
    size_t expDigits = 0;
    while (i < n && isDigit(w[i])) { ++i; ++expDigits; }
    if (expDigits == 0) return false;
  }
  return i == n;
}

// The problem with a v/vn/vt line's numbers, or "".
std::string numbersProblem(const std::vector<std::string>& w, size_t minCount, size_t maxCount, bool coordinates) {
  const std::string& kind = w[0];
  size_t count = w.size() - 1;
  if (count < minCount || count > maxCount)
    return "\"" + kind + "\" needs " + std::to_string(minCount) +
           (maxCount == minCount ? "" : " to " + std::to_string(maxCount)) + " numbers, got " + std::to_string(count);
  for (size_t i = 1; i < w.size(); ++i) {
    if (!isDecimal(w[i])) return "\"" + w[i] + "\" is not a decimal number";
    double d = std::strtod(w[i].c_str(), nullptr);
    if (!std::isfinite(float(d))) return "number " + w[i] + " is not finite as a 32-bit float";
    // x, y, z of a vertex (not w, nor vertex colours)
    if (coordinates && i <= 3 && !(std::fabs(d) <= double(limits::kMaxCoordinate)))
      return "coordinate " + w[i] + " is out of range: coordinates must be within +-1e+09 m, the range the ray "
             "tracer handles (docs/scene-format.md)";
  }
  return "";
}

// The problem with one corner of a face (v, v/vt, v//vn, v/vt/vn), or "".
std::string cornerProblem(const std::string& corner) {
  size_t start = 0;
  for (int part = 0; start <= corner.size(); ++part) {
    size_t slash = corner.find('/', start);
    std::string index = corner.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    bool optional = part == 1 && slash != std::string::npos;  // the vt of v//vn
    if (part > 2) return "face corner \"" + corner + "\" has more than 3 parts";
    if (!(index.empty() && optional)) {
      size_t i = (!index.empty() && index[0] == '-') ? 1 : 0;
      if (i == index.size()) return "face corner \"" + corner + "\": \"" + index + "\" is not an index";
      for (size_t k = i; k < index.size(); ++k)
        if (!isDigit(index[k])) return "face corner \"" + corner + "\": \"" + index + "\" is not an integer index";
      if (index.size() - i > 10 || std::strtoll(index.c_str(), nullptr, 10) > INT_MAX ||
          std::strtoll(index.c_str(), nullptr, 10) < -INT_MAX)
        return "face corner \"" + corner + "\": index " + index + " is too large";
      if (std::strtoll(index.c_str(), nullptr, 10) == 0) return "face corner \"" + corner + "\": OBJ indices start at 1, got 0";
    }
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return "";
}

// Checks every line strictly; records the line of each face, in file order.
bool precheck(const std::string& path, const std::string& name, std::vector<size_t>* faceLines, std::string* problem) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::vector<std::string> w = wordsOf(line);
    if (w.empty()) continue;
    std::string why;
    if (w[0] == "v") why = numbersProblem(w, 3, 7, true);  // x y z [w] or x y z r g b [a]
    else if (w[0] == "vn") why = numbersProblem(w, 3, 3, false);
    else if (w[0] == "vt") why = numbersProblem(w, 1, 3, false);
    else if (w[0] == "f") {
      if (w.size() < 4) why = "a face needs at least 3 vertices, got " + std::to_string(w.size() - 1);
      for (size_t i = 1; i < w.size() && why.empty(); ++i) why = cornerProblem(w[i]);
      faceLines->push_back(number);
    }
    if (!why.empty()) {
      *problem = name + ", line " + std::to_string(number) + ": " + why;
      return false;
    }
  }
  if (in.bad()) {
    *problem = name + ": read error";
    return false;
  }
  return true;
}

// Appends one polygon's triangles; false (with `problem`) on a bad index.
bool addPolygon(const tinyobj::index_t* corners, size_t n, size_t face, size_t vertexCount, ObjMesh* mesh,
                const std::vector<size_t>& faceLines, std::string* problem, const tinyobj::attrib_t& attrib,
                bool* allUv, bool* allNormals) {
  for (size_t k = 0; k < n; ++k) {
    int v = corners[k].vertex_index;
    if (v < 0 || size_t(v) >= vertexCount) {
      // Report 1-based OBJ indices; negative (relative) ones resolve below 0.
      *problem = (face < faceLines.size() ? "line " + std::to_string(faceLines[face]) + ": " : std::string()) + "face " +
                 std::to_string(face + 1) + " uses vertex " + std::to_string(int64_t(v) + 1) + " but the file has " +
                 std::to_string(vertexCount) + " vertices";
      return false;
    }
  }
  const size_t uvCount = attrib.texcoords.size() / 2;
  for (size_t k = 0; k < n && *allUv; ++k) {
    int t = corners[k].texcoord_index;
    if (t < 0) *allUv = false;  // a face without vt: no uv for the mesh
    else if (size_t(t) >= uvCount) {
      *problem = (face < faceLines.size() ? "line " + std::to_string(faceLines[face]) + ": " : std::string()) + "face " +
                 std::to_string(face + 1) + " uses texture coordinate " + std::to_string(int64_t(t) + 1) +
                 " but the file has " + std::to_string(uvCount);
      return false;
    }
  }
  const size_t normalCount = attrib.normals.size() / 3;
  for (size_t k = 0; k < n && *allNormals; ++k) {
    int t = corners[k].normal_index;
    if (t < 0) *allNormals = false;  // a face without vn: the geometric normal for the mesh
    else if (size_t(t) >= normalCount) {
      *problem = (face < faceLines.size() ? "line " + std::to_string(faceLines[face]) + ": " : std::string()) + "face " +
                 std::to_string(face + 1) + " uses normal " + std::to_string(int64_t(t) + 1) +
                 " but the file has " + std::to_string(normalCount);
      return false;
    }
  }
  auto normal = [&](const tinyobj::index_t& c) {
    const size_t i = 3 * size_t(c.normal_index);
    return Vec3f{float(attrib.normals[i]), float(attrib.normals[i + 1]), float(attrib.normals[i + 2])};
  };
  auto uv = [&](const tinyobj::index_t& c) {
    return Vec2f{float(attrib.texcoords[2 * size_t(c.texcoord_index)]), float(attrib.texcoords[2 * size_t(c.texcoord_index) + 1])};
  };
  for (size_t k = 1; k + 1 < n; ++k) {
    if (*allUv) mesh->uvs.insert(mesh->uvs.end(), {uv(corners[0]), uv(corners[k]), uv(corners[k + 1])});
    if (*allNormals) mesh->normals.insert(mesh->normals.end(), {normal(corners[0]), normal(corners[k]), normal(corners[k + 1])});
    mesh->indices.push_back(uint32_t(corners[0].vertex_index));
    mesh->indices.push_back(uint32_t(corners[k].vertex_index));
    mesh->indices.push_back(uint32_t(corners[k + 1].vertex_index));
  }
  return true;
}

bool collectVertices(const tinyobj::attrib_t& attrib, ObjMesh* mesh, std::string* problem) {
  size_t count = attrib.vertices.size() / 3;
  mesh->vertices.resize(count);
  for (size_t i = 0; i < count; ++i) {
    Vec3f p{float(attrib.vertices[3 * i]), float(attrib.vertices[3 * i + 1]), float(attrib.vertices[3 * i + 2])};
    if (!isFinite(p)) {
      *problem = "vertex " + std::to_string(i + 1) + " is not finite";
      return false;
    }
    mesh->vertices[i] = p;
  }
  return true;
}

bool collectFaces(const std::vector<tinyobj::shape_t>& shapes, const tinyobj::attrib_t& attrib, ObjMesh* mesh,
                  const std::vector<size_t>& faceLines, std::string* problem) {
  size_t face = 0;
  bool allUv = true, allNormals = true;
  for (const auto& shape : shapes) {
    size_t offset = 0;
    for (size_t n : shape.mesh.num_face_vertices) {
      if (!addPolygon(&shape.mesh.indices[offset], n, face++, mesh->vertices.size(), mesh, faceLines, problem, attrib,
                      &allUv, &allNormals))
        return false;
      offset += n;
    }
  }
  if (!allUv || mesh->uvs.size() != mesh->indices.size()) mesh->uvs.clear();
  if (!allNormals || mesh->normals.size() != mesh->indices.size()) mesh->normals.clear();
  return true;
}

}  // namespace

bool loadObjMesh(const std::string& path, ObjMesh* mesh, std::string* problem) {
  const std::string name = "mesh \"" + path + "\"";
  std::string why;
  if (!readable(path, &why)) {
    *problem = name + " " + why;
    return false;
  }
  std::vector<size_t> faceLines;
  if (!precheck(path, name, &faceLines, problem)) return false;
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // see the file comment
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    *problem = name + ": not a valid OBJ file: " + firstLine(reader.Error());
    return false;
  }
  // tinyobjloader only warns about faces with fewer than 3 corners.
  if (reader.Warning().find("Degenerated face") != std::string::npos) {
    *problem = name + ": has a face with fewer than 3 vertices";
    return false;
  }
  *mesh = ObjMesh{};
  if (!collectVertices(reader.GetAttrib(), mesh, &why) || !collectFaces(reader.GetShapes(), reader.GetAttrib(), mesh, faceLines, &why)) {
    *problem = name + (why.compare(0, 5, "line ") == 0 ? ", " : ": ") + why;
    return false;
  }
  if (mesh->indices.empty()) {
    *problem = name + " has no triangles";
    return false;
  }
  return true;
}

}  // namespace tdpm::scene
