// scene/mesh_obj.cpp — OBJ loading for mesh shapes (see mesh_obj.h).
// tinyobjloader's own triangulation silently drops faces whose indices are
// out of range, so we read raw polygons, check every index ourselves and
// fan-triangulate (exact for triangles and convex polygons).
#include "scene/mesh_obj.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <tiny_obj_loader.h>

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
  if (!std::ifstream(path, std::ios::binary)) { *why = "cannot be opened for reading"; return false; }
  return true;
}

// Appends one polygon's triangles; false (with `problem`) on a bad index.
bool addPolygon(const tinyobj::index_t* corners, size_t n, size_t face, size_t vertexCount, ObjMesh* mesh,
                std::string* problem) {
  for (size_t k = 0; k < n; ++k) {
    int v = corners[k].vertex_index;
    if (v < 0 || size_t(v) >= vertexCount) {
      // Report 1-based OBJ indices; negative (relative) ones resolve below 0.
      *problem = "face " + std::to_string(face + 1) + " uses vertex " + std::to_string(int64_t(v) + 1) +
                 " but the file has " + std::to_string(vertexCount) + " vertices";
      return false;
    }
  }
  for (size_t k = 1; k + 1 < n; ++k) {
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

bool collectFaces(const std::vector<tinyobj::shape_t>& shapes, ObjMesh* mesh, std::string* problem) {
  size_t face = 0;
  for (const auto& shape : shapes) {
    size_t offset = 0;
    for (size_t n : shape.mesh.num_face_vertices) {
      if (!addPolygon(&shape.mesh.indices[offset], n, face++, mesh->vertices.size(), mesh, problem)) return false;
      offset += n;
    }
  }
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
  if (!collectVertices(reader.GetAttrib(), mesh, &why) || !collectFaces(reader.GetShapes(), mesh, &why)) {
    *problem = name + ": " + why;
    return false;
  }
  if (mesh->indices.empty()) {
    *problem = name + " has no triangles";
    return false;
  }
  return true;
}

}  // namespace tdpm::scene
