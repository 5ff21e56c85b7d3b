// tests/test_textures.cpp — scene/texture.*, image/tga.*, image/
// texture_image.* and the textures of the JSON format and the pbrt import:
// exact and bilinear lookups against pbrt's formula, wrap modes, the uv
// mapping, uv on spheres, quads and meshes at known points, scale / mix /
// checkerboard values, a rendered textured quad against its radiance, the
// convert round trip, and located errors for bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "core/error.h"
#include "error_capture.h"
#include "image/pfm.h"
#include "image/png.h"
#include "image/texture_image.h"
#include "image/tga.h"
#include "import/pbrt_import.h"
#include "render_fixtures.h"
#include "scene/json_writer.h"
#include "scene/parse.h"
#include "scene/scene.h"
#include "scene/texture.h"

using namespace tdpm;

namespace {

// A 4 x 2 image whose texels are all different: (x, y) -> (x, y, x + 4 y) / 10.
TextureSet fourByTwo() {
  TextureSet s;
  s.images.push_back({4, 2, 0});
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) s.texels.push_back(Rgb(float(x), float(y), float(x + 4 * y)) * 0.1f);
  return s;
}

Rgb texelOf(int x, int y) { return Rgb(float(x), float(y), float(x + 4 * y)) * 0.1f; }

void checkRgb(Rgb got, Rgb want, float eps = 1e-6f) {
  CHECK(got.r == doctest::Approx(want.r).epsilon(eps));
  CHECK(got.g == doctest::Approx(want.g).epsilon(eps));
  CHECK(got.b == doctest::Approx(want.b).epsilon(eps));
}

