// tests/test_subdivision.cpp — Loop subdivision (scene/subdivision.*) with
// pbrt's rules: limit positions against Loop's closed form, a closed mesh
// stays closed and its limit points do not move between levels, boundary
// curves depend on the boundary alone, triangle counts, the budget and the
// topology errors; the JSON "subdivision" key and pbrt's loopsubdiv shape
// (import, render, convert round trip).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include <unistd.h>

#include "core/error.h"
#include "error_capture.h"
#include "import/pbrt_import.h"
#include "render/renderer.h"
#include "scene/json_writer.h"
#include "scene/limits.h"
#include "scene/parse.h"
#include "scene/scene.h"
#include "scene/subdivision.h"
#include "render_fixtures.h"

using namespace tdpm;

namespace {

constexpr uint64_t kBudget = scene::limits::kMaxSubdividedTriangles;

// A fan: vertex 0 at the centre, n ring vertices around it (z perturbed by a
// fixed seed), n triangles. The centre is an interior vertex of valence n.
scene::LoopMesh fan(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> z(-0.3f, 0.3f);
  scene::LoopMesh m;
  m.vertices.push_back({0.1f, -0.05f, z(rng)});
  for (int i = 0; i < n; ++i) {
    float a = 2.0f * 3.14159265f * float(i) / float(n);
    m.vertices.push_back({std::cos(a) * (1.0f + 0.2f * z(rng)), std::sin(a), z(rng)});
  }
  for (int i = 0; i < n; ++i) m.indices.insert(m.indices.end(), {0u, uint32_t(1 + i), uint32_t(1 + (i + 1) % n)});
  return m;
}

scene::LoopMesh octahedron() {
  scene::LoopMesh m;
  m.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return m;
}

// An (n+1) x (n+1) grid of unit squares in the x-y plane, each split along
// a diagonal; `interiorZ` lifts the interior vertices (the boundary stays flat).
scene::LoopMesh grid(int n, float interiorZ, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  scene::LoopMesh m;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      bool boundary = x == 0 || y == 0 || x == n || y == n;
      m.vertices.push_back({float(x), float(y), boundary ? 0.0f : interiorZ * u(rng)});
    }
  auto at = [n](int x, int y) { return uint32_t(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      m.indices.insert(m.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
  return m;
}

double gap(Vec3f a, Vec3f b) { return std::sqrt(double(dot(a - b, a - b))); }

bool sameVertices(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z) return false;
  return true;
}

std::string tempDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("tdpm_subdiv_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

void writeFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

using test::sameImage;
double sum(const Film& f) { return test::imageSum(f); }

Film renderDesc(const scene::SceneDescription& d) {
  return test::renderOnce(d, test::smallRenderOptions(RenderMethod::PathTrace, 2, 3, 11));
}

}  // namespace

// Loop's thesis (1987, section 3.4): around an interior vertex c of valence
// n with ring r_i, one level maps (c, r_i) by c' = (1 - n b) c + b sum r_i,
// r_i' = 3/8 c + 3/8 r_i + 1/8 (r_{i-1} + r_{i+1}). The limit is the left
// eigenvector of eigenvalue 1, (l_c, l_r, ..., l_r): l_c b = 3/8 l_r, so
// l_r / l_c = 8 b / 3 and, normalised, l_r = g = 1 / (n + 3 / (8 b)). The
// 1-ring maps onto itself, so the limit of the centre is the same after any
// number of levels. pbrt's b is 3/16 for n = 3, else 3 / (8 n) (1/16 at the
// regular valence 6, where g = 1/12 and the limit is c/2 + sum r_i / 12).
TEST_CASE("loop subdivision: an interior vertex's limit is Loop's closed form, at every level") {
  for (int n = 3; n <= 9; ++n) {
    scene::LoopMesh m = fan(n, 100 + n);
    double b = n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * n);
    double g = 1.0 / (n + 3.0 / (8.0 * b));
    if (n == 6) CHECK(g == doctest::Approx(1.0 / 12.0));
    double ex = (1 - n * g) * m.vertices[0].x, ey = (1 - n * g) * m.vertices[0].y, ez = (1 - n * g) * m.vertices[0].z;
    for (int i = 1; i <= n; ++i) {
      ex += g * m.vertices[i].x;
      ey += g * m.vertices[i].y;
      ez += g * m.vertices[i].z;
    }
    for (int levels = 0; levels <= 4; ++levels) {
      CAPTURE(n);
      CAPTURE(levels);
      scene::LoopMesh r = scene::loopSubdivide(m.vertices, m.indices, levels, kBudget);
      Vec3f c = r.vertices[0];  // even vertices keep their index
      CHECK(gap(c, Vec3f(float(ex), float(ey), float(ez))) < 2e-6);
    }
  }
}

TEST_CASE("loop subdivision: a flat regular patch stays flat") {
  scene::LoopMesh m = grid(4, 0.0f, 1);
  scene::LoopMesh r = scene::loopSubdivide(m.vertices, m.indices, 3, kBudget);
  for (Vec3f v : r.vertices) CHECK(v.z == 0.0f);
}

TEST_CASE("loop subdivision: a closed octahedron stays a closed manifold and its limit points do not move") {
  scene::LoopMesh m = octahedron();
  scene::LoopMesh l4 = scene::loopSubdivide(m.vertices, m.indices, 4, kBudget);
  scene::LoopMesh l5 = scene::loopSubdivide(m.vertices, m.indices, 5, kBudget);
  for (const scene::LoopMesh* r : {&l4, &l5}) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t i = 0; i < r->indices.size(); i += 3)
      for (int k = 0; k < 3; ++k) {
        uint32_t a = r->indices[i + k], b = r->indices[i + (k + 1) % 3];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    bool everyEdgeTwice = true;
    for (const auto& [e, count] : edges) everyEdgeTwice = everyEdgeTwice && count == 2;
    CHECK(everyEdgeTwice);
    // Euler characteristic of a sphere.
    CHECK(int64_t(r->vertices.size()) - int64_t(edges.size()) + int64_t(r->indices.size() / 3) == 2);
    CHECK(scene::loopTopologyProblem(r->indices, r->vertices.size()).empty());
  }
  // Level 4's vertices are level 5's first ones: each is at its limit point
  // already, so refining once more must not move it.
  REQUIRE(l5.vertices.size() > l4.vertices.size());
  double worst = 0;
  for (size_t i = 0; i < l4.vertices.size(); ++i) worst = std::max(worst, gap(l4.vertices[i], l5.vertices[i]));
  CHECK(worst < 1e-6);
  // The corners have valence 4 and their ring sums to zero: g = 1/8, limit
  // (1 - 4/8) v = v / 2. Every limit point lies within the control hull.
  CHECK(gap(l5.vertices[0], {0.5f, 0, 0}) < 1e-6);
  CHECK(gap(l5.vertices[5], {0, 0, -0.5f}) < 1e-6);
  for (Vec3f v : l5.vertices) CHECK(std::fabs(v.x) + std::fabs(v.y) + std::fabs(v.z) <= 1.0f + 1e-6f);
}

