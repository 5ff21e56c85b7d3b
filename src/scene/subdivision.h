// scene/subdivision.h — owns Loop subdivision of triangle meshes: the
// scheme pbrt's `loopsubdiv` shape uses (pbrt-v3/v4 loopsubdiv.cpp), with
// its weights and its boundary rules, so that a converted pbrt scene gives
// the triangles pbrt intersects. Used by scene/build.cpp (refinement), by
// scene/parse.cpp and the pbrt import (validation and the budget, before
// anything is built). Positions only: tdpm shades with geometric normals.
//
// Why not OpenSubdiv (Debian libosd-dev 3.5): its Loop scheme uses Loop's
// original vertex weight (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n and the
// true B-spline boundary limit (1/6, 4/6, 1/6), where pbrt uses Warren's
// 3 / (8 n) (3/16 for n = 3) and a boundary limit of (1/5, 3/5, 1/5). The
// two agree only at regular vertices, so OpenSubdiv would not give pbrt's
// surface (third_party_notes/opensubdiv.md).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm::scene {

// The rules, as pbrt writes them (n: valence = number of neighbours):
// - odd (edge) vertex: interior edge 3/8 (a + b) + 1/8 (c + d), c and d the
//   opposite corners; boundary edge 1/2 (a + b);
// - even vertex: interior (1 - n beta) v + beta sum(ring), beta = 3/16 for
//   n = 3, else 3 / (8 n); boundary 3/4 v + 1/8 (b0 + b1), b0 and b1 its two
//   boundary neighbours (boundary edges are cubic B-spline curves);
// - after the last level every vertex moves to its limit position: interior
//   (1 - n g) v + g sum(ring), g = 1 / (n + 3 / (8 beta)) (Loop's thesis,
//   exact for any beta); boundary 3/5 v + 1/5 (b0 + b1) (pbrt's weight).
// levels 0 is the control triangles with their vertices at the limit, as in pbrt.
struct LoopMesh {
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle; each child keeps its parent's winding
};

// The triangle count after `levels` levels (4^levels x faces), saturated at
// UINT64_MAX; levels must be >= 0.
uint64_t loopTriangleCount(uint64_t triangles, int levels);

// Empty when `indices` (3 per triangle, each < vertexCount) is a mesh Loop's
// rules apply to, else the problem: a triangle with a repeated corner, an
// edge shared by more than two triangles, or a vertex whose triangles do not
// form a single fan (two surfaces touching at a point). Orientation may be
// inconsistent: the rules do not depend on it.
std::string loopTopologyProblem(const std::vector<uint32_t>& indices, size_t vertexCount);

// Refines `levels` times and moves the vertices to the limit surface.
// Throws tdpm::Error (no location: callers add it) for a topology problem,
// levels < 0, or more than maxTriangles refined triangles.
LoopMesh loopSubdivide(const std::vector<Vec3f>& vertices, const std::vector<uint32_t>& indices, int levels,
                       uint64_t maxTriangles);

}  // namespace tdpm::scene
