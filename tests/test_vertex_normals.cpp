// tests/test_vertex_normals.cpp — meshes' per-vertex shading normals (OBJ
// vn, pbrt "N", PLY nx/ny/nz; scene/shading_normal.cpp's
// interpolatedNormal): on a coarse triangulated sphere the shading normal is
// the analytic barycentric blend of its vertices' normals and the rendered
// cosine falloff follows the analytic sphere's far closer than the faceted
// mesh's; normals equal to the face normals render bit for bit as none
// (still and moving, pathtrace and time); shading normals tilted toward a
// light behind the surface let nothing through; pbrt N and PLY normals are
// imported, written by convert as OBJ vn and the JSON renders the same
// pixels; a wrong N count is a located error and convert writes nothing.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "error_capture.h"
#include "import/pbrt_import.h"
#include "normal_checks.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

RenderOptions options(RenderMethod m, int spp, int maxDepth, uint64_t seed) {
  return test::normalTestOptions(m, spp, maxDepth, seed);
}

struct TriMesh {
  std::vector<Vec3f> v;
  std::vector<uint32_t> f;  // 3 per triangle, counter-clockwise seen from outside
};

// A unit UV sphere of `rings` latitude bands and `segments` longitudes
// (poles included), wound outward; every vertex's exact normal is itself.
TriMesh uvSphere(int rings, int segments) {
  TriMesh m;
  m.v.push_back({0, 0, 1});
  for (int i = 1; i < rings; ++i) {
    float th = kPi * float(i) / float(rings);
    for (int j = 0; j < segments; ++j) {
      float ph = 2 * kPi * float(j) / float(segments);
      m.v.push_back({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  }
  m.v.push_back({0, 0, -1});
  auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    Vec3f n = cross(m.v[b] - m.v[a], m.v[c] - m.v[a]);
    if (dot(n, m.v[a] + m.v[b] + m.v[c]) < 0) std::swap(b, c);
    m.f.insert(m.f.end(), {a, b, c});
  };
  const uint32_t south = uint32_t(m.v.size() - 1);
  for (int j = 0; j < segments; ++j) {
    add(0, ring(1, j), ring(1, j + 1));
    for (int i = 1; i + 1 < rings; ++i) {
      add(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
      add(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
    }
    add(south, ring(rings - 1, j + 1), ring(rings - 1, j));
  }
  return m;
}

// OBJ text; with `normals`, one vn per vertex (the same index).
std::string objText(const TriMesh& m, const std::vector<Vec3f>* normals) {
  std::string s;
  char buf[128];
  for (Vec3f p : m.v) {
    std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", double(p.x), double(p.y), double(p.z));
    s += buf;
  }
  if (normals)
    for (Vec3f n : *normals) {
      std::snprintf(buf, sizeof buf, "vn %.9g %.9g %.9g\n", double(n.x), double(n.y), double(n.z));
      s += buf;
    }
  for (size_t i = 0; i < m.f.size(); i += 3) {
    s += "f";
    for (int k = 0; k < 3; ++k) {
      std::string c = std::to_string(m.f[i + size_t(k)] + 1);
      s += " " + c + (normals ? "//" + c : std::string());
    }
    s += "\n";
  }
  return s;
}

// Camera on +z looking at a unit sphere at the origin under a directional
// light from the upper right front; `shape` is the object's shape JSON.
constexpr int kRes = 32;
std::string sphereScene(const std::string& shape) {
  return R"({"camera": {"position": [0, 0, 4], "target": [0, 0, 0], "fov": 40, "resolution": [32, 32]},
    "materials": {"m": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}},
    "objects": [{"shape": )" + shape + R"(, "material": "m"}],
    "lights": [{"type": "directional", "direction": [-0.6, -0.5, -0.62], "irradiance": [1, 1, 1]}]})";
}

// RMS difference of the green channel over the pixels within 6 of the
// image centre (the sphere's disc is about 11.5 pixels in radius). Further
// out the inscribed mesh's parallax against the sphere (a ray meets them at
// points up to 5% of the radius apart) outweighs shading: at 8 pixels the
// smooth mesh's error was 0.0049 against the faceted 0.0123.
double interiorRms(const Film& a, const Film& b) {
  double s = 0;
  int n = 0;
  for (int y = 0; y < kRes; ++y)
    for (int x = 0; x < kRes; ++x) {
      float dx = float(x) + 0.5f - kRes / 2.0f, dy = float(y) + 0.5f - kRes / 2.0f;
      if (dx * dx + dy * dy > 36) continue;
      size_t i = size_t(y) * size_t(kRes) + size_t(x);
      double d = double(a.color[i].g) - double(b.color[i].g);
      s += d * d;
      ++n;
    }
  return std::sqrt(s / n);
}

}  // namespace