void writeBytes(const std::string& path, const std::vector<unsigned char>& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

// A scene around `body` (textures, materials, objects, lights), one camera.
std::string sceneText(const std::string& body, const std::string& camera =
                          R"("camera": {"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov": 30, "resolution": [16, 16]})") {
  return "{" + camera + ", " + body + "}";
}

std::string errorOfJson(const std::string& text, const std::string& path) {
  return test::errorMessageOf([&] { scene::parseScene(text, path); });
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

// The JSON `tdpm convert` wrote for d reads back to the same scene (the
// same JSON again) and renders the same, non-black pixels.
static void checkJsonRoundTrip(const scene::SceneDescription& d, const std::string& json) {
  scene::SceneDescription back = scene::loadScene(json);
  CHECK(nlohmann::json::parse(pbrt::sceneToJson(back, "/x/s.json").json) ==
        nlohmann::json::parse(pbrt::sceneToJson(d, "/x/s.json").json));
  RenderOptions o = test::smallRenderOptions(RenderMethod::PathTrace, 4, 4, 11);
  Film a = test::renderOnce(d, o), b = test::renderOnce(back, o);
  CHECK(test::sameImage(a, b));
  CHECK(test::imageSum(a) > 0);
}

TEST_CASE("texture lookup: a texel centre gives the texel exactly, bilinear or point") {
  TextureSet s = fourByTwo();
  const TextureImage& im = s.images[0];
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      // pbrt: s = (x + 1/2) / w, t = 1 - (y + 1/2) / h (row 0 at the top, t up).
      float u = (x + 0.5f) / 4, t = 1 - (y + 0.5f) / 2;
      Rgb b = s.lookup(im, TextureNode::Wrap::Clamp, true, u, t), p = s.lookup(im, TextureNode::Wrap::Clamp, false, u, t);
      checkRgb(b, texelOf(x, y));
      CHECK(p.b == texelOf(x, y).b);
    }
}

TEST_CASE("texture lookup: bilinear between the four texel centres, as pbrt's Bilerp") {
  TextureSet s = fourByTwo();
  const TextureImage& im = s.images[0];
  // st = (0.4, 0.6): x = 0.4 * 4 - 0.5 = 1.1, y = (1 - 0.6) * 2 - 0.5 = 0.3.
  float dx = 0.1f, dy = 0.3f;
  Rgb want = texelOf(1, 0) * ((1 - dx) * (1 - dy)) + texelOf(2, 0) * (dx * (1 - dy)) + texelOf(1, 1) * ((1 - dx) * dy) +
             texelOf(2, 1) * (dx * dy);
  checkRgb(s.lookup(im, TextureNode::Wrap::Repeat, true, 0.4f, 0.6f), want, 1e-5f);
  // Point filtering: the texel the point lies in.
  checkRgb(s.lookup(im, TextureNode::Wrap::Repeat, false, 0.4f, 0.6f), texelOf(1, 0));
}

TEST_CASE("texture wrap modes: repeat, clamp and black outside [0, 1]") {
  TextureSet s = fourByTwo();
  const TextureImage& im = s.images[0];
  // Repeat: s + 1 and s - 2 are s.
  checkRgb(s.lookup(im, TextureNode::Wrap::Repeat, true, 1.3f, 0.75f), s.lookup(im, TextureNode::Wrap::Repeat, true, 0.3f, 0.75f), 1e-5f);
  checkRgb(s.lookup(im, TextureNode::Wrap::Repeat, false, -1.875f, 0.75f), texelOf(0, 0));
  // Repeat blends the last column with the first across the seam.
  checkRgb(s.lookup(im, TextureNode::Wrap::Repeat, true, 1.0f, 0.75f), (texelOf(3, 0) + texelOf(0, 0)) * 0.5f, 1e-5f);
  // Clamp: the edge texel beyond the edge; at the edge itself, no blend with the far side.
  checkRgb(s.lookup(im, TextureNode::Wrap::Clamp, true, 1.7f, 0.75f), texelOf(3, 0));
  checkRgb(s.lookup(im, TextureNode::Wrap::Clamp, true, -3.0f, -2.0f), texelOf(0, 1));
  checkRgb(s.lookup(im, TextureNode::Wrap::Clamp, true, 1.0f, 0.75f), texelOf(3, 0));
  // Black: zero outside, half the edge texel at the edge (one of two weights).
  checkRgb(s.lookup(im, TextureNode::Wrap::Black, true, 1.5f, 0.75f), Rgb(0.0f));
  checkRgb(s.lookup(im, TextureNode::Wrap::Black, true, 1.0f, 0.75f), texelOf(3, 0) * 0.5f, 1e-5f);
}

TEST_CASE("texture nodes: uscale/udelta, scale, invert, mix and checkerboards") {
  TextureSet s = fourByTwo();
  TextureNode img;
  img.kind = TextureNode::Kind::Image;
  img.bilinear = false;
  img.uscale = 2, img.vscale = 1, img.udelta = 0.25f, img.vdelta = 0;
  s.nodes.push_back(img);  // 0
  // u = 0.2: s = 2 * 0.2 + 0.25 = 0.65 -> column 2; v = 0.9 -> row 0.
  checkRgb(s.eval(0, {{0.2f, 0.9f}, {}}), texelOf(2, 0));
  s.nodes[0].scale = 2;
  s.nodes[0].invert = true;  // max(0, 1 - 2 x texel)
  Rgb t = texelOf(2, 0);
  checkRgb(s.eval(0, {{0.2f, 0.9f}, {}}), Rgb(std::max(0.f, 1 - 2 * t.r), std::max(0.f, 1 - 2 * t.g), std::max(0.f, 1 - 2 * t.b)));
  TextureNode c;
  c.kind = TextureNode::Kind::Constant;
  c.a.value = Rgb(0.25f, 0.5f, 1.0f);
  s.nodes.push_back(c);  // 1
  TextureNode sc;
  sc.kind = TextureNode::Kind::Scale;
  sc.a.node = 1;
  sc.b.value = Rgb(0.5f);
  s.nodes.push_back(sc);  // 2
  checkRgb(s.eval(2, {}), Rgb(0.125f, 0.25f, 0.5f));
  TextureNode mix;
  mix.kind = TextureNode::Kind::Mix;
  mix.a.node = 1;
  mix.b.value = Rgb(0.0f);
  mix.amount.value = Rgb(0.25f);
  s.nodes.push_back(mix);  // 3: 0.75 x node 1
  checkRgb(s.eval(3, {}), Rgb(0.1875f, 0.375f, 0.75f));
  TextureNode ch;
  ch.kind = TextureNode::Kind::Checkerboard;
  ch.uscale = 4, ch.vscale = 2, ch.udelta = 0.5f;
  ch.a.value = Rgb(1.0f);
  ch.b.node = 3;
  s.nodes.push_back(ch);  // 4
  // floor(4 u + 0.5) + floor(2 v): (0.05, 0.1) -> 0 + 0 even; (0.2, 0.1) -> 1 odd; (0.2, 0.6) -> 2 even.
  checkRgb(s.eval(4, {{0.05f, 0.1f}, {}}), Rgb(1.0f));
  checkRgb(s.eval(4, {{0.2f, 0.1f}, {}}), Rgb(0.1875f, 0.375f, 0.75f));
  checkRgb(s.eval(4, {{0.2f, 0.6f}, {}}), Rgb(1.0f));
  TextureNode c3;
  c3.kind = TextureNode::Kind::Checker3D;
  c3.invCell = 2;
  c3.a.value = Rgb(0.9f);
  c3.b.value = Rgb(0.1f);
  s.nodes.push_back(c3);  // 5: cells of 0.5 centred on the origin
  checkRgb(s.eval(5, {{}, {0.2f, 0.1f, -0.2f}}), Rgb(0.9f));
  checkRgb(s.eval(5, {{}, {0.3f, 0.1f, -0.2f}}), Rgb(0.1f));
}

TEST_CASE("uv at hits: pbrt's sphere parameterisation, the quad's corners, OBJ vt interpolation") {
  std::string dir = test::makeTempDir();
  // A unit square of two triangles with vt (0,0) (2,0) (2,4) (0,4) at x-z corners.
  test::writeFile(dir + "/sq.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvt 0 0\nvt 2 0\nvt 2 4\nvt 0 4\n"
                                   "f 1/1 4/4 3/3\nf 1/1 3/3 2/2\n");
  std::string text = sceneText(R"("objects": [
    {"shape": {"type": "sphere", "radius": 0.5}},
    {"shape": {"type": "quad", "size": [2, 4]}, "transform": {"translate": [10, 0, 0]}},
    {"shape": {"type": "mesh", "file": "sq.obj"}, "transform": {"translate": [20, 0, 0]}}])");
  scene::SceneDescription d = scene::parseScene(text, dir + "/s.json");
  REQUIRE(d.objects[2].shape.uvs.size() == 6);
  auto s = Scene::build(d);
  auto uvAlong = [&](Vec3f o, Vec3f dir) {
    Hit h;
    REQUIRE(s->intersect(o, dir, 100.0f, 0.0f, h));
    return s->uvAt(h);
  };
  // Sphere: u = phi / 2 pi about +z, v = 1 - theta / pi (v = 1 at +z).
  Vec2f a = uvAlong({3, 0, 0}, {-1, 0, 0});  // (r, 0, 0): phi 0, theta pi/2
  CHECK(a.x == doctest::Approx(0.0f).epsilon(1e-5));
  CHECK(a.y == doctest::Approx(0.5f).epsilon(1e-5));
  Vec2f b = uvAlong({0, 3, 0}, {0, -1, 0});  // phi pi/2
  CHECK(b.x == doctest::Approx(0.25f).epsilon(1e-5));
  Vec2f c = uvAlong({-3, 0, 0.3f}, {1, 0, 0});  // phi pi, z = 0.3 of r = 0.5
  CHECK(c.x == doctest::Approx(0.5f).epsilon(1e-5));
  CHECK(c.y == doctest::Approx(1 - std::acos(0.3f / 0.5f) / kPi).epsilon(1e-4));
  // Quad (2 x 4 at x = 10): u = x / 2 + 1/2, v = 1/2 - z / 4.
  Vec2f q = uvAlong({10.5f, 3, -1}, {0, -1, 0});
  CHECK(q.x == doctest::Approx(0.75f).epsilon(1e-5));
  CHECK(q.y == doctest::Approx(0.75f).epsilon(1e-5));
  // Mesh: vt (u, v) = (2 x, 4 z) on this square.
  Vec2f m = uvAlong({20.3f, 3, 0.6f}, {0, -1, 0});
  CHECK(m.x == doctest::Approx(0.6f).epsilon(1e-4));
  CHECK(m.y == doctest::Approx(2.4f).epsilon(1e-4));
  std::filesystem::remove_all(dir);
}

