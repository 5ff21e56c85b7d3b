// scene/mesh_obj.h — owns reading a Wavefront OBJ file into a validated
// triangle list (tinyobjloader underneath). The scene parser calls it for
// "mesh" shapes and adds the file/line/JSON-path prefix to any problem.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm::scene {

struct ObjMesh {
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle
  // (u, v) per triangle corner from the faces' vt indices, when every face
  // has them (else empty: the renderer's default per triangle).
  std::vector<Vec2f> uvs;
  // Shading normals per triangle corner from the faces' vn indices, when
  // every face has them (else empty: the geometric normal).
  std::vector<Vec3f> normals;
};

// Loads every face of every group of `path`, triangulated (polygons are
// split; vt texture coordinates and vn normals kept, materials ignored). On failure returns false and sets
// `problem` to a message naming the file, e.g.
//   mesh "meshes/bad.obj": face 3 uses vertex 9 but the file has 4 vertices
bool loadObjMesh(const std::string& path, ObjMesh* mesh, std::string* problem);

}  // namespace tdpm::scene