TEST_CASE("a coarse sphere's vertex normals: the analytic barycentric blend, and a smooth cosine falloff") {
  std::string dir = test::makeTempDir();
  TriMesh m = uvSphere(6, 10);
  std::vector<Vec3f> exact = m.v;  // a unit sphere's normal is its point
  test::writeFile(dir + "/smooth.obj", objText(m, &exact));
  test::writeFile(dir + "/faceted.obj", objText(m, nullptr));
  scene::SceneDescription smooth = scene::parseScene(sphereScene(R"({"type": "mesh", "file": "smooth.obj"})"), dir + "/a.json");
  scene::SceneDescription faceted = scene::parseScene(sphereScene(R"({"type": "mesh", "file": "faceted.obj"})"), dir + "/b.json");
  scene::SceneDescription analytic = scene::parseScene(sphereScene(R"({"type": "sphere", "radius": 1})"), dir + "/c.json");
  REQUIRE(smooth.objects[0].shape.normals.size() == m.f.size());
  CHECK(faceted.objects[0].shape.normals.empty());

  // The shading normal at hits over the sphere: normalize(b0 n0 + b1 n1 +
  // b2 n2) with the barycentrics of the hit point in its triangle.
  auto s = Scene::build(smooth);
  int hits = 0;
  for (float x : {-0.7f, -0.31f, 0.0f, 0.23f, 0.55f})
    for (float y : {-0.6f, -0.17f, 0.12f, 0.66f}) {
      Hit hit;
      REQUIRE(s->intersect({x, y, 3}, {0, 0, -1}, 10, 0, hit));
      const uint32_t* t = &m.f[size_t(hit.primitive) * 3];
      Vec3f a = m.v[t[0]], b = m.v[t[1]], c = m.v[t[2]];
      Vec3f n = cross(b - a, c - a);
      float area = dot(n, n);
      float b1 = dot(cross(hit.p - a, c - a), n) / area, b2 = dot(cross(b - a, hit.p - a), n) / area;
      Vec3f want = normalize(exact[t[0]] * (1 - b1 - b2) + exact[t[1]] * b1 + exact[t[2]] * b2);
      Vec3f ns = s->shadingNormal(s->materials[0], hit);
      INFO("ray at " << x << ", " << y);
      CHECK(length(ns - want) < 2e-5f);
      // And it is not the facet's normal (the test sees interpolation).
      if (std::fabs(b1) > 0.05f && std::fabs(b2) > 0.05f && 1 - b1 - b2 > 0.05f) {
        CHECK(length(ns - hit.n) > 1e-3f);
        ++hits;
      }
    }
  CHECK(hits >= 5);

  // Rendered: the analytic sphere's cosine falloff. Smooth shading follows
  // it far closer than the facets' steps (measured 0.0012 against 0.0095).
  RenderOptions o = options(RenderMethod::PathTrace, 16, 3, 7);
  Film ref = test::renderOnce(analytic, o);
  double errSmooth = interiorRms(test::renderOnce(smooth, o), ref);
  double errFaceted = interiorRms(test::renderOnce(faceted, o), ref);
  MESSAGE("RMS vs the analytic sphere: smooth " << errSmooth << ", faceted " << errFaceted);
  CHECK(test::imageSum(ref) > 0);
  CHECK(errFaceted > 0.005);  // the facets do show (albedo / pi = 0.16)
  CHECK(errSmooth < 0.25 * errFaceted);
  std::filesystem::remove_all(dir);
}