TEST_CASE("JSON textures: image (PFM, TGA raw and RLE, PNG sRGB / linear), scale, mix and checkerboard values") {
  std::string dir = test::makeTempDir();
  image::ImageRgb img(2, 1);
  img.at(0, 0) = Rgb(0.2f, 0.4f, 0.6f);
  img.at(1, 0) = Rgb(0.8f, 0.6f, 0.4f);
  image::writePfm(dir + "/a.pfm", img);
  // TGA, bottom-left origin, BGR: the same 2 x 1 codes (51, 102, 153) and (204, 153, 102) raw and RLE.
  std::vector<unsigned char> hdr = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0};
  std::vector<unsigned char> raw = hdr;
  raw.insert(raw.end(), {153, 102, 51, 102, 153, 204});
  writeBytes(dir + "/raw.tga", raw);
  std::vector<unsigned char> rle = hdr;
  rle[2] = 10;
  rle.insert(rle.end(), {0x00, 153, 102, 51, 0x80, 102, 153, 204});  // a raw packet of 1, a run of 1
  writeBytes(dir + "/rle.tga", rle);
  image::ImageRgb8 r = image::readTga(dir + "/raw.tga"), l = image::readTga(dir + "/rle.tga");
  CHECK(r.rgb == std::vector<uint8_t>{51, 102, 153, 204, 153, 102});
  CHECK(l.rgb == r.rgb);
  image::ImageRgb lin = image::readTextureImage(dir + "/raw.tga", {image::TexelEncoding::Kind::Linear, 1});
  CHECK(lin.at(0, 0).r == doctest::Approx(0.2f));
  image::ImageRgb srgb = image::readTextureImage(dir + "/raw.tga", {});
  CHECK(srgb.at(0, 0).r == doctest::Approx(image::srgbDecode(0.2f)));
  image::ImageRgb gam = image::readTextureImage(dir + "/raw.tga", {image::TexelEncoding::Kind::Gamma, 2.0f});
  CHECK(gam.at(1, 0).r == doctest::Approx(0.8f * 0.8f));
  // PNG (8-bit, written as sRGB codes of 0.2 linear): "linear" gives the code / 255.
  image::writePngPreview(dir + "/p.png", image::ImageRgb(1, 1, Rgb(0.2f)), 0.0f);
  float code = float(image::toSrgb8(0.2f)) / 255.0f;
  CHECK(image::readTextureImage(dir + "/p.png", {image::TexelEncoding::Kind::Linear, 1}).at(0, 0).g == doctest::Approx(code));
  CHECK(image::readTextureImage(dir + "/p.png", {}).at(0, 0).g == doctest::Approx(image::srgbDecode(code)));

  std::string text = sceneText(R"("textures": {
      "img": {"type": "image", "file": "a.pfm", "filter": "point", "wrap": "clamp"},
      "tga": {"type": "image", "file": "rle.tga", "encoding": "linear", "filter": "point"},
      "half": {"type": "constant", "value": 0.5, "float": true},
      "scaled": {"type": "scale", "texture": "img", "scale": "half"},
      "mixed": {"type": "mix", "tex1": "img", "tex2": [1, 1, 1], "amount": 0.25},
      "checks": {"type": "checkerboard", "tex1": "scaled", "tex2": [0, 0, 1], "uscale": 2, "vscale": 2}},
    "materials": {"m": {"type": "diffuse", "texture": "checks"}, "t": {"type": "diffuse", "texture": "tga"},
                  "chrome": {"type": "metal", "color": "img", "roughness": 0.3}},
    "objects": [{"shape": {"type": "quad", "size": [2, 2]}, "material": "m"},
                {"shape": {"type": "quad", "size": [2, 2]}, "material": "chrome", "transform": {"translate": [5, 0, 0]}}])");
  scene::SceneDescription d = scene::parseScene(text, dir + "/s.json");
  REQUIRE(d.textures.size() == 6);
  // The PFM is read once though two textures could name it; each image once in the built set.
  auto s = Scene::build(d);
  CHECK(s->textures.images.size() == 2);
  auto idx = [&](const std::string& n) {
    for (size_t i = 0; i < d.textures.size(); ++i)
      if (d.textures[i].name == n) return uint32_t(i);
    FAIL("no texture " << n);
    return 0u;
  };
  TexturePoint left{{0.25f, 0.5f}, {}}, right{{0.75f, 0.5f}, {}};
  checkRgb(s->textures.eval(idx("scaled"), left), Rgb(0.1f, 0.2f, 0.3f));
  checkRgb(s->textures.eval(idx("mixed"), right), Rgb(0.8f, 0.6f, 0.4f) * 0.75f + Rgb(0.25f));
  checkRgb(s->textures.eval(idx("tga"), right), Rgb(0.8f, 0.6f, 0.4f));
  // checkerboard: floor(2u) + floor(2v): (0.25, 0.25) even -> scaled; (0.75, 0.25) odd -> blue.
  checkRgb(s->textures.eval(idx("checks"), {{0.25f, 0.25f}, {}}), Rgb(0.1f, 0.2f, 0.3f));
  checkRgb(s->textures.eval(idx("checks"), {{0.75f, 0.25f}, {}}), Rgb(0, 0, 1));
  // Textured specular colour: the metal's reflectance is the image at the hit's (u, v).
  Hit h;
  REQUIRE(s->intersect({5.5f, 2, 0}, {0, -1, 0}, 10.0f, 0.0f, h));  // u = 0.75
  const Material& base = s->materials[s->objects[h.object].material];
  std::optional<Material> scratch;
  checkRgb(s->shadedMaterial(base, h, scratch).specular, Rgb(0.8f, 0.6f, 0.4f));
  Hit h0;
  REQUIRE(s->intersect({-0.5f, 2, 0}, {0, -1, 0}, 10.0f, 0.0f, h0));
  const Material& diffuse = s->materials[s->objects[h0.object].material];
  CHECK(&s->shadedMaterial(diffuse, h0, scratch) == &diffuse);  // untextured specular: no copy
  std::filesystem::remove_all(dir);
}

