// scene/subdivision.cpp — Loop subdivision with pbrt's rules (see
// subdivision.h for the weights). The mesh is kept as a flat index list;
// each level finds its edges by sorting (min, max) vertex-pair keys, so no
// half-edge structure is needed and the triangles' orientation does not
// matter. Positions are refined in double and stored in float at the end.
#include "scene/subdivision.h"

#include <algorithm>
#include <numeric>

#include "core/error.h"

namespace tdpm::scene {
namespace {

constexpr uint32_t kNone = 0xffffffffu;

struct D3 {
  double x = 0, y = 0, z = 0;
};
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator*(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }

uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

// The edges of one level: per edge its end points and its opposite corners
// (opp[1] == kNone on a boundary), per face corner k the edge k -> k+1.
struct Edges {
  std::vector<uint32_t> a, b, opp0, opp1;
  std::vector<uint32_t> ofCorner;
  bool tooManyFaces = false;  // some edge has three or more triangles
};

Edges findEdges(const std::vector<uint32_t>& idx) {
  const size_t corners = idx.size();
  std::vector<std::pair<uint64_t, uint32_t>> keyed(corners);
  for (size_t c = 0; c < corners; ++c) {
    size_t f = c / 3, k = c % 3;
    keyed[c] = {edgeKey(idx[c], idx[3 * f + (k + 1) % 3]), uint32_t(c)};
  }
  std::sort(keyed.begin(), keyed.end());
  Edges e;
  e.ofCorner.assign(corners, kNone);
  for (size_t i = 0; i < corners;) {
    size_t j = i;
    while (j < corners && keyed[j].first == keyed[i].first) ++j;
    if (j - i > 2) e.tooManyFaces = true;
    uint32_t id = uint32_t(e.a.size());
    uint64_t key = keyed[i].first;
    e.a.push_back(uint32_t(key >> 32));
    e.b.push_back(uint32_t(key & 0xffffffffu));
    uint32_t opp[2] = {kNone, kNone};
    for (size_t m = i; m < j; ++m) {
      uint32_t c = keyed[m].second;
      e.ofCorner[c] = id;
      if (m - i < 2) opp[m - i] = idx[3 * (c / 3) + (c % 3 + 2) % 3];
    }
    e.opp0.push_back(opp[0]);
    e.opp1.push_back(opp[1]);
    i = j;
  }
  return e;
}

// Per vertex: valence (neighbour count), the sum of its neighbours and its
// boundary neighbours (two for a boundary vertex of a manifold mesh).
struct Rings {
  std::vector<uint32_t> valence, boundaryCount;
  std::vector<D3> sum;
  std::vector<uint32_t> b0, b1;
};

Rings findRings(const std::vector<D3>& P, const Edges& e) {
  Rings r;
  const size_t n = P.size();
  r.valence.assign(n, 0);
  r.boundaryCount.assign(n, 0);
  r.sum.assign(n, D3{});
  r.b0.assign(n, kNone);
  r.b1.assign(n, kNone);
  auto addBoundary = [&](uint32_t v, uint32_t w) {
    (r.boundaryCount[v]++ == 0 ? r.b0[v] : r.b1[v]) = w;
  };
  for (size_t i = 0; i < e.a.size(); ++i) {
    uint32_t a = e.a[i], b = e.b[i];
    ++r.valence[a];
    ++r.valence[b];
    r.sum[a] = r.sum[a] + P[b];
    r.sum[b] = r.sum[b] + P[a];
    if (e.opp1[i] == kNone) {
      addBoundary(a, b);
      addBoundary(b, a);
    }
  }
  return r;
}

double beta(uint32_t n) { return n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * n); }
double limitGamma(uint32_t n) { return 1.0 / (n + 3.0 / (8.0 * beta(n))); }

// Interior: (1 - n w) v + w sum(ring); boundary: (1 - 2 w) v + w (b0 + b1).
D3 weighted(const std::vector<D3>& P, const Rings& r, uint32_t v, double interiorW, double boundaryW) {
  uint32_t n = r.valence[v];
  if (n == 0) return P[v];  // a vertex no triangle uses stays where it is
  if (r.boundaryCount[v] == 0) return (1.0 - n * interiorW) * P[v] + interiorW * r.sum[v];
  return (1.0 - 2.0 * boundaryW) * P[v] + boundaryW * (P[r.b0[v]] + P[r.b1[v]]);
}

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(uint32_t x, uint32_t y) { parent[find(x)] = find(y); }
};

}  // namespace

uint64_t loopTriangleCount(uint64_t triangles, int levels) {
  uint64_t n = triangles;
  for (int i = 0; i < levels && n != 0; ++i) {
    if (n > UINT64_MAX / 4) return UINT64_MAX;
    n *= 4;
  }
  return n;
}