TEST_CASE("normals equal to the face normals render bit for bit as none (still and moving, pathtrace and time)") {
  std::string dir = test::makeTempDir();
  // A unit cube: every face's normal an axis, exactly the face normal tdpm
  // computes, given per corner (OBJ v//vn).
  TriMesh cube;
  for (int c = 0; c < 8; ++c) cube.v.push_back({(c & 1) ? 0.5f : -0.5f, (c & 2) ? 0.5f : -0.5f, (c & 4) ? 0.5f : -0.5f});
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  const char* axis[6] = {"-1 0 0", "1 0 0", "0 -1 0", "0 1 0", "0 0 -1", "0 0 1"};
  std::string plain, normals;
  for (Vec3f p : cube.v) plain += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  normals = plain;
  for (const char* a : axis) normals += std::string("vn ") + a + "\n";
  for (int f = 0; f < 6; ++f) {
    const uint32_t* q = faces[f];
    uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
    for (auto& t : tri) {
      plain += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
      std::string k = std::to_string(f + 1);
      normals += "f " + std::to_string(t[0] + 1) + "//" + k + " " + std::to_string(t[1] + 1) + "//" + k + " " +
                 std::to_string(t[2] + 1) + "//" + k + "\n";
    }
  }
  test::writeFile(dir + "/plain.obj", plain);
  test::writeFile(dir + "/normals.obj", normals);
  auto text = [&](const std::string& file) {
    return R"({"camera": {"position": [0, 2, 4], "target": [0, 0.5, 0], "fov": 40, "resolution": [16, 12], "shutter": [0, 1]},
      "materials": {"floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6]},
                    "box": {"type": "plastic", "color": [0.7, 0.3, 0.2], "roughness": 0.3}},
      "objects": [{"shape": {"type": "quad", "size": [6, 6]}, "material": "floor"},
                  {"shape": {"type": "mesh", "file": ")" + file + R"("}, "material": "box",
                   "transform": {"translate": [-0.6, 0.5, 0], "rotate": {"axis": [0.3, 1, 0.2], "angle": 37}}},
                  {"shape": {"type": "mesh", "file": ")" + file + R"("}, "material": "floor",
                   "transform": {"translate": [0.9, 0.3, 0.2], "scale": [0.6, 0.6, 0.8]},
                   "motion": [{"time": 0, "translate": [0.8, 0.3, 0]}, {"time": 1, "translate": [1.1, 0.3, 0.3],
                               "rotate": {"axis": [0, 1, 0], "angle": 30}}]}],
      "lights": [{"type": "sphere", "radius": 0.3, "power": [200, 200, 200], "transform": {"translate": [0, 3, 1]}}]})";
  };
  scene::SceneDescription a = scene::parseScene(text("plain.obj"), dir + "/a.json");
  scene::SceneDescription b = scene::parseScene(text("normals.obj"), dir + "/b.json");
  REQUIRE(b.objects[1].shape.normals.size() == 36);
  REQUIRE(a.objects[1].shape.normals.empty());
  // The shading path is taken: the context is a shaded one.
  auto s = Scene::build(b);
  Hit hit;
  REQUIRE(s->intersect({-0.6f, 3, 0}, {0, -1, 0}, 10, 0, hit));
  REQUIRE(hit.object == 1);
  std::optional<Material> scratch;
  CHECK(s->shadingContext(s->materials[1], hit, {0, 1, 0}, scratch).shaded);
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Time}) {
    RenderOptions o = options(m, 4, 4, 9);
    Film fa = test::renderOnce(a, o), fb = test::renderOnce(b, o);
    CHECK(test::imageSum(fa) > 0);
    CHECK(test::sameImage(fa, fb));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("no light leak: vertex normals tilted toward a light behind the surface give exactly 0") {
  std::string dir = test::makeTempDir();
  // A quad in y = 0 (geometric normal +y) whose vertex normals lean 60
  // degrees toward -x; the light arrives from below, travelling (1, 0.3, 0):
  // the shading normal alone would take it in, the geometric one does not.
  Vec3f lean = normalize(Vec3f(-std::sqrt(3.0f), 1, 0));
  char vn[96];
  std::snprintf(vn, sizeof vn, "vn %.9g %.9g %.9g\n", double(lean.x), double(lean.y), double(lean.z));
  test::writeFile(dir + "/q.obj", std::string("v -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\n") + vn +
                                      "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n");
  std::string text = R"({"camera": {"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov": 30, "resolution": [16, 16]},
    "materials": {"m": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}},
    "objects": [{"shape": {"type": "mesh", "file": "q.obj"}, "material": "m"}],
    "lights": [{"type": "directional", "direction": [1, 0.3, 0], "irradiance": [1, 1, 1]}]})";
  scene::SceneDescription d = scene::parseScene(text, dir + "/s.json");
  auto s = Scene::build(d);
  Hit hit;
  REQUIRE(s->intersect({0.1f, 1, 0.2f}, {0, -1, 0}, 10, 0, hit));
  REQUIRE(hit.n.y > 0.99f);
  Vec3f wi = normalize(Vec3f(-1, -0.3f, 0));
  Vec3f ns = s->shadingNormal(s->materials[0], hit);
  CHECK(length(ns - lean) < 1e-5f);
  test::checkLightFromBelowStaysOut(d, *s, hit, wi);
  std::filesystem::remove_all(dir);
}