// pbrt's boundary rules use only boundary vertices: boundary edges are cubic
// B-spline curves of the boundary polygon, whatever the interior does.
TEST_CASE("loop subdivision: boundary vertices stay on the boundary curve") {
  scene::LoopMesh flat = grid(4, 0.0f, 1), bumpy = grid(4, 0.8f, 2);
  for (int levels = 0; levels <= 3; ++levels) {
    CAPTURE(levels);
    scene::LoopMesh a = scene::loopSubdivide(flat.vertices, flat.indices, levels, kBudget);
    scene::LoopMesh b = scene::loopSubdivide(bumpy.vertices, bumpy.indices, levels, kBudget);
    REQUIRE(a.vertices.size() == b.vertices.size());
    // Boundary vertices: the ends of edges with one triangle.
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t i = 0; i < a.indices.size(); i += 3)
      for (int k = 0; k < 3; ++k) {
        uint32_t p = a.indices[i + k], q = a.indices[i + (k + 1) % 3];
        ++edges[{std::min(p, q), std::max(p, q)}];
      }
    std::vector<bool> boundary(a.vertices.size(), false);
    for (const auto& [e, count] : edges)
      if (count == 1) boundary[e.first] = boundary[e.second] = true;
    int onBoundary = 0;
    for (size_t i = 0; i < a.vertices.size(); ++i) {
      if (!boundary[i]) continue;
      ++onBoundary;
      CHECK(b.vertices[i].x == a.vertices[i].x);  // the same point with a different interior
      CHECK(b.vertices[i].y == a.vertices[i].y);
      CHECK(b.vertices[i].z == 0.0f);
      // The boundary is a closed curve inside the square, touching it only
      // along the straight runs.
      CHECK(a.vertices[i].x >= 0.0f);
      CHECK(a.vertices[i].y >= 0.0f);
    }
    CHECK(onBoundary == 16 << levels);  // 16 boundary edges, each split in two per level
  }
  // The corner (0, 0) with boundary neighbours (1, 0) and (0, 1), at level 0:
  // pbrt's boundary limit 3/5 v + 1/5 (b0 + b1).
  scene::LoopMesh r = scene::loopSubdivide(flat.vertices, flat.indices, 0, kBudget);
  CHECK(gap(r.vertices[0], {0.2f, 0.2f, 0}) < 1e-6);
  // One level first: the corner's even rule 3/4 v + 1/8 (b0 + b1) gives
  // (1/8, 1/8), its new boundary neighbours are the edge midpoints (1/2, 0)
  // and (0, 1/2); the limit 3/5 (1/8, 1/8) + 1/5 (1/2, 1/2) = (0.175, 0.175).
  scene::LoopMesh r1 = scene::loopSubdivide(flat.vertices, flat.indices, 1, kBudget);
  CHECK(gap(r1.vertices[0], {0.175f, 0.175f, 0}) < 1e-6);
  // A straight, uniform boundary keeps its points in place at every level.
  for (int levels = 0; levels <= 3; ++levels)
    CHECK(gap(scene::loopSubdivide(flat.vertices, flat.indices, levels, kBudget).vertices[2], {2, 0, 0}) < 1e-6);
}