TEST_CASE("a rendered textured quad: each half's pixels have the radiance of its texel (albedo x E / pi)") {
  std::string dir = test::makeTempDir();
  image::ImageRgb img(2, 1);
  img.at(0, 0) = Rgb(0.2f);
  img.at(1, 0) = Rgb(0.8f, 0.5f, 0.1f);
  image::writePfm(dir + "/t.pfm", img);
  // Seen from +y with -z up: image x along world x, the quad fills the frame.
  std::string text = sceneText(R"("textures": {"t": {"type": "image", "file": "t.pfm", "filter": "point"}},
    "materials": {"m": {"type": "diffuse", "texture": "t"}},
    "objects": [{"shape": {"type": "quad", "size": [2, 2]}, "material": "m"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}])");
  scene::SceneDescription d = scene::parseScene(text, dir + "/s.json");
  Film f = test::renderOnce(d, test::smallRenderOptions(RenderMethod::PathTrace, 16, 4, 3));
  REQUIRE(f.width == 16);
  Rgb sumL(0.0f), sumR(0.0f);
  int n = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < 5; ++x, ++n) {  // away from the seam (the pixel filter spans it)
      sumL += f.color[size_t(y) * 16 + size_t(x)];
      sumR += f.color[size_t(y) * 16 + size_t(15 - x)];
    }
  Rgb meanL = sumL * (1.0f / float(n)), meanR = sumR * (1.0f / float(n));
  checkRgb(meanL, Rgb(0.2f / kPi), 0.02f);
  checkRgb(meanR, Rgb(0.8f, 0.5f, 0.1f) * (1 / kPi), 0.02f);
  std::filesystem::remove_all(dir);
}

TEST_CASE("pbrt textures: imagemap, scale, mix and checkerboard on a uv mesh; convert round trip renders the same pixels") {
  std::string dir = test::makeTempDir();
  image::ImageRgb img(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.at(x, y) = Rgb(0.1f + 0.2f * float(x), 0.2f + 0.15f * float(y), 0.5f);
  image::writePfm(dir + "/tex.pfm", img);
  std::string text = R"(LookAt 0 3 0  0 0 0  0 0 -1
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 12 "integer yresolution" 12
Sampler "random" "integer pixelsamples" 4
WorldBegin
LightSource "distant" "rgb L" [2 2 2] "point3 from" [0 1 0] "point3 to" [0 0 0]
Texture "img" "spectrum" "imagemap" "string filename" "tex.pfm" "string wrap" "clamp" "float uscale" 2 "float udelta" -0.5
Texture "amt" "float" "checkerboard" "float uscale" 3 "float vscale" 3 "float tex1" 0.2 "float tex2" 0.9
Texture "m" "spectrum" "mix" "texture tex1" "img" "rgb tex2" [0.9 0.1 0.1] "texture amount" "amt"
Texture "s" "spectrum" "scale" "texture tex" "m" "float scale" 0.8
Material "diffuse" "texture reflectance" "s"
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0 1  -1 0 1] "integer indices" [0 2 1 0 3 2]
  "point2 uv" [0 0  1 0  1 1  0 1]
AttributeBegin
Material "matte" "texture Kd" "img"
Translate 0 0.5 0
Shape "sphere" "float radius" 0.3
AttributeEnd
AttributeBegin
Material "mirror" "texture Kr" "m"
Translate 0.6 0.3 0.4
Shape "sphere" "float radius" 0.2
AttributeEnd
)";
  test::writeFile(dir + "/s.pbrt", text);
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  scene::SceneDescription& d = r.scene;
  REQUIRE(d.textures.size() == 4);
  REQUIRE(d.objects.size() == 3);
  CHECK(d.materials[d.objects[2].material].specularTexture == 2);  // "m"
  CHECK(d.objects[0].shape.uvs.size() == 6);
  // The image file is read once though two materials use it.
  auto built = Scene::build(d);
  CHECK(built->textures.images.size() == 1);
  std::string json = dir + "/out/s.json";
  std::filesystem::create_directories(dir + "/out");
  pbrt::writeSceneJson(d, json);
  std::ifstream in(json);
  std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(contains(written, "\"file\": \"../tex.pfm\""));  // relative to the JSON's folder
  checkJsonRoundTrip(d, json);
  std::filesystem::remove_all(dir);
}