TEST_CASE("pbrt N and PLY nx/ny/nz: imported, written as OBJ vn by convert, the JSON renders the same pixels") {
  std::string dir = test::makeTempDir();
  // A bent strip (two triangles meeting at a crease) with smooth normals,
  // under a rotation, a mirror and a non-uniform scale (normals transform by
  // the inverse transpose), and a PLY with normals under a moving transform.
  test::writeFile(dir + "/n.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property float nx\nproperty float ny\nproperty float nz\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "-0.5 0 -0.5 -0.3 1 0\n0.5 0 -0.5 0.3 1 0\n0 0 0.5 0 1 0.4\n3 0 2 1\n");
  std::string text = R"(LookAt 0 3 2  0 0 0  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" 16 "integer yresolution" 12
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "distant" "rgb L" [2 2 2] "point3 from" [0.3 1 0.2] "point3 to" [0 0 0]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
AttributeBegin
Rotate 20 0 1 0
Scale -1 0.7 1.3
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0.4 1  -1 0.4 1] "integer indices" [0 1 2 0 2 3]
  "normal N" [-0.2 1 -0.1  0.2 1 -0.1  0.3 1 0.4  -0.3 1 0.2]
AttributeEnd
AttributeBegin
ActiveTransform StartTime
Translate 0.8 0.2 0
ActiveTransform EndTime
Translate 1.0 0.2 0
ActiveTransform All
Shape "plymesh" "string filename" "n.ply"
AttributeEnd
)";
  test::writeFile(dir + "/s.pbrt", text);
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  for (const std::string& n : r.notes) {
    INFO(n);
    CHECK(n.find("\"N\"") == std::string::npos);
    CHECK(n.find("nx") == std::string::npos);
  }
  scene::SceneDescription& d = r.scene;
  REQUIRE(d.objects.size() == 2);
  CHECK(d.objects[0].shape.normals.size() == 6);
  CHECK(d.objects[1].shape.normals.size() == 3);
  CHECK(!d.objects[1].motion.empty());
  // The static mesh's normals were baked as normals: each stays on its
  // corner's side of the baked surface (the winding agrees with them).
  const scene::ShapeDesc& sh = d.objects[0].shape;
  for (size_t i = 0; i < sh.indices.size(); i += 3) {
    Vec3f g = cross(sh.vertices[sh.indices[i + 1]] - sh.vertices[sh.indices[i]],
                    sh.vertices[sh.indices[i + 2]] - sh.vertices[sh.indices[i]]);
    CHECK(dot(g, sh.normals[i] + sh.normals[i + 1] + sh.normals[i + 2]) > 0);
  }
  std::filesystem::create_directories(dir + "/out");
  std::string json = dir + "/out/s.json";
  pbrt::writeSceneJson(d, json);
  std::ifstream in(dir + "/out/s.mesh0.obj");
  std::string obj((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(obj.find("\nvn ") != std::string::npos);
  scene::SceneDescription back = scene::loadScene(json);
  REQUIRE(back.objects.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    REQUIRE(back.objects[k].shape.normals.size() == d.objects[k].shape.normals.size());
    for (size_t i = 0; i < d.objects[k].shape.normals.size(); ++i) {
      Vec3f a = d.objects[k].shape.normals[i], b = back.objects[k].shape.normals[i];
      CHECK((a.x == b.x && a.y == b.y && a.z == b.z));
    }
  }
  for (RenderMethod m : {RenderMethod::PathTrace, RenderMethod::Time}) {
    RenderOptions o = options(m, 4, 4, 11);
    Film fa = test::renderOnce(d, o), fb = test::renderOnce(back, o);
    CHECK(test::imageSum(fa) > 0);
    CHECK(test::sameImage(fa, fb));
    // And the normals change the picture (not silently dropped).
    scene::SceneDescription flat = d;
    for (auto& ob : flat.objects) ob.shape.normals.clear();
    CHECK_FALSE(test::sameImage(fa, test::renderOnce(flat, o)));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("bad vertex normals: located errors, convert writes nothing") {
  std::string dir = test::makeTempDir();
  // pbrt: three points, two normals.
  test::writeFile(dir + "/bad.pbrt", "WorldBegin\nMaterial \"diffuse\"\n"
                                     "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"integer indices\" [0 1 2]\n"
                                     "  \"normal N\" [0 0 1  0 0 1]\n");
  std::string e = test::errorMessageOf([&] { pbrt::importPbrtFile(dir + "/bad.pbrt"); });
  INFO(e);
  CHECK(e.find("bad.pbrt:4") != std::string::npos);  // the parameter's line
  CHECK(e.find("N\"") != std::string::npos);
  CHECK(e.find("expected 3 numbers per point (9), got 6") != std::string::npos);
  auto c = test::runTdpm("convert -q '" + dir + "/bad.pbrt' -o '" + dir + "/bad.json'");
  CHECK(c.exitCode == 1);
  CHECK(!test::fileExists(dir + "/bad.json"));
  CHECK(!test::fileExists(dir + "/bad.mesh0.obj"));
  // OBJ: a face naming a normal the file does not have, with its line.
  test::writeFile(dir + "/m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
  std::string j = R"({"camera": {"position": [0, 0, 3], "target": [0, 0, 0]},
    "objects": [{"shape": {"type": "mesh", "file": "m.obj"}}]})";
  std::string eo = test::errorMessageOf([&] { scene::parseScene(j, dir + "/s.json"); });
  INFO(eo);
  CHECK(eo.find("m.obj") != std::string::npos);
  CHECK(eo.find("line 5") != std::string::npos);
  CHECK(eo.find("uses normal 2 but the file has 1") != std::string::npos);
  // PLY: half a normal (nx alone) is not a normal: noted, not used.
  test::writeFile(dir + "/h.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property float nx\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n");
  test::writeFile(dir + "/h.pbrt", "WorldBegin\nShape \"plymesh\" \"string filename\" \"h.ply\"\n");
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/h.pbrt");
  CHECK(r.scene.objects.at(0).shape.normals.empty());
  bool noted = false;
  for (const std::string& n : r.notes) noted = noted || n.find("\"nx\" ignored") != std::string::npos;
  CHECK(noted);
  std::filesystem::remove_all(dir);
}

TEST_CASE("photons at a shading normal: Veach's adjoint factor and the gather's |wi.ns| / |wi.ng|") {
  // ng = +z, ns tilted 30 degrees toward +x; a diffuse context seen from wo.
  Material m;
  m.type = Material::Type::Diffuse;
  const float th = 30.0f * kPi / 180.0f;
  Vec3f ng{0, 0, 1}, ns{std::sin(th), 0, std::cos(th)};
  Vec3f wPrev = normalize(Vec3f(-0.5f, 0.2f, 1)), wNext = normalize(Vec3f(0.7f, -0.1f, 0.4f));
  ShadingContext c = makeShadingContext(m, Rgb(0.5f), ng, wPrev, ns);
  REQUIRE(c.shaded);
  float want = std::fabs(dot(wPrev, ns)) * std::fabs(dot(wNext, ng)) / (std::fabs(dot(wPrev, ng)) * std::fabs(dot(wNext, ns)));
  CHECK(adjointShadingFactor(c, wPrev, wNext) == doctest::Approx(want).epsilon(1e-6));
  CHECK(want != doctest::Approx(1.0f).epsilon(1e-2));  // the factor is not trivially 1 here
  CHECK(gatherShadingFactor(c, wNext) == doctest::Approx(std::fabs(dot(wNext, ns)) / dot(wNext, ng)).epsilon(1e-6));
  // Seen from below (frame flipped with the geometric normal): the same values.
  ShadingContext below = makeShadingContext(m, Rgb(0.5f), ng, -wPrev, ns);
  REQUIRE(below.shaded);
  CHECK(adjointShadingFactor(below, -wPrev, -wNext) == doctest::Approx(want).epsilon(1e-6));
  // Without a shading normal both are exactly 1.
  ShadingContext plain = makeShadingContext(m, Rgb(0.5f), ng, wPrev);
  CHECK(adjointShadingFactor(plain, wPrev, wNext) == 1.0f);
  CHECK(gatherShadingFactor(plain, wNext) == 1.0f);
}