TEST_CASE("loop subdivision: 4^levels triangles per control triangle, orientation kept per face") {
  scene::LoopMesh m = octahedron();
  // Flip one triangle: Loop's rules do not depend on orientation.
  scene::LoopMesh flipped = m;
  std::swap(flipped.indices[1], flipped.indices[2]);
  for (int levels = 0; levels <= 4; ++levels) {
    scene::LoopMesh r = scene::loopSubdivide(m.vertices, m.indices, levels, kBudget);
    scene::LoopMesh f = scene::loopSubdivide(flipped.vertices, flipped.indices, levels, kBudget);
    CHECK(r.indices.size() / 3 == (8u << (2 * levels)));
    CHECK(scene::loopTriangleCount(8, levels) == (8u << (2 * levels)));
    CHECK(sameVertices(f.vertices, r.vertices));
    // Outward normals stay outward on the unflipped mesh.
    bool outward = true;
    for (size_t i = 0; i < r.indices.size(); i += 3) {
      Vec3f a = r.vertices[r.indices[i]], b = r.vertices[r.indices[i + 1]], c = r.vertices[r.indices[i + 2]];
      outward = outward && dot(cross(b - a, c - a), a + b + c) > 0;
    }
    CHECK(outward);
  }
  CHECK(scene::loopTriangleCount(3, 40) == UINT64_MAX);
}