std::string loopTopologyProblem(const std::vector<uint32_t>& idx, size_t vertexCount) {
  for (size_t f = 0; f * 3 < idx.size(); ++f) {
    uint32_t a = idx[3 * f], b = idx[3 * f + 1], c = idx[3 * f + 2];
    if (a == b || b == c || c == a)
      return "triangle " + std::to_string(f) + " repeats a vertex (" + std::to_string(a) + ", " + std::to_string(b) + ", " +
             std::to_string(c) + ")";
  }
  Edges e = findEdges(idx);
  if (e.tooManyFaces) {
    std::vector<uint32_t> count(e.a.size(), 0);
    for (uint32_t id : e.ofCorner) ++count[id];
    for (size_t i = 0; i < count.size(); ++i)
      if (count[i] > 2)
        return "the edge between vertices " + std::to_string(e.a[i]) + " and " + std::to_string(e.b[i]) + " is shared by " +
               std::to_string(count[i]) + " triangles (Loop subdivision needs a manifold mesh: at most two)";
  }
  // The triangles around each vertex must form one fan: join the two corners
  // at each end of every interior edge, then count the groups per vertex.
  UnionFind uf(idx.size());
  std::vector<uint32_t> first(e.a.size(), kNone);
  for (size_t c = 0; c < idx.size(); ++c) {
    uint32_t id = e.ofCorner[c];
    if (first[id] == kNone) {
      first[id] = uint32_t(c);
      continue;
    }
    // Corners c and first[id] share this edge; the edge runs from corner k
    // to corner k+1 of each face, in either direction.
    uint32_t d = first[id];
    uint32_t cNext = uint32_t(3 * (c / 3) + (c % 3 + 1) % 3), dNext = uint32_t(3 * (d / 3) + (d % 3 + 1) % 3);
    if (idx[c] == idx[d]) {
      uf.join(c, d);
      uf.join(cNext, dNext);
    } else {
      uf.join(c, dNext);
      uf.join(cNext, d);
    }
  }
  std::vector<uint32_t> root(vertexCount, kNone);
  for (size_t c = 0; c < idx.size(); ++c) {
    uint32_t r = uf.find(uint32_t(c));
    if (root[idx[c]] == kNone) root[idx[c]] = r;
    else if (root[idx[c]] != r)
      return "vertex " + std::to_string(idx[c]) +
             " joins surfaces that touch only there (its triangles form more than one fan; Loop subdivision needs a "
             "manifold mesh)";
  }
  return "";
}

LoopMesh loopSubdivide(const std::vector<Vec3f>& vertices, const std::vector<uint32_t>& indices, int levels,
                       uint64_t maxTriangles) {
  if (levels < 0) throw Error("subdivision levels must be >= 0, got " + std::to_string(levels));
  uint64_t refined = loopTriangleCount(indices.size() / 3, levels);
  if (refined > maxTriangles)
    throw Error(std::to_string(levels) + " levels of Loop subdivision of " + std::to_string(indices.size() / 3) +
                " triangles give " + (refined == UINT64_MAX ? std::string("more than 2^64") : std::to_string(refined)) +
                " triangles, more than the limit of " + std::to_string(maxTriangles));
  std::string problem = loopTopologyProblem(indices, vertices.size());
  if (!problem.empty()) throw Error(problem);

  std::vector<D3> P(vertices.size());
  for (size_t i = 0; i < P.size(); ++i) P[i] = {vertices[i].x, vertices[i].y, vertices[i].z};
  std::vector<uint32_t> idx = indices;
  for (int level = 0; level < levels; ++level) {
    Edges e = findEdges(idx);
    Rings r = findRings(P, e);
    const uint32_t nv = uint32_t(P.size());
    std::vector<D3> next(P.size() + e.a.size());
    for (uint32_t v = 0; v < nv; ++v) next[v] = weighted(P, r, v, beta(r.valence[v]), 1.0 / 8.0);
    for (size_t i = 0; i < e.a.size(); ++i) {
      D3 ends = P[e.a[i]] + P[e.b[i]];
      next[nv + i] = e.opp1[i] == kNone ? 0.5 * ends : (3.0 / 8.0) * ends + (1.0 / 8.0) * (P[e.opp0[i]] + P[e.opp1[i]]);
    }
    std::vector<uint32_t> children;
    children.reserve(idx.size() * 4);
    for (size_t f = 0; f * 3 < idx.size(); ++f) {
      uint32_t v0 = idx[3 * f], v1 = idx[3 * f + 1], v2 = idx[3 * f + 2];
      uint32_t m0 = nv + e.ofCorner[3 * f], m1 = nv + e.ofCorner[3 * f + 1], m2 = nv + e.ofCorner[3 * f + 2];
      children.insert(children.end(), {v0, m0, m2, m0, v1, m1, m2, m1, v2, m0, m1, m2});
    }
    P.swap(next);
    idx.swap(children);
  }
  // Move every vertex to its limit position.
  Edges e = findEdges(idx);
  Rings r = findRings(P, e);
  LoopMesh out;
  out.vertices.resize(P.size());
  for (uint32_t v = 0; v < P.size(); ++v) {
    D3 p = weighted(P, r, v, limitGamma(r.valence[v]), 1.0 / 5.0);
    out.vertices[v] = {float(p.x), float(p.y), float(p.z)};
  }
  out.indices = std::move(idx);
  return out;
}

}  // namespace tdpm::scene