TEST_CASE("texture bad input: located errors (JSON and pbrt), and convert writes nothing") {
  std::string dir = test::makeTempDir();
  image::writePfm(dir + "/ok.pfm", image::ImageRgb(1, 1, Rgb(0.5f)));
  test::writeFile(dir + "/bad.tga", std::string("\0\0\2\0\0\0\0\0\0\0\0\0\4\0\4\0\30\0\1\2\3", 21));
  auto mat = [](const std::string& tex) {
    return "\"materials\": {\"m\": {\"type\": \"diffuse\", \"texture\": \"" + tex + "\"}}, \"objects\": []";
  };
  std::string p = dir + "/s.json";
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"t": {"type": "image", "file": "missing.png"}}, "objects": [])"), p),
                 "textures.t.file: " + dir + "/missing.png"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"t": {"type": "image", "file": "bad.tga"}}, "objects": [])"), p),
                 "bad.tga: TGA pixel data ends early"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"t": {"type": "image", "file": "ok.pfm", "wrap": "mirror"}}, "objects": [])"), p),
                 "textures.t.wrap"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"t": {"type": "constant", "value": 1}}, )" + mat("u")), p),
                 "unknown texture \"u\"; defined textures: t"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"f": {"type": "constant", "value": 0.5, "float": true}}, )" + mat("f")), p),
                 "is a float texture, but a spectrum (RGB) one is expected here"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"a": {"type": "scale", "texture": "b"}, "b": {"type": "scale", "texture": "a"}}, "objects": [])"), p),
                 "refers to itself"));
  CHECK(contains(errorOfJson(sceneText(R"("textures": {"a": {"type": "mix", "amount": [1, 0, 0]}}, "objects": [])"), p),
                 "textures.a.amount"));
  // pbrt: missing file, unknown wrap, each located at its statement.
  auto pbrtError = [&](const std::string& body) {
    return test::errorMessageOf([&] { pbrt::importPbrtText("WorldBegin\n" + body, dir + "/t.pbrt"); });
  };
  CHECK(contains(pbrtError("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"nope.exr\"\n"),
                 dir + "/t.pbrt:2: Texture \"t\": "));
  CHECK(contains(pbrtError("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"ok.pfm\" \"string wrap\" \"mirror\"\n"),
                 "t.pbrt:2: Texture \"t\": unknown wrap mode \"mirror\" (supported: repeat, clamp, black)"));
  CHECK(contains(pbrtError("Texture \"a\" \"spectrum\" \"scale\" \"texture tex\" \"b\"\n"),
                 "no texture named \"b\" has been defined"));
  CHECK(contains(pbrtError("Texture \"f\" \"spectrum\" \"constant\"\nTexture \"m\" \"spectrum\" \"mix\" \"texture amount\" \"f\"\n"),
                 "texture \"f\" is a spectrum texture, but Texture \"m\"'s amount needs a float one"));
  // tdpm convert: the error, and no JSON (nor mesh) left behind.
  test::writeFile(dir + "/c.pbrt", "Camera \"perspective\"\nWorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"gone.png\"\n"
                                   "Material \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"\n");
  test::CommandResult res = test::runTdpm("convert '" + dir + "/c.pbrt' --output '" + dir + "/c.json'");
  CHECK(res.exitCode != 0);
  CHECK(contains(res.output, "c.pbrt:3: Texture \"t\""));
  CHECK(!test::fileExists(dir + "/c.json"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("pbrt uv: a rotated sphere keeps pbrt's (u, v) at its object-space points; PLY u/v reach the mesh") {
  // Rotate 90 about x takes pbrt's object (0,0,1) (v = 1), (1,0,0) (u = 0,
  // v = 1/2) and (0,1,0) (u = 1/4) to world (0,-1,0), (1,0,0), (0,0,1);
  // tdpm's world is pbrt's mirrored in x.
  scene::SceneDescription d = pbrt::importPbrtText("WorldBegin\nRotate 90 1 0 0\nShape \"sphere\"\n", "dir/t.pbrt").scene;
  auto s = Scene::build(d);
  auto uvToward = [&](Vec3f p) {
    Hit h;
    REQUIRE(s->intersect(p * 3.0f, p * -1.0f, 10.0f, 0.0f, h));
    return s->uvAt(h);
  };
  CHECK(uvToward({0, -1, 0}).y == doctest::Approx(1.0f).epsilon(1e-4));
  Vec2f a = uvToward({-1, 0, 0});
  CHECK(std::fmod(a.x + 0.5f, 1.0f) == doctest::Approx(0.5f).epsilon(1e-4));  // u = 0 (or 1 at the seam)
  CHECK(a.y == doctest::Approx(0.5f).epsilon(1e-4));
  CHECK(uvToward({0, 0, 1}).x == doctest::Approx(0.25f).epsilon(1e-4));

  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/m.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                  "property float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                  "0 0 0 0 0\n1 0 0 0.5 0\n1 0 1 0.5 0.25\n0 0 1 0 0.25\n4 0 3 2 1\n");
  test::writeFile(dir + "/p.pbrt", "WorldBegin\nShape \"plymesh\" \"string filename\" \"m.ply\"\n");
  scene::SceneDescription q = pbrt::importPbrtFile(dir + "/p.pbrt").scene;
  REQUIRE(q.objects.size() == 1);
  const scene::ShapeDesc& m = q.objects[0].shape;
  REQUIRE(m.uvs.size() == m.indices.size());
  for (size_t k = 0; k < m.indices.size(); ++k) {
    Vec3f v = m.vertices[m.indices[k]];  // tdpm x = -pbrt x
    CHECK(m.uvs[k].x == doctest::Approx(-0.5f * v.x));
    CHECK(m.uvs[k].y == doctest::Approx(0.25f * v.z));
  }
  std::filesystem::remove_all(dir);
}

// ------------------------------------------------ textured roughness, Ks, conductor reflectance

namespace {

// A 2 x 2 m plane seen from above, under a directional light from the side:
// a GGX highlight whose shape depends on the roughness. `rough` is the
// metal's "roughness" value (a number or a texture's name).
std::string metalPlane(const std::string& textures, const std::string& rough, const std::string& extra = "") {
  return sceneText(R"("textures": {)" + textures + R"(},
    "materials": {"m": {"type": "metal", "color": [0.9, 0.8, 0.7], "roughness": )" + rough + extra + R"(}},
    "objects": [{"shape": {"type": "quad", "size": [2, 2]}, "material": "m"}],
    "lights": [{"type": "directional", "direction": [-0.3, -1, 0.2], "irradiance": [3, 3, 3]}])");
}

// The per-hit material straight below (x, z): Scene::shadedMaterial's copy.
Material shadedBelow(const Scene& s, float x, float z) {
  Hit h;
  REQUIRE(s.intersect({x, 3, z}, {0, -1, 0}, 100.0f, 0.0f, h));
  std::optional<Material> scratch;
  return s.shadedMaterial(s.materials[s.objects[h.object].material], h, scratch);
}

// The same in a pbrt scene's coordinates: the importer mirrors x (pbrt's
// camera frame is left-handed, pbrt_import.cpp).
Material pbrtBelow(const Scene& s, float x, float z) { return shadedBelow(s, -x, z); }

}  // namespace

TEST_CASE("textured roughness: a checkerboard on a metal plane gives each half the pixels of that constant roughness") {
  std::string dir = test::makeTempDir();
  // u < 1/2 (x < 0): tex1 = 0.1, u >= 1/2: tex2 = 0.5 (uscale 2: two cells across).
  const std::string checker = R"("r": {"type": "checkerboard", "float": true, "uscale": 2, "tex1": 0.1, "tex2": 0.5})";
  scene::SceneDescription textured = scene::parseScene(metalPlane(checker, "\"r\""), dir + "/a.json");
  scene::SceneDescription sharp = scene::parseScene(metalPlane(checker, "0.1"), dir + "/b.json");
  scene::SceneDescription rough = scene::parseScene(metalPlane(checker, "0.5"), dir + "/c.json");
  REQUIRE(textured.materials[0].roughnessTexture == 0);
  auto s = Scene::build(textured);
  CHECK(shadedBelow(*s, -0.5f, 0.1f).alpha == 0.1f);
  CHECK(shadedBelow(*s, 0.5f, 0.1f).alpha == 0.5f);
  // Classification from the range [0.1, 0.5]: the sharpest, a glossy metal.
  CHECK(s->materials[0].alpha == 0.1f);
  CHECK(s->materials[0].isGlossy());
  CHECK(!s->materials[0].isDeltaOnly());
  RenderOptions o = test::smallRenderOptions(RenderMethod::PathTrace, 4, 3, 5);
  Film t = test::renderOnce(textured, o), a = test::renderOnce(sharp, o), b = test::renderOnce(rough, o);
  REQUIRE(t.width == 16);
  int sameA = 0, sameB = 0, n = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 6; ++x, ++n) {  // away from the seam (the pixel filter spans it)
      size_t l = size_t(y) * 16 + size_t(x), r = size_t(y) * 16 + size_t(15 - x);
      sameA += t.color[l].r == a.color[l].r && t.color[l].g == a.color[l].g && t.color[l].b == a.color[l].b;
      sameB += t.color[r].r == b.color[r].r && t.color[r].g == b.color[r].g && t.color[r].b == b.color[r].b;
    }
  CHECK(sameA == n);
  CHECK(sameB == n);
  // And the halves do differ between the two roughnesses (the test can fail).
  CHECK(!test::sameImage(a, b));
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured roughness from pbrt: remaproughness per hit (v4 sqrt, v3 polynomial, off), classification from the range") {
  auto build = [](const std::string& material) {
    std::string text = "WorldBegin\nTexture \"r\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0.01 \"float tex2\" 0.25\n"
                       "Texture \"z\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0 \"float tex2\" 0.0000001\n"
                       "Texture \"h\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0 \"float tex2\" 0.25\n"
                       "Texture \"g\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float tex1\" 0.09 \"float tex2\" 0.25\n" +
                       material + "\nShape \"bilinearmesh\" \"point3 P\" [-1 0 -1 1 0 -1 -1 0 1 1 0 1] \"point2 uv\" [0 0 1 0 0 1 1 1]\n";
    return Scene::build(pbrt::importPbrtText(text, "dir/t.pbrt").scene);
  };
  {  // pbrt-v4's conductor: alpha = sqrt(r) per hit.
    auto s = build("Material \"conductor\" \"texture roughness\" \"r\"");
    CHECK(pbrtBelow(*s, -0.5f, 0.1f).alpha == doctest::Approx(0.1f).epsilon(1e-6));
    CHECK(pbrtBelow(*s, 0.5f, 0.1f).alpha == doctest::Approx(0.5f).epsilon(1e-6));
    CHECK(s->materials[0].alpha == doctest::Approx(0.1f).epsilon(1e-6));
    CHECK(s->materials[0].isGlossy());
  }
  {  // remaproughness off: the texture is alpha; the range [0.01, 0.25] is glossy at its sharp end.
    auto s = build("Material \"conductor\" \"texture roughness\" \"r\" \"bool remaproughness\" false");
    CHECK(pbrtBelow(*s, -0.5f, 0.1f).alpha == doctest::Approx(0.01f).epsilon(1e-6));
    CHECK(pbrtBelow(*s, 0.5f, 0.1f).alpha == doctest::Approx(0.25f).epsilon(1e-6));
  }
  {  // pbrt-v3's metal: RoughnessToAlpha's polynomial in log r.
    auto s = build("Material \"metal\" \"texture roughness\" \"r\"");
    auto v3 = [](double r) {
      double x = std::log(r);
      return 1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x + 0.000640711 * x * x * x * x;
    };
    CHECK(pbrtBelow(*s, -0.5f, 0.1f).alpha == doctest::Approx(v3(0.01)).epsilon(1e-5));
    CHECK(pbrtBelow(*s, 0.5f, 0.1f).alpha == doctest::Approx(v3(0.25)).epsilon(1e-5));
    CHECK(s->materials[0].alpha == doctest::Approx(v3(0.01)).epsilon(1e-5));  // 0.139: the sharp end
    CHECK(s->materials[0].isGlossy());
  }
  {  // Range [0.09, 0.25] -> alphas [0.3, 0.5]: above kGlossyAlpha everywhere, a diffuse-like gather surface.
    auto s = build("Material \"conductor\" \"texture roughness\" \"g\"");
    CHECK(s->materials[0].alpha == doctest::Approx(0.3f).epsilon(1e-6));
    CHECK(!s->materials[0].isGlossy());
    CHECK(!s->materials[0].isDeltaOnly());
  }
  {  // Smooth everywhere: a delta conductor, as a constant roughness 0.
    auto s = build("Material \"conductor\" \"texture roughness\" \"z\"");
    CHECK(s->materials[0].isDeltaOnly());
    CHECK(s->materials[0].roughnessTexture == -1);
  }
  {  // Smooth on one half only: non-delta, the smooth half clamped to alpha 1e-3 (no division by zero).
    auto s = build("Material \"conductor\" \"texture roughness\" \"h\"");
    CHECK(!s->materials[0].isDeltaOnly());
    CHECK(s->materials[0].isGlossy());
    CHECK(pbrtBelow(*s, -0.5f, 0.1f).alpha == 1e-3f);
    CHECK(pbrtBelow(*s, 0.5f, 0.1f).alpha == doctest::Approx(0.5f).epsilon(1e-6));
  }
  {  // A rough dielectric that is smooth on one half stays a rough dielectric (a caustic bounce).
    auto s = build("Material \"dielectric\" \"texture roughness\" \"h\"");
    CHECK(s->materials[0].type == Material::Type::RoughDielectric);
    CHECK(pbrtBelow(*s, -0.5f, 0.1f).alpha == 1e-3f);
  }
}

TEST_CASE("textured Ks (uber, substrate) and conductor reflectance: per-hit values; convert round trip renders the same pixels") {
  std::string dir = test::makeTempDir();
  std::string text = R"(LookAt 0 3 0  0 0 0  0 0 -1
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 12 "integer yresolution" 12
WorldBegin
LightSource "distant" "rgb L" [2 2 2] "point3 from" [0.3 1 0] "point3 to" [0 0 0]
Texture "ks" "spectrum" "checkerboard" "float uscale" 2 "rgb tex1" [0.1 0.2 0.3] "rgb tex2" [0.6 0.5 0.4]
Texture "r" "float" "checkerboard" "float vscale" 2 "float tex1" 0.04 "float tex2" 0.3
Texture "refl" "spectrum" "checkerboard" "float uscale" 2 "rgb tex1" [0.9 0.5 0.2] "rgb tex2" [0.3 0.6 0.9]
AttributeBegin
Material "uber" "texture Ks" "ks" "texture roughness" "r"
Shape "bilinearmesh" "point3 P" [-1 0 -1 1 0 -1 -1 0 1 1 0 1] "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
AttributeBegin
Translate 3 0 0
Material "conductor" "texture reflectance" "refl" "texture roughness" "r"
Shape "bilinearmesh" "point3 P" [-1 0 -1 1 0 -1 -1 0 1 1 0 1] "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
AttributeBegin
Translate -3 0 0
Material "coatedconductor" "texture conductor.roughness" "r" "texture interface.roughness" "r"
Shape "bilinearmesh" "point3 P" [-1 0 -1 1 0 -1 -1 0 1 1 0 1] "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
AttributeBegin
Translate 0 0.4 0
Material "substrate" "texture Ks" "ks" "texture vroughness" "r" "texture uroughness" "r"
Shape "sphere" "float radius" 0.3
AttributeEnd
)";
  test::writeFile(dir + "/s.pbrt", text);
  pbrt::ImportResult r = pbrt::importPbrtFile(dir + "/s.pbrt");
  scene::SceneDescription& d = r.scene;
  REQUIRE(d.materials.size() == 4);
  auto s = Scene::build(d);
  Material uber = pbrtBelow(*s, -0.5f, -0.5f);  // u < 1/2, v > 1/2 (v runs against z)
  checkRgb(uber.specular, Rgb(0.1f, 0.2f, 0.3f));
  checkRgb(pbrtBelow(*s, 0.5f, -0.5f).specular, Rgb(0.6f, 0.5f, 0.4f));
  double x = std::log(0.04);  // uber is pbrt-v3's: RoughnessToAlpha of tex1
  CHECK(uber.alpha == doctest::Approx(1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x +
                                      0.000640711 * x * x * x * x).epsilon(1e-5));
  Material cond = pbrtBelow(*s, 2.5f, 0.5f);
  checkRgb(cond.eta, Rgb(1.0f));
  for (int i = 0; i < 3; ++i) {
    float ri = Rgb(0.9f, 0.5f, 0.2f)[i];
    CHECK(cond.k[i] == doctest::Approx(2 * std::sqrt(ri) / std::sqrt(1 - ri)).epsilon(1e-5));
  }
  // The coated conductor: both roughnesses per hit, pbrt-v4's sqrt (v = 3/4: tex2 = 0.3).
  Material coated = pbrtBelow(*s, -3.5f, 0.5f);
  CHECK(coated.baseAlpha == doctest::Approx(std::sqrt(0.3f)).epsilon(1e-6));
  CHECK(coated.alpha == doctest::Approx(std::sqrt(0.3f)).epsilon(1e-6));
  CHECK(pbrtBelow(*s, -3.5f, -0.5f).baseAlpha == doctest::Approx(0.2f).epsilon(1e-6));
  // The round trip: the JSON names the textures and renders the same pixels.
  std::string json = dir + "/s.json";
  pbrt::writeSceneJson(d, json);
  std::ifstream in(json);
  std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(contains(written, "\"roughness\": \"r\""));
  CHECK(contains(written, "\"roughness_remap\": \"pbrt-v4\""));
  CHECK(contains(written, "\"roughness_remap\": \"pbrt-v3\""));
  CHECK(contains(written, "\"specular\": \"ks\""));
  CHECK(contains(written, "\"color\": \"refl\""));
  CHECK(contains(written, "\"conductor_roughness\": \"r\""));
  checkJsonRoundTrip(d, json);
  std::filesystem::remove_all(dir);
}

TEST_CASE("textured material parameters: bad input gets located errors") {
  std::string dir = test::makeTempDir();
  std::string p = dir + "/s.json";
  const std::string texs = R"("f": {"type": "constant", "value": 0.3, "float": true}, "c": {"type": "constant", "value": [0.3, 0.3, 0.3]})";
  auto json = [&](const std::string& material) {
    return errorOfJson(sceneText(R"("textures": {)" + texs + R"(}, "materials": {"m": )" + material + R"(}, "objects": [])"), p);
  };
  CHECK(contains(json(R"({"type": "metal", "roughness": "c"})"),
                 "materials.m.roughness: texture \"c\" is a spectrum texture, but a float one is expected here"));
  CHECK(contains(json(R"({"type": "uber", "specular": "f"})"),
                 "materials.m.specular: texture \"f\" is a float texture, but a spectrum (RGB) one is expected here"));
  CHECK(contains(json(R"({"type": "metal", "roughness": "nope"})"), "unknown texture \"nope\""));
  CHECK(contains(json(R"({"type": "metal", "roughness": 0.3, "roughness_remap": "pbrt-v4"})"),
                 "materials.m.roughness_remap: roughness_remap applies only to a textured roughness"));
  CHECK(contains(json(R"({"type": "metal", "roughness": "f", "roughness_remap": "v5"})"), "materials.m.roughness_remap"));
  // A texture whose values reach past alpha 1: refused when the scene is built.
  std::string big = sceneText(R"("textures": {"b": {"type": "checkerboard", "float": true, "tex1": 0.5, "tex2": 2}},
    "materials": {"m": {"type": "metal", "roughness": "b"}}, "objects": [{"shape": {"type": "quad", "size": [1, 1]}, "material": "m"}])");
  scene::SceneDescription d = scene::parseScene(big, p);
  CHECK(contains(test::errorMessageOf([&] { Scene::build(d); }), "material \"m\": its roughness texture's values"));
  // pbrt: a spectrum texture as a roughness, a textured coated conductor's base roughness.
  auto pbrtError = [&](const std::string& body) {
    return test::errorMessageOf([&] { pbrt::importPbrtText("WorldBegin\n" + body, dir + "/t.pbrt"); });
  };
  const std::string defs = "Texture \"s\" \"spectrum\" \"checkerboard\"\nTexture \"f\" \"float\" \"checkerboard\"\n";
  CHECK(contains(pbrtError(defs + "Material \"conductor\" \"texture roughness\" \"s\"\n"),
                 "t.pbrt:4: Material \"conductor\": parameter \"texture roughness\": texture \"s\" is a spectrum texture, but a "
                 "roughness needs a float one"));
  CHECK(contains(pbrtError(defs + "Material \"coatedconductor\" \"texture conductor.roughness\" \"s\"\n"),
                 "texture \"s\" is a spectrum texture, but a roughness needs a float one"));
  CHECK(contains(pbrtError(defs + "Material \"conductor\" \"texture uroughness\" \"f\" \"float vroughness\" 0.1\n"),
                 "anisotropic roughness"));
  CHECK(contains(pbrtError(defs + "Material \"uber\" \"texture Ks\" \"f\"\n"), "is a float texture, but a reflectance needs a spectrum one"));
  CHECK(contains(pbrtError(defs + "Material \"uber\" \"texture opacity\" \"s\"\n"),
                 "a spectrum texture that varies is supported only on Kd of matte"));
  CHECK(contains(pbrtError(defs + "Material \"coateddiffuse\" \"texture eta\" \"f\"\n"),
                 "a float texture that varies is supported only as a roughness, a mix's amount, matte's sigma, "
                 "a coating's thickness"));
  std::filesystem::remove_all(dir);
}