TEST_CASE("loop subdivision: the budget, negative levels and non-manifold meshes are refused") {
  scene::LoopMesh m = octahedron();
  // 8 x 4^11 = 33.5M > 2^24.
  std::string e = test::errorMessageOf([&] { scene::loopSubdivide(m.vertices, m.indices, 11, kBudget); });
  CHECK(e.find("33554432 triangles") != std::string::npos);
  CHECK(test::errorMessageOf([&] { scene::loopSubdivide(m.vertices, m.indices, -1, kBudget); }).find(">= 0") !=
        std::string::npos);
  // Three triangles on one edge.
  std::vector<uint32_t> fin = {0, 1, 2, 0, 1, 3, 0, 1, 4};
  CHECK(scene::loopTopologyProblem(fin, 5).find("shared by 3 triangles") != std::string::npos);
  // Two fans touching at vertex 0 (a bow tie).
  std::vector<uint32_t> bowtie = {0, 1, 2, 0, 3, 4};
  CHECK(scene::loopTopologyProblem(bowtie, 5).find("vertex 0") != std::string::npos);
  CHECK(scene::loopTopologyProblem({0, 0, 1}, 2).find("repeats a vertex") != std::string::npos);
  CHECK(scene::loopTopologyProblem(m.indices, 6).empty());
}

namespace {

const char* kOctaObj =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

std::string jsonScene(const std::string& subdivision, const std::string& extra = "") {
  return R"({"camera": {"position": [0, 0, 4], "target": [0, 0, 0], "fov": 40, "resolution": [16, 16]},
  "materials": {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]}},
  "objects": [{"name": "blob", "shape": {"type": "mesh", "file": "octa.obj")" +
         subdivision + R"(}, "material": "white")" + extra + R"(}],
  "lights": [{"type": "point", "position": [1, 2, 4], "power": [300, 300, 300]}]})";
}

}  // namespace

TEST_CASE("scene format: a mesh's \"subdivision\" key refines it; bad values are located errors") {
  std::string dir = tempDir("json");
  writeFile(dir + "/octa.obj", kOctaObj);
  auto load = [&](const std::string& text) {
    writeFile(dir + "/s.json", text);
    return scene::loadScene(dir + "/s.json");
  };
  auto error = [&](const std::string& text) { return test::errorMessageOf([&] { load(text); }); };
  scene::SceneDescription d = load(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 2})"));
  REQUIRE(d.objects.size() == 1);
  CHECK(d.objects[0].shape.loopLevels == 2);
  CHECK(d.objects[0].shape.vertices.size() == 6);  // the control mesh; Scene::build refines
  scene::SceneDescription plain = load(jsonScene(""));
  CHECK(plain.objects[0].shape.loopLevels == -1);
  Film a = renderDesc(d), b = renderDesc(plain);
  CHECK(sum(a) > 0);
  CHECK(!sameImage(a, b));  // the smooth blob is smaller than the octahedron it refines
  // Moving, as any mesh.
  scene::SceneDescription moving = load(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 1})",
                                                  R"(, "motion": [{"time": 0, "translate": [0, 0, 0]}, {"time": 1, "translate": [0.3, 0, 0]}])"));
  CHECK(moving.objects[0].motion.times.size() == 2);
  CHECK(sum(renderDesc(moving)) > 0);

  std::string e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 12})"));
  CHECK(e.find("s.json") != std::string::npos);
  CHECK(e.find("levels") != std::string::npos);
  CHECK(e.find("134217728 triangles") != std::string::npos);
  e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": -1})"));
  CHECK(e.find("levels must be >= 0") != std::string::npos);
  e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 1.5})"));
  CHECK(e.find("levels") != std::string::npos);
  e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 1000})"));
  CHECK(e.find("more than the limit") != std::string::npos);
  e = error(jsonScene(R"(, "subdivision": {"scheme": "catmull-clark", "levels": 1})"));
  CHECK(e.find("scheme") != std::string::npos);
  e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 1, "crease": 2})"));
  CHECK(e.find("crease") != std::string::npos);
  writeFile(dir + "/octa.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 1 2 4\nf 1 2 5\n");
  e = error(jsonScene(R"(, "subdivision": {"scheme": "loop", "levels": 1})"));
  CHECK(e.find("shared by 3 triangles") != std::string::npos);
  std::filesystem::remove_all(dir);
}

