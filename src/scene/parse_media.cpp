// scene/parse_media.cpp — the media keys of a scene file (see parse_media.h
// and docs/scene-format.md "Media"): named homogeneous and grid media, the
// exterior medium and which medium the camera, the lights and the objects'
// two sides are in. Kept apart from parse.cpp so that file stays about the
// surfaces.
#include "scene/parse_media.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <utility>

#include "core/memory.h"
#include "media/grid_file.h"
#include "scene/limits.h"

namespace tdpm::scene::detail {

namespace {

std::string fmt(double v) { return formatNumber(v); }

Node memberOrSelf(const Node& object, const char* key) { return object.has(key) ? object.member(key) : object; }

// Finite and >= 0 per channel (Node::color's checks).
Rgb readCoefficient(const Node& n) { return n.color(); }

float readScaleFactor(const Node& n) {
  float v = n.number();
  n.require(v >= 0, "scale must be non-negative, got " + fmt(v));
  return v;
}

float readAsymmetry(const Node& n) {
  float g = n.number();
  n.require(g > -1 && g < 1, "g (Henyey-Greenstein asymmetry) must be in (-1, 1), got " + fmt(g));
  return g;
}

Bounds3f readGridBounds(const Node& n) {
  size_t count = n.arraySize("2 corners [[x0, y0, z0], [x1, y1, z1]]");
  n.require(count == 2, "expected 2 corners [[x0, y0, z0], [x1, y1, z1]], got " + std::to_string(count) + " elements");
  Vec3f lo = n.element(0).vec3(), hi = n.element(1).vec3();
  const float m = limits::kMaxCoordinate;
  for (Vec3f p : {lo, hi})
    n.require(std::fabs(p.x) <= m && std::fabs(p.y) <= m && std::fabs(p.z) <= m,
              "corner " + formatVec(p) + " is out of range: coordinates must be within +-" + fmt(m) + " m");
  n.require(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z,
            "the first corner must be below the second on every axis, got " + formatVec(lo) + " and " + formatVec(hi));
  return {lo, hi};
}

// [nx, ny, nz], each >= 1, and the dense grid within maxBytes: checked
// before the density array is read or anything is allocated.
void readResolution(const Node& n, DensityGridDesc* g, uint64_t maxBytes) {
  size_t count = n.arraySize("3 integers [nx, ny, nz]");
  n.require(count == 3, "expected 3 integers [nx, ny, nz], got " + std::to_string(count) + " elements");
  int64_t r[3];
  for (size_t i = 0; i < 3; ++i) {
    Node e = n.element(i);
    r[i] = e.integer();
    e.require(r[i] >= 1 && r[i] <= limits::kMaxResolution,
              "each resolution must be in [1, " + std::to_string(limits::kMaxResolution) + "], got " + std::to_string(r[i]));
  }
  uint64_t bytes = uint64_t(r[0]) * uint64_t(r[1]) * uint64_t(r[2]) * sizeof(float);
  n.require(bytes <= maxBytes, "the density grid " + std::to_string(r[0]) + " x " + std::to_string(r[1]) + " x " +
                                   std::to_string(r[2]) + " needs " + std::to_string(bytes) + " bytes; at most " +
                                   std::to_string(maxBytes) + " bytes are allowed (scene/limits.h, memory available)");
  g->nx = int(r[0]);
  g->ny = int(r[1]);
  g->nz = int(r[2]);
}

void readDensity(const Node& n, DensityGridDesc* g) {
  size_t want = size_t(g->nx) * size_t(g->ny) * size_t(g->nz);
  size_t count = n.arraySize("density values");
  n.require(count == want, "resolution " + std::to_string(g->nx) + " x " + std::to_string(g->ny) + " x " +
                               std::to_string(g->nz) + " needs " + std::to_string(want) + " density values, got " +
                               std::to_string(count));
  g->density.resize(want);
  for (size_t i = 0; i < want; ++i) {
    Node e = n.element(i);
    float d = e.number();  // finite
    e.require(d >= 0, "density must be non-negative, got " + fmt(d));
    g->density[i] = d;
  }
}

std::string resolvePath(const std::string& file, const std::string& sceneDir) {
  std::filesystem::path p(file);
  if (p.is_absolute() || sceneDir.empty()) return p.lexically_normal().string();
  return (std::filesystem::path(sceneDir) / p).lexically_normal().string();
}

void readGrid(const Node& n, const std::string& sceneDir, MediumDesc* m) {
  DensityGridDesc& g = m->grid;
  bool inlineGrid = n.has("resolution") || n.has("density");
  if (n.has("file") && inlineGrid)
    n.member("file").fail("give either \"file\" or \"resolution\" and \"density\", not both");
  if (!n.has("file") && !inlineGrid)
    n.fail("a grid medium needs \"resolution\" and \"density\" (inline) or \"file\" (an OpenVDB / NanoVDB grid)");
  if (n.has("grid")) {
    Node gn = n.member("grid");
    gn.require(n.has("file"), "\"grid\" names a grid in \"file\"; there is no file");
    g.gridName = gn.string();
    gn.require(!g.gridName.empty(), "grid name must not be empty");
  }
  uint64_t maxBytes = maxDensityGridBytes();
  if (inlineGrid) {
    readResolution(n.required("resolution"), &g, maxBytes);
    readDensity(n.required("density"), &g);
  } else {
    Node f = n.member("file");
    std::string file = f.string();
    f.require(!file.empty(), "file name must not be empty");
    g.file = resolvePath(file, sceneDir);
    media::loadDensityGridFile(g, f.path().empty() ? n.path() : f.path(), maxBytes);
  }
  if (n.has("bounds")) g.bounds = readGridBounds(n.member("bounds"));
  if (n.has("transform")) m->placement = readPlacement(n.member("transform"));
}

MediumDesc readMedium(const Node& n, const std::string& name, const std::string& sceneDir) {
  n.requireObject();
  std::string type = n.required("type").choice({"homogeneous", "grid"}, "medium type");
  MediumDesc m;
  m.name = name;
  if (type == "homogeneous") {
    n.expectObject({"type", "sigma_a", "sigma_s", "scale", "g"});
  } else {
    n.expectObject({"type", "sigma_a", "sigma_s", "scale", "g", "resolution", "density", "file", "grid", "bounds",
                    "transform"});
    m.type = MediumDesc::Type::Grid;
  }
  m.sigmaA = readCoefficient(n.required("sigma_a"));
  m.sigmaS = readCoefficient(n.required("sigma_s"));
  if (n.has("scale")) m.scale = readScaleFactor(n.member("scale"));
  if (n.has("g")) m.g = readAsymmetry(n.member("g"));
  Rgb t = (m.sigmaA + m.sigmaS) * m.scale;
  memberOrSelf(n, "scale").require(std::isfinite(t.r) && std::isfinite(t.g) && std::isfinite(t.b),
                                   "scale x (sigma_a + sigma_s) overflows: " + formatRgb(t));
  if (m.type == MediumDesc::Type::Grid) readGrid(n, sceneDir, &m);
  return m;
}

// A medium name (string) or null (vacuum) -> index or -1.
int32_t resolveMedium(const Node& n, const SceneDescription& scene) {
  if (n.json().is_null()) return -1;
  if (!n.json().is_string()) n.fail("expected a string (a medium name) or null, got " + describeKind(n.json()));
  std::string name = n.string();
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (scene.media[i].name == name) return int32_t(i);
  std::vector<std::string> defined;
  for (const auto& m : scene.media) defined.push_back(m.name);
  n.fail("unknown medium \"" + name + "\"; " +
         (defined.empty() ? std::string("no media are defined (\"media\")") : "defined media: " + joinNames(defined)));
}

}  // namespace

uint64_t maxDensityGridBytes() {
  uint64_t limit = limits::kMaxDensityGridBytes;
  uint64_t available = availableMemoryBytes();
  if (available > 0) limit = std::min(limit, available / 2);
  return limit;
}

void readMedia(const Node& root, const std::string& sceneDir, SceneDescription* scene) {
  if (root.has("media")) {
    root.member("media").forEachMember([&](const std::string& name, const Node& m) {
      m.require(!name.empty(), "medium names must not be empty");
      scene->media.push_back(readMedium(m, name, sceneDir));
    });
  }
  if (root.has("exterior_medium")) scene->exteriorMedium = resolveMedium(root.member("exterior_medium"), *scene);
}

int32_t readMediumKey(const Node& owner, const SceneDescription& scene) {
  if (!owner.has("medium")) return scene.exteriorMedium;
  return resolveMedium(owner.member("medium"), scene);
}

bool shapeIsClosed(const ShapeDesc& shape, std::string* why) {
  switch (shape.type) {
    case ShapeDesc::Type::Sphere:
    case ShapeDesc::Type::Box: return true;
    case ShapeDesc::Type::Quad: *why = "a quad is an open surface"; return false;
    case ShapeDesc::Type::Disk: *why = "a disk is an open surface"; return false;
    case ShapeDesc::Type::Cylinder: *why = "a cylinder has no caps: it is an open surface"; return false;
    case ShapeDesc::Type::Mesh: break;
  }
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t i = 0; i + 2 < shape.indices.size(); i += 3)
    for (int e = 0; e < 3; ++e) {
      uint32_t a = shape.indices[i + size_t(e)], b = shape.indices[i + size_t((e + 1) % 3)];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, faces] : edges)
    if (faces != 2) {
      *why = "the mesh is not closed: its edge between vertices " + std::to_string(edge.first) + " and " +
             std::to_string(edge.second) + " has " + std::to_string(faces) + " face" + (faces == 1 ? "" : "s") +
             " (every edge needs exactly 2)";
      return false;
    }
  if (edges.empty()) {
    *why = "the mesh has no triangles";
    return false;
  }
  return true;
}

void readObjectMedia(const Node& object, const SceneDescription& scene, ObjectDesc* o) {
  if (object.has("medium") && object.has("medium_interface"))
    object.member("medium_interface").fail("give either \"medium\" or \"medium_interface\", not both");
  if (object.has("medium")) {
    Node n = object.member("medium");
    std::string why;
    if (!shapeIsClosed(o->shape, &why))
      n.fail("an interior medium needs a closed shape: " + why + "; use \"medium_interface\" for a surface between media");
    o->media.present = true;
    o->media.inside = resolveMedium(n, scene);
    o->media.outside = scene.exteriorMedium;
  } else if (object.has("medium_interface")) {
    Node n = object.member("medium_interface");
    n.expectObject({"inside", "outside"});
    o->media.present = true;
    if (n.has("inside")) o->media.inside = resolveMedium(n.member("inside"), scene);
    if (n.has("outside")) o->media.outside = resolveMedium(n.member("outside"), scene);
  }
}

}  // namespace tdpm::scene::detail
