// import/ply_reader.h — a small strict reader for PLY triangle meshes (ASCII
// and binary little/big endian), for pbrt's "plymesh". Debian 12 packages no
// C/C++ PLY library, so this is ours. Hostile input is expected: counts are
// checked against the file size before anything is allocated, every index
// against the vertex count, every coordinate for finiteness; a truncated
// or malformed file is an error naming the file and the problem.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm::pbrt {

struct PlyMesh {
  std::vector<Vec3f> vertices;
  std::vector<Vec2f> uvs;                    // per vertex (u/v, s/t), or empty
  std::vector<Vec3f> normals;                // per vertex (nx, ny, nz), or empty
  std::vector<uint32_t> triangles;           // 3 per triangle
  std::vector<uint32_t> quads;               // 4 per quad, in the file's corner order
  std::vector<std::string> ignoredProperties;  // e.g. nx, u: read but not used
};

// Parses PLY bytes; throws tdpm::Error "<name>: <problem>".
PlyMesh parsePly(const std::string& bytes, const std::string& name);
// Reads and parses a file.
PlyMesh readPly(const std::string& path);

}  // namespace tdpm::pbrt