namespace {

const char* kPbrtLoop = R"(
LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "image" "integer xresolution" 16 "integer yresolution" 16
Sampler "random" "integer pixelsamples" 2
WorldBegin
LightSource "point" "rgb I" [30 30 30] "point3 from" [1 2 4]
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "loopsubdiv" "integer levels" LEVELS
  "point3 P" [1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1]
  "integer indices" [0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5]
)";

std::string withLevels(const std::string& levels) {
  std::string t = kPbrtLoop;
  return t.replace(t.find("LEVELS"), 6, levels);
}

}  // namespace

TEST_CASE("pbrt loopsubdiv: imports, renders as its refined triangles, converts to the JSON key") {
  pbrt::ImportResult imp = pbrt::importPbrtText(withLevels("2"), "dir/loop.pbrt");
  const scene::SceneDescription& d = imp.scene;
  REQUIRE(d.objects.size() == 1);
  CHECK(d.objects[0].shape.loopLevels == 2);
  Film a = renderDesc(d);
  CHECK(sum(a) > 0);
  // The same pixels as a trianglemesh holding the refined triangles.
  scene::LoopMesh r = scene::loopSubdivide(d.objects[0].shape.vertices, d.objects[0].shape.indices, 2, kBudget);
  scene::SceneDescription refined = d;
  refined.objects[0].shape.vertices = r.vertices;
  refined.objects[0].shape.indices = r.indices;
  refined.objects[0].shape.loopLevels = -1;
  CHECK(sameImage(a, renderDesc(refined)));
  // tdpm convert: control mesh + key; the JSON renders the same pixels.
  std::string dir = tempDir("convert");
  pbrt::writeSceneJson(d, dir + "/loop.json");
  std::ifstream in(dir + "/loop.json");
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(json.find("\"subdivision\"") != std::string::npos);
  scene::SceneDescription back = scene::loadScene(dir + "/loop.json");
  CHECK(back.objects[0].shape.loopLevels == 2);
  CHECK(sameVertices(back.objects[0].shape.vertices, d.objects[0].shape.vertices));
  CHECK(back.objects[0].shape.indices == d.objects[0].shape.indices);
  CHECK(sameImage(a, renderDesc(back)));
  std::filesystem::remove_all(dir);
  // Default levels: 3.
  std::string noLevels = withLevels("3");
  noLevels.replace(noLevels.find("\"integer levels\" 3"), 18, "");
  CHECK(pbrt::importPbrtText(noLevels, "dir/loop.pbrt").scene.objects[0].shape.loopLevels == 3);
  // pbrt-v3's older spelling.
  std::string nlevels = withLevels("2");
  nlevels.replace(nlevels.find("\"integer levels\""), 16, "\"integer nlevels\"");
  CHECK(pbrt::importPbrtText(nlevels, "dir/loop.pbrt").scene.objects[0].shape.loopLevels == 2);
}

TEST_CASE("pbrt loopsubdiv: negative levels, the budget and non-manifold meshes are located errors") {
  auto error = [](const std::string& text) {
    return test::errorMessageOf([&] { pbrt::importPbrtText(text, "dir/loop.pbrt"); });
  };
  std::string e = error(withLevels("-1"));
  CHECK(e.find("dir/loop.pbrt:9") != std::string::npos);
  CHECK(e.find("levels must be >= 0") != std::string::npos);
  e = error(withLevels("12"));
  CHECK(e.find("dir/loop.pbrt:9") != std::string::npos);
  CHECK(e.find("134217728 triangles") != std::string::npos);
  std::string fin = withLevels("1");
  fin.replace(fin.find("[0 2 4 2 1 4"), 0, "[0 2 4 0 2 5 0 2 1 ] #");
  e = error(fin);
  CHECK(e.find("dir/loop.pbrt") != std::string::npos);
  CHECK(e.find("shared by 3 triangles") != std::string::npos);
}
