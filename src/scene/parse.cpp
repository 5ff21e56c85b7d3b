// scene/parse.cpp — owns turning a scene file (JSON) into a validated
// SceneDescription: the meaning of every key, its defaults and its valid
// range (docs/scene-format.md is the user-facing version of this file).
// Typed reading and the error format live in parse_node.*, positions in
// json_locate.*, OBJ loading in mesh_obj.*.
#include "scene/parse.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "core/error.h"
#include "math/bounds.h"
#include "motion/motion.h"
#include "image/texture_image.h"
#include "scene/environment.h"
#include "scene/json_locate.h"
#include "scene/limits.h"
#include "scene/mesh_obj.h"
#include "scene/subdivision.h"
#include "scene/parse_animation.h"
#include "scene/parse_media.h"
#include "scene/parse_node.h"
#include "scene/render_method.h"

namespace tdpm::scene {

namespace {

using detail::formatNumber;
using detail::formatRgb;
using detail::formatVec;
using detail::Json;
using detail::joinNames;
using detail::Node;
using detail::Source;

using limits::kMaxResolution;
constexpr float kDegrees = kPi / 180.0f;

struct Shutter {
  float open = 0, close = 1;
  const char* name = "the shutter";  // "the animation" when the interval is an animation's timeline
};

std::string fmt(double v) { return formatNumber(v); }

// The member if present, else the object: where to point an error about a
// value that may have come from a default.
Node memberOr(const Node& object, const char* key) { return object.has(key) ? object.member(key) : object; }

bool isZero(Vec3f v) { return v.x == 0 && v.y == 0 && v.z == 0; }

// Normalises in double, so any non-zero float vector (1e-40 or 3e38 per
// component) gives a unit vector; float arithmetic would underflow or
// overflow (v / m computes 1 / m, which is inf for m = 1e-40).
Vec3f safeNormalize(Vec3f v) {
  double x = v.x, y = v.y, z = v.z, len = std::sqrt(x * x + y * y + z * z);
  return {float(x / len), float(y / len), float(z / len)};
}

// ---------------------------------------------------------------- ranges

std::string coordinateRange() {
  return "within +-" + fmt(limits::kMaxCoordinate) + " m, the range the ray tracer handles (docs/scene-format.md)";
}

bool inRange(Vec3f p) {
  const float m = limits::kMaxCoordinate;  // false for NaN and inf too
  return std::fabs(p.x) <= m && std::fabs(p.y) <= m && std::fabs(p.z) <= m;
}

// A point the renderer uses as given (camera, light position).
void checkPoint(const Node& n, Vec3f p, const char* what) {
  n.require(inRange(p), std::string(what) + " " + formatVec(p) + " is out of range: coordinates must be " + coordinateRange());
}

// A scale factor per axis (placement times keyframe), as build.cpp composes it.
void checkScale(const Node& n, Vec3f s) {
  for (float c : {s.x, s.y, s.z})
    n.require(std::fabs(c) >= limits::kMinScale && std::fabs(c) <= limits::kMaxScale,
              "scale " + formatVec(s) + " is out of range: each factor's magnitude must be in [" + fmt(limits::kMinScale) +
                  ", " + fmt(limits::kMaxScale) + "] (the transform and its inverse must be finite)");
}

Vec3f readDirection(const Node& n) {
  Vec3f d = n.vec3();
  n.require(!isZero(d), "direction must not be a zero vector");
  return safeNormalize(d);
}

float readPositive(const Node& n, const char* what) {
  float v = n.number();
  n.require(v > 0, std::string(what) + " must be positive, got " + fmt(v));
  return v;
}

// A colour that a surface reflects or transmits: at most 1 per channel, or
// the material would create energy.
Rgb readReflectance(const Node& n) {
  Rgb c = n.color();
  n.require(c.maxComponent() <= 1.0f,
            "reflectance must be at most 1 in every channel (energy conservation), got " + formatRgb(c));
  return c;
}

// ---------------------------------------------------------------- transforms

Quaternion readRotation(const Node& n) {
  n.expectObject({"axis", "angle"});
  Node axisNode = n.required("axis");
  Vec3f axis = axisNode.vec3();
  axisNode.require(!isZero(axis), "rotation axis must not be a zero vector");
  float angle = n.required("angle").number();
  return Quaternion::fromAxisAngle(safeNormalize(axis), angle * kDegrees);
}

Vec3f readScale(const Node& n) {
  Vec3f s = n.numberOrVec3();
  n.require(s.x != 0 && s.y != 0 && s.z != 0, "scale must not have a zero component, got " + formatVec(s));
  return s;
}

void readPoseFields(const Node& n, TransformDesc* t) {
  if (n.has("translate")) t->translate = n.member("translate").vec3();
  if (n.has("rotate")) t->rotate = readRotation(n.member("rotate"));
  if (n.has("scale")) t->scale = readScale(n.member("scale"));
}

TransformDesc readTransform(const Node& n) {
  n.expectObject({"translate", "rotate", "scale"});
  TransformDesc t;
  readPoseFields(n, &t);
  return t;
}

// ---------------------------------------------------------------- motion

size_t keyframeCount(const Node& motion) {
  size_t n = motion.arraySize("keyframes");
  motion.require(n >= 2, "motion needs at least 2 keyframes, got " + std::to_string(n));
  return n;
}

// Keyframe `index`'s time: strictly after `previous`, inside the shutter.
float readKeyTime(const Node& key, size_t index, float previous, Shutter s) {
  Node t = key.required("time");
  float time = t.number();
  t.require(index == 0 || time > previous,
            "keyframe times must be strictly increasing: " + fmt(time) + " does not come after " + fmt(previous));
  t.require(time >= s.open && time <= s.close,
            "time " + fmt(time) + " is outside " + s.name + " [" + fmt(s.open) + ", " + fmt(s.close) + "]");
  // motion/motion.cpp divides a keyframe pair's rotation by its share of the
  // shutter (to choose the step count, an int): shares below ~4e-8 overflow it.
  float gap = limits::kMinKeyframeGap * (s.close - s.open);
  t.require(index == 0 || time - previous >= gap,
            "keyframe time " + fmt(time) + " is too close to the previous one (" + fmt(previous) +
                "): keyframes must be at least " + fmt(limits::kMinKeyframeGap) + " of the shutter apart");
  return time;
}

MotionDesc readMotion(const Node& n, Shutter s) {
  MotionDesc m;
  size_t count = keyframeCount(n);
  for (size_t i = 0; i < count; ++i) {
    Node key = n.element(i);
    key.expectObject({"time", "translate", "rotate", "scale"});
    m.times.push_back(readKeyTime(key, i, i ? m.times.back() : 0.0f, s));
    TransformDesc pose;  // identity unless given
    readPoseFields(key, &pose);
    m.poses.push_back(pose);
  }
  return m;
}

// ---------------------------------------------------------------- placement checks

// The motion exactly as scene/build.cpp makes it (placement, keyframes,
// resampled over the shutter), so the checks below see what the renderer will.
Motion motionOf(const TransformDesc& placement, const MotionDesc& motion, Shutter s) {
  if (motion.empty()) return Motion::still(placement.matrix());
  std::vector<MotionKey> keys;
  for (size_t i = 0; i < motion.times.size(); ++i)
    keys.push_back({motion.times[i], motion.poses[i].translate, motion.poses[i].rotate, motion.poses[i].scale});
  MotionKey p{0.0f, placement.translate, placement.rotate, placement.scale};
  return Motion::keyframed(p, keys, ::tdpm::Shutter{s.open, s.close});
}

// Scale factors as composed (keyframe times placement), and no keyframe pair
// whose linear blend passes through a zero scale.
void checkScales(const Node& n, const TransformDesc& placement, const MotionDesc& motion) {
  if (motion.empty()) {
    checkScale(memberOr(memberOr(n, "transform"), "scale"), placement.scale);
    return;
  }
  Node keys = n.member("motion");
  for (size_t i = 0; i < motion.poses.size(); ++i) {
    Node key = memberOr(keys.element(i), "scale");
    Vec3f s = motion.poses[i].scale;
    checkScale(key, s * placement.scale);
    if (i == 0) continue;
    Vec3f prev = motion.poses[i - 1].scale;
    key.require(prev.x * s.x > 0 && prev.y * s.y > 0 && prev.z * s.z > 0,
                "scale " + formatVec(s) + " has a sign opposite to the previous keyframe's " + formatVec(prev) +
                    ": the object would shrink through zero size in between");
  }
}

// World-space bounds over the shutter must stay in the supported range.
void checkWorldBounds(const Node& n, const Bounds3f& world, const char* what) {
  if (inRange(world.lo) && inRange(world.hi)) return;
  Vec3f far = inRange(world.lo) ? world.hi : world.lo;
  Node at = n.has("motion") ? n.member("motion") : memberOr(n, "transform");
  at.fail(std::string(what) + " reaches " + formatVec(far) +
          " in world space (after its transform and motion); coordinates must be " + coordinateRange());
}

// ---------------------------------------------------------------- camera

// A look-at frame must be well defined: distinct eye and target, up not
// along the view direction.
void checkView(const Node& at, Vec3f position, Vec3f target, Vec3f up) {
  memberOr(at, "target").require(!(position.x == target.x && position.y == target.y && position.z == target.z),
                                 "camera position and target are the same point " + formatVec(position));
  Node upNode = memberOr(at, "up");
  upNode.require(!isZero(up), "up must not be a zero vector");
  Vec3f dir = safeNormalize(target - position);
  upNode.require(length(cross(dir, safeNormalize(up))) > 1e-4f,
                 "up " + formatVec(up) + " is parallel to the view direction " + formatVec(dir));
  checkPoint(memberOr(at, "position"), position, "camera position");
  checkPoint(memberOr(at, "target"), target, "camera target");
  // The camera normalises in float (scene/camera.cpp): tiny differences underflow.
  Vec3f forward = normalize(target - position);
  memberOr(at, "target").require(isFinite(forward), "camera target " + formatVec(target) + " is too close to the position " +
                                                        formatVec(position) + " to give a view direction in float");
  upNode.require(isFinite(normalize(cross(forward, up))),
                 "up " + formatVec(up) + " is too small to give a camera frame in float");
}

void readResolution(const Node& n, CameraDesc* cam) {
  size_t size = n.arraySize("2 integers [width, height]");
  n.require(size == 2, "expected an array of 2 integers [width, height], got " + detail::describeKind(n.json()));
  int64_t w = n.element(0).integer(), h = n.element(1).integer();
  std::string res = std::to_string(w) + "x" + std::to_string(h);
  n.require(w >= 1 && h >= 1, "resolution must be at least 1x1, got " + res);
  n.require(w <= kMaxResolution && h <= kMaxResolution,
            "resolution " + res + " is too large (at most " + std::to_string(kMaxResolution) + " per side)");
  cam->width = int(w);
  cam->height = int(h);
}

void readShutter(const Node& n, CameraDesc* cam) {
  Vec2f s = n.vec2();
  n.require(s.y >= s.x, "shutter close (" + fmt(s.y) + ") is before open (" + fmt(s.x) + ")");
  // The renderer maps scene time to [0, 1] by (t - open) / (close - open) in float.
  n.require(std::isfinite(s.y - s.x), "shutter [" + fmt(s.x) + ", " + fmt(s.y) +
                                          "] is too long: its duration overflows a 32-bit float");
  cam->shutterOpen = s.x;
  cam->shutterClose = s.y;
}

// Camera keyframes default to the camera's own position, target and up.
std::vector<CameraKeyframe> readCameraMotion(const Node& n, const CameraDesc& cam, const char* interval) {
  std::vector<CameraKeyframe> keys;
  size_t count = keyframeCount(n);
  Shutter s{cam.shutterOpen, cam.shutterClose, interval};
  for (size_t i = 0; i < count; ++i) {
    Node key = n.element(i);
    key.expectObject({"time", "position", "target", "up"});
    CameraKeyframe k{0, cam.position, cam.target, cam.up};
    k.time = readKeyTime(key, i, i ? keys.back().time : 0.0f, s);
    if (key.has("position")) k.position = key.member("position").vec3();
    if (key.has("target")) k.target = key.member("target").vec3();
    if (key.has("up")) k.up = key.member("up").vec3();
    checkView(key, k.position, k.target, k.up);
    keys.push_back(k);
  }
  return keys;
}

// Thin lens: lens_radius >= 0 (0: pinhole), focal_distance > 0, by default
// the distance from position to target (the point looked at is in focus).
void readLens(const Node& n, CameraDesc* cam) {
  cam->focalDistance = length(cam->target - cam->position);
  if (n.has("lens_radius")) {
    Node r = n.member("lens_radius");
    cam->lensRadius = r.number();
    r.require(cam->lensRadius >= 0, "lens_radius must be >= 0 (0: a pinhole camera), got " + fmt(cam->lensRadius));
    r.require(cam->lensRadius <= limits::kMaxCoordinate,
              "lens_radius " + fmt(cam->lensRadius) + " is too large; lengths must be " + coordinateRange());
  }
  if (n.has("focal_distance")) {
    Node f = n.member("focal_distance");
    cam->focalDistance = f.number();
    f.require(cam->focalDistance > 0, "focal_distance must be > 0 (metres along the view direction), got " +
                                          fmt(cam->focalDistance));
    f.require(cam->focalDistance <= limits::kMaxCoordinate,
              "focal_distance " + fmt(cam->focalDistance) + " is too large; lengths must be " + coordinateRange());
  }
}

CameraDesc readCamera(const Node& n, const std::optional<AnimationDesc>& animation) {
  n.expectObject({"position", "target", "up", "fov", "resolution", "shutter", "motion", "lens_radius", "focal_distance",
                  "medium"});
  CameraDesc cam;
  if (animation) {
    // The animation's timeline is the shutter every keyframe lives in.
    cam.shutterOpen = 0.0f;
    cam.shutterClose = float(animation->duration());
  }
  if (n.has("position")) cam.position = n.member("position").vec3();
  if (n.has("target")) cam.target = n.member("target").vec3();
  if (n.has("up")) cam.up = n.member("up").vec3();
  checkView(n, cam.position, cam.target, cam.up);
  if (n.has("fov")) {
    Node f = n.member("fov");
    cam.fovDegrees = f.number();
    f.require(cam.fovDegrees > 0 && cam.fovDegrees < 180, "fov must be in (0, 180) degrees, got " + fmt(cam.fovDegrees));
  }
  if (n.has("resolution")) readResolution(n.member("resolution"), &cam);
  if (n.has("shutter")) {
    n.member("shutter").require(!animation, "camera.shutter cannot be used together with \"animation\": each frame's "
                                            "shutter is [i / fps, i / fps + (shutter_angle / 360) / fps]; remove "
                                            "camera.shutter or the animation block");
    readShutter(n.member("shutter"), &cam);
  }
  if (n.has("motion")) cam.motion = readCameraMotion(n.member("motion"), cam, animation ? "the animation" : "the shutter");
  readLens(n, &cam);
  return cam;
}

// ---------------------------------------------------------------- materials

TextureDesc readTexture(const Node& n) {
  n.requireObject();
  std::string kind = n.required("type").choice({"constant", "checker"}, "texture type");
  TextureDesc t;
  if (kind == "constant") {
    n.expectObject({"type", "color"});
    if (n.has("color")) t.color = readReflectance(n.member("color"));
    return t;
  }
  n.expectObject({"type", "colors", "scale"});
  t.kind = TextureDesc::Kind::Checker;
  if (n.has("colors")) {
    Node c = n.member("colors");
    size_t size = c.arraySize("2 colours");
    c.require(size == 2, "expected an array of 2 colours, got " + detail::describeKind(c.json()));
    t.color = readReflectance(c.element(0));
    t.color2 = readReflectance(c.element(1));
  }
  if (n.has("scale")) {
    t.scale = readPositive(n.member("scale"), "checker scale (cell size)");
    // The renderer multiplies by 1 / scale (scene/build.cpp).
    n.member("scale").require(std::isfinite(1.0f / t.scale), "checker scale " + fmt(t.scale) + " is too small (1 / scale overflows)");
  }
  return t;
}

// ---------------------------------------------------------------- named textures
// "textures": {"name": {...}} (docs/scene-format.md, "Textures"). Inputs
// name other textures, so they are read on demand (JSON objects have no
// order) with a cycle check; each lands in SceneDescription::textures after
// its inputs. Images are read once per (file, encoding).
std::string resolveMeshPath(const std::string& file, const std::string& sceneDir);

// Set while parseScene(text, path, meshes[, images]) runs (on this thread only).
thread_local const MeshSource* tMeshSource = nullptr;
thread_local const ImageSource* tImageSource = nullptr;
// An image the caller of parseScene lends (ImageSource), or null.
std::shared_ptr<const image::ImageRgb> lentImage(const std::string& file, const std::string& key) {
  return tImageSource ? (*tImageSource)(file, key) : nullptr;
}

class TextureReader {
 public:
  TextureReader(const Node& block, const std::string& sceneDir, std::vector<TextureDef>* out)
      : block_(block), sceneDir_(sceneDir), out_(out) {}

  void readAll() {
    block_.forEachMember([&](const std::string& name, const Node& n) { index(name, n); });
  }
  // The index of texture `name` (reading it first if needed); `from` is
  // where the reference was written, for the error.
  int32_t index(const std::string& name, const Node& from) {
    auto done = indices_.find(name);
    if (done != indices_.end()) return done->second;
    if (!block_.has(name)) {
      std::vector<std::string> names;
      block_.forEachMember([&](const std::string& k, const Node&) { names.push_back(k); });
      from.fail("unknown texture \"" + name + "\"; " +
                (names.empty() ? "no textures are defined" : "defined textures: " + joinNames(names)));
    }
    if (reading_.count(name)) from.fail("texture \"" + name + "\" refers to itself (through its inputs)");
    from.require(reading_.size() < limits::kMaxTextureDepth,
                 "textures nest more than " + std::to_string(limits::kMaxTextureDepth) + " deep");
    reading_.insert(name);
    TextureDef t = read(block_.member(name), name);
    reading_.erase(name);
    out_->push_back(std::move(t));
    int32_t i = int32_t(out_->size() - 1);
    indices_[name] = i;
    return i;
  }
  std::vector<TextureDef>* out() const { return out_; }

 private:
  // A number, [r, g, b] or a texture's name; `isFloat`: a float input (a
  // number, or a float texture).
  TexInput input(const Node& n, bool isFloat, const char* what) {
    TexInput in;
    if (n.json().is_string()) {
      in.texture = index(n.string(), n);
      bool f = (*out_)[size_t(in.texture)].isFloat;
      if (f != isFloat)
        n.fail(std::string(what) + ": texture \"" + n.string() + "\" is a " + (f ? "float" : "spectrum (RGB)") +
               " texture, but a " + (isFloat ? "float" : "spectrum (RGB)") + " one is expected here");
      return in;
    }
    if (isFloat) {
      in.value = Rgb(n.number());
      n.require(in.value.r >= 0, std::string(what) + " must not be negative");
    } else {
      in.value = n.color();
    }
    return in;
  }
  void readUvMapping(const Node& n, TextureDef* t) {
    if (n.has("uscale")) t->uscale = n.member("uscale").number();
    if (n.has("vscale")) t->vscale = n.member("vscale").number();
    if (n.has("udelta")) t->udelta = n.member("udelta").number();
    if (n.has("vdelta")) t->vdelta = n.member("vdelta").number();
  }
  TextureDef read(const Node& n, const std::string& name);
  void readImage(const Node& n, TextureDef* t);

  Node block_;
  std::string sceneDir_;
  std::vector<TextureDef>* out_;
  std::map<std::string, int32_t> indices_;
  std::set<std::string> reading_;
  std::map<std::pair<std::string, std::string>, std::shared_ptr<const image::ImageRgb>> images_;
};

void TextureReader::readImage(const Node& n, TextureDef* t) {
  Node f = n.required("file");
  std::string file = f.string();
  f.require(!file.empty(), "texture file name must not be empty");
  t->file = resolveMeshPath(file, sceneDir_);
  if (n.has("encoding")) {
    Node e = n.member("encoding");
    std::string s = e.string();
    if (s == "sRGB") t->encoding.kind = image::TexelEncoding::Kind::Srgb;
    else if (s == "linear") t->encoding.kind = image::TexelEncoding::Kind::Linear;
    else if (s.compare(0, 6, "gamma ") == 0) {
      char* end = nullptr;
      double g = std::strtod(s.c_str() + 6, &end);
      e.require(end && *end == 0 && g > 0 && g < 100, "encoding \"" + s + "\": the gamma must be a number in (0, 100)");
      t->encoding = {image::TexelEncoding::Kind::Gamma, float(g)};
    } else {
      e.fail("unknown encoding \"" + s + "\" (sRGB, linear or \"gamma <g>\")");
    }
  }
  if (n.has("wrap")) {
    std::string w = n.member("wrap").choice({"repeat", "clamp", "black"}, "wrap mode");
    t->wrap = w == "repeat" ? TextureDef::Wrap::Repeat : w == "clamp" ? TextureDef::Wrap::Clamp : TextureDef::Wrap::Black;
  }
  if (n.has("filter"))
    t->filter = n.member("filter").choice({"bilinear", "point"}, "texture filter") == "point" ? TextureDef::Filter::Point
                                                                                             : TextureDef::Filter::Bilinear;
  if (n.has("scale")) {
    t->scale = n.member("scale").number();
    n.member("scale").require(t->scale >= 0, "scale must not be negative, got " + fmt(t->scale));
  }
  if (n.has("invert")) {
    Node v = n.member("invert");
    v.require(v.json().is_boolean(), "expected true or false, got " + detail::describeKind(v.json()));
    t->invert = v.json().get<bool>();
  }
  auto key = std::make_pair(t->file, image::encodingName(t->encoding));
  auto& img = images_[key];
  if (!img) img = lentImage(key.first, key.second);
  if (!img) {
    try {
      img = std::make_shared<const image::ImageRgb>(image::readTextureImage(t->file, t->encoding));
    } catch (const Error& e) {
      images_.erase(key);
      f.fail(e.what());
    }
  }
  t->image = img;
}

TextureDef TextureReader::read(const Node& n, const std::string& name) {
  n.requireObject();
  std::string kind =
      n.required("type").choice({"constant", "image", "scale", "mix", "checkerboard", "checker3d"}, "texture type");
  TextureDef t;
  t.name = name;
  if (n.has("float")) {
    Node v = n.member("float");
    v.require(v.json().is_boolean(), "expected true or false, got " + detail::describeKind(v.json()));
    t.isFloat = v.json().get<bool>();
  }
  const std::vector<std::string> uv = {"uscale", "vscale", "udelta", "vdelta"};
  auto keys = [&](std::vector<std::string> k, bool mapping) {
    k.insert(k.end(), {"type", "float"});
    if (mapping) k.insert(k.end(), uv.begin(), uv.end());
    n.expectObject(k);
  };
  if (kind == "constant") {
    keys({"value"}, false);
    t.kind = TextureDef::Kind::Constant;
    t.a = input(n.required("value"), t.isFloat, "value");
  } else if (kind == "image") {
    keys({"file", "encoding", "wrap", "filter", "scale", "invert"}, true);
    t.kind = TextureDef::Kind::Image;
    readUvMapping(n, &t);
    readImage(n, &t);
  } else if (kind == "scale") {
    keys({"texture", "scale"}, false);
    t.kind = TextureDef::Kind::Scale;
    if (n.has("texture")) t.a = input(n.member("texture"), t.isFloat, "texture");
    if (n.has("scale")) {
      // A number or float texture; on a spectrum texture also an [r, g, b]
      // or a spectrum texture (pbrt-v3's tex1 x tex2, translucent's lobes).
      Node sc = n.member("scale");
      bool rgb = !t.isFloat && (sc.json().is_array() ||
                                (sc.json().is_string() && !(*out_)[size_t(index(sc.string(), sc))].isFloat));
      t.b = input(sc, !rgb, "scale");
    }
  } else if (kind == "mix") {
    keys({"tex1", "tex2", "amount"}, false);
    t.kind = TextureDef::Kind::Mix;
    t.a.value = Rgb(0.0f);
    t.amount.value = Rgb(0.5f);
    if (n.has("tex1")) t.a = input(n.member("tex1"), t.isFloat, "tex1");
    if (n.has("tex2")) t.b = input(n.member("tex2"), t.isFloat, "tex2");
    if (n.has("amount")) t.amount = input(n.member("amount"), true, "amount");
  } else {
    bool flat = kind == "checkerboard";
    keys(flat ? std::vector<std::string>{"tex1", "tex2"} : std::vector<std::string>{"tex1", "tex2", "scale"}, flat);
    t.kind = flat ? TextureDef::Kind::Checkerboard : TextureDef::Kind::Checker3D;
    t.b.value = Rgb(0.0f);
    if (n.has("tex1")) t.a = input(n.member("tex1"), t.isFloat, "tex1");
    if (n.has("tex2")) t.b = input(n.member("tex2"), t.isFloat, "tex2");
    if (flat) readUvMapping(n, &t);
    else if (n.has("scale")) {
      t.cell = readPositive(n.member("scale"), "checker3d scale (cell size)");
      n.member("scale").require(std::isfinite(1.0f / t.cell), "checker3d scale " + fmt(t.cell) + " is too small");
    }
  }
  return t;
}

// Diffuse reflectance / plastic base colour: "color", or "texture" (an
// inline constant or checker, or the name of a spectrum texture).
TextureDesc readAlbedo(const Node& n, TextureReader* textures, int32_t* named) {
  if (n.has("color") && n.has("texture"))
    n.member("texture").fail("give either \"color\" or \"texture\", not both");
  TextureDesc t;
  if (n.has("color")) t.color = readReflectance(n.member("color"));
  if (n.has("texture")) {
    Node tn = n.member("texture");
    if (tn.json().is_string()) {
      if (!textures) tn.fail("unknown texture \"" + tn.string() + "\"; no textures are defined");
      *named = textures->index(tn.string(), tn);
      const TextureDef& d = (*textures->out())[size_t(*named)];
      if (d.isFloat) tn.fail("texture \"" + tn.string() + "\" is a float texture, but a spectrum (RGB) one is expected here");
    } else {
      t = readTexture(tn);
    }
  }
  return t;
}

float readIor(const Node& n) {
  float ior = n.number();
  n.require(ior >= 1, "ior must be at least 1, got " + fmt(ior));
  return ior;
}

float readRoughness(const Node& n) {
  float r = n.number();
  n.require(r > 0 && r <= 1, "roughness must be in (0, 1], got " + fmt(r));
  return r;
}

// pbrt's materials take roughness 0 for smooth (scene/build.cpp).
float readRoughnessOrZero(const Node& n) {
  float r = n.number();
  n.require(r >= 0 && r <= 1, "roughness must be in [0, 1], got " + fmt(r));
  return r;
}

// A material parameter naming a texture: its index, a located error when
// it is unknown or of the other kind (float / spectrum).
int32_t namedTextureIndex(const Node& c, TextureReader* textures, bool isFloat) {
  if (!textures) c.fail("unknown texture \"" + c.string() + "\"; no textures are defined");
  int32_t i = textures->index(c.string(), c);
  if ((*textures->out())[size_t(i)].isFloat != isFloat)
    c.fail("texture \"" + c.string() + "\" is a " + (isFloat ? "spectrum" : "float") + " texture, but a " +
           (isFloat ? "float" : "spectrum (RGB)") + " one is expected here");
  return i;
}
int32_t spectrumTextureIndex(const Node& c, TextureReader* textures) { return namedTextureIndex(c, textures, false); }

// A conductor's (coated conductor's) complex IOR: "eta" and "k", or a
// normal-incidence reflectance "color", which becomes eta = 1, k = 2 sqrt(r)
// / sqrt(1 - r) (pbrt-v4's conductor "reflectance": the Fresnel curve
// through r). Each may name a spectrum texture (per hit, Scene::shadedMaterial).
void readConductor(const Node& n, MaterialDesc* m, TextureReader* textures) {
  if (n.has("color") && (n.has("eta") || n.has("k")))
    n.member("color").fail("give either \"color\" (a reflectance) or \"eta\" and \"k\", not both");
  if (n.has("color") && n.member("color").json().is_string()) {
    m->eta = Rgb(1.0f);  // per hit from the texture (Scene::shadedMaterial)
    m->k = Rgb(0.0f);
    m->specularTexture = spectrumTextureIndex(n.member("color"), textures);
    return;
  }
  if (n.has("color")) {
    Rgb r = readReflectance(n.member("color"));
    m->eta = Rgb(1.0f);
    for (int i = 0; i < 3; ++i) {
      float ri = std::min(r[i], 0.9999f);
      m->k[i] = 2.0f * std::sqrt(ri) / std::sqrt(1.0f - ri);
    }
    return;
  }
  // eta, k: each [r, g, b] or the name of a spectrum texture (per hit).
  Node eta = n.required("eta");
  if (eta.json().is_string()) {
    m->etaTexture = spectrumTextureIndex(eta, textures);
  } else {
    m->eta = eta.color();
    eta.require(m->eta.r > 0 && m->eta.g > 0 && m->eta.b > 0, "eta must be positive in every channel");
  }
  Node k = n.required("k");
  if (k.json().is_string()) m->kTexture = spectrumTextureIndex(k, textures);
  else m->k = k.color();
}

struct MaterialKind {
  const char* name;
  MaterialDesc::Type type;
  std::vector<std::string> keys;
};

const std::vector<MaterialKind>& materialKinds() {
  using T = MaterialDesc::Type;
  static const std::vector<MaterialKind> kinds = {
      {"diffuse", T::Diffuse, {"type", "color", "texture", "sigma"}},
      {"mirror", T::Mirror, {"type", "color"}},
      {"dielectric", T::Dielectric, {"type", "ior", "tint", "roughness", "roughness_remap"}},
      {"metal", T::Metal, {"type", "color", "roughness", "roughness_remap"}},
      {"plastic", T::Plastic, {"type", "color", "texture", "ior", "roughness", "roughness_remap"}},
      {"conductor", T::Conductor, {"type", "eta", "k", "color", "roughness", "roughness_remap"}},
      {"uber", T::Uber, {"type", "color", "texture", "specular", "ior", "roughness", "roughness_remap"}},
      {"substrate", T::Substrate, {"type", "color", "texture", "specular", "roughness", "roughness_remap"}},
      {"coateddiffuse", T::CoatedDiffuse, {"type", "color", "texture", "ior", "roughness", "roughness_remap", "thickness"}},
      {"coatedconductor", T::CoatedConductor,
       {"type", "ior", "roughness", "roughness_remap", "eta", "k", "color", "conductor_roughness", "thickness"}},
      {"mix", T::Mix, {"type", "materials", "amount"}},
      {"interface", T::Interface, {"type"}},  // no surface: a boundary between media (parse_media.h)
  };
  return kinds;
}

// A material's "bump": a float texture's name, or {"texture": name,
// "scale": s} (the displacement is s x the texture); "normal_map": an image
// file (resolved against the scene's folder), read as linear RGB as
// pbrt-v4 reads normal maps, whatever its bit depth.
void readShadingNormal(const Node& n, MaterialDesc* m, TextureReader* textures, const std::string& sceneDir) {
  if (n.has("bump")) {
    Node b = n.member("bump");
    if (b.json().is_string()) {
      m->bumpTexture = namedTextureIndex(b, textures, true);
    } else {
      b.requireObject();
      b.expectObject({"texture", "scale"});
      m->bumpTexture = namedTextureIndex(b.required("texture"), textures, true);
      if (b.has("scale")) {
        m->bumpScale = b.member("scale").number();
        b.member("scale").require(std::isfinite(m->bumpScale), "scale must be finite");
      }
    }
  }
  if (n.has("normal_map")) {
    Node f = n.member("normal_map");
    std::string file = f.string();
    f.require(!file.empty(), "normal_map file name must not be empty");
    m->normalMapFile = resolveMeshPath(file, sceneDir);
    image::TexelEncoding linear;
    linear.kind = image::TexelEncoding::Kind::Linear;
    m->normalMap = lentImage(m->normalMapFile, image::encodingName(linear));
    if (!m->normalMap) {
      try {
        m->normalMap = std::make_shared<const image::ImageRgb>(image::readTextureImage(m->normalMapFile, linear));
      } catch (const Error& e) {
        f.fail(e.what());
      }
    }
  }
}

// mixNames: a mix's two component names, resolved by readMaterials.
MaterialDesc readMaterial(const Node& n, const std::string& name, TextureReader* textures,
                          std::vector<std::string>* mixNames, const std::string& sceneDir) {
  using T = MaterialDesc::Type;
  n.requireObject();
  std::vector<std::string> names;
  for (const auto& k : materialKinds()) names.push_back(k.name);
  std::string typeName = n.required("type").choice(names, "material type");
  const MaterialKind& kind = *std::find_if(materialKinds().begin(), materialKinds().end(),
                                           [&](const MaterialKind& k) { return typeName == k.name; });
  std::vector<std::string> keys = kind.keys;
  if (kind.type != T::Mix && kind.type != T::Interface) keys.insert(keys.end(), {"bump", "normal_map"});
  n.expectObject(keys);
  MaterialDesc m;
  m.name = name;
  m.type = kind.type;
  bool pbrtKind = kind.type >= T::Conductor;
  if (kind.type == T::Mix) {
    Node list = n.required("materials");
    list.require(list.arraySize("2 material names") == 2, "expected an array of 2 material names");
    for (size_t i = 0; i < 2; ++i) {
      Node e = list.element(i);
      if (!e.json().is_string()) e.fail("expected a string (a material name), got " + detail::describeKind(e.json()));
      mixNames->push_back(e.string());
    }
    if (n.has("amount") && n.member("amount").json().is_string()) {
      // Per hit (Scene::materialAt): a float texture picks a material, a
      // spectrum one blends the two per channel (pbrt-v3's Spectrum amount).
      Node a = n.member("amount");
      if (!textures) a.fail("unknown texture \"" + a.string() + "\"; no textures are defined");
      m.amountTexture = textures->index(a.string(), a);
      m.amountPerChannel = !(*textures->out())[size_t(m.amountTexture)].isFloat;
    } else if (n.has("amount") && n.member("amount").json().is_array()) {
      Node a = n.member("amount");
      m.amountPerChannel = true;
      m.amountRgb = a.color();
      for (int i = 0; i < 3; ++i)
        a.require(m.amountRgb[i] >= 0 && m.amountRgb[i] <= 1, "amount must be in [0, 1] in every channel, got " + formatRgb(m.amountRgb));
    } else if (n.has("amount")) {
      m.amount = n.member("amount").number();
      n.member("amount").require(m.amount >= 0 && m.amount <= 1, "amount must be in [0, 1], got " + fmt(m.amount));
    }
    return m;
  }
  // A specular colour: a reflectance, or the name of a spectrum texture.
  auto specular = [&](const Node& c) {
    if (!c.json().is_string()) {
      m.specular = readReflectance(c);
      return;
    }
    m.specularTexture = spectrumTextureIndex(c, textures);
  };
  if (kind.type == T::Conductor || kind.type == T::CoatedConductor) {
    readConductor(n, &m, textures);
  } else {
    bool albedo = kind.type == T::Diffuse || kind.type == T::Plastic || kind.type == T::Uber ||
                  kind.type == T::Substrate || kind.type == T::CoatedDiffuse;
    if (albedo) m.albedo = readAlbedo(n, textures, &m.albedoTexture);
    else if (n.has("color")) specular(n.member("color"));
  }
  if (n.has("tint")) specular(n.member("tint"));
  if (n.has("specular")) specular(n.member("specular"));
  else if (kind.type == T::Uber || kind.type == T::Substrate) m.specular = Rgb(0.25f);  // pbrt-v3's Ks
  if (n.has("ior") && n.member("ior").json().is_string()) {
    // A float texture, per hit (pbrt-v3's glass and uber eta); build.cpp checks its range.
    n.member("ior").require(kind.type == T::Dielectric || kind.type == T::Uber,
                            "a textured ior is supported on dielectric and uber only");
    m.iorTexture = namedTextureIndex(n.member("ior"), textures, true);
  } else if (n.has("ior")) {
    m.ior = readIor(n.member("ior"));
  }
  if (kind.type == T::Dielectric && n.has("roughness")) {
    m.type = T::RoughDielectric;
    pbrtKind = true;
  }
  if (pbrtKind) m.roughness = 0.0f;
  if (n.has("roughness") && n.member("roughness").json().is_string()) {
    // A float texture, evaluated per hit (GGX alpha, or through roughness_remap).
    m.roughnessTexture = namedTextureIndex(n.member("roughness"), textures, true);
  } else if (n.has("roughness")) {
    m.roughness = pbrtKind ? readRoughnessOrZero(n.member("roughness")) : readRoughness(n.member("roughness"));
  }
  if (n.has("conductor_roughness") && n.member("conductor_roughness").json().is_string())
    m.baseRoughnessTexture = namedTextureIndex(n.member("conductor_roughness"), textures, true);
  else if (n.has("conductor_roughness"))
    m.baseRoughness = readRoughnessOrZero(n.member("conductor_roughness"));
  if (n.has("roughness_remap")) {
    Node r = n.member("roughness_remap");
    std::string v = r.choice({"none", "pbrt-v3", "pbrt-v4"}, "roughness_remap");
    r.require(m.roughnessTexture >= 0 || m.baseRoughnessTexture >= 0,
              "roughness_remap applies only to a textured roughness (a constant one is the GGX alpha)");
    m.roughnessRemap = v == "pbrt-v3" ? MaterialDesc::Remap::PbrtV3 : v == "pbrt-v4" ? MaterialDesc::Remap::PbrtV4 : MaterialDesc::Remap::None;
  }
  if (n.has("thickness") && n.member("thickness").json().is_string()) {
    m.thicknessTexture = namedTextureIndex(n.member("thickness"), textures, true);  // per hit; build.cpp checks its range
  } else if (n.has("thickness")) {
    m.thickness = n.member("thickness").number();
    n.member("thickness").require(m.thickness >= 0 && std::isfinite(m.thickness), "thickness must be non-negative, got " + fmt(m.thickness));
  }
  if (n.has("sigma") && n.member("sigma").json().is_string()) {
    m.sigmaTexture = namedTextureIndex(n.member("sigma"), textures, true);  // per hit, clamped to [0, 90]
  } else if (n.has("sigma")) {
    m.sigma = n.member("sigma").number();
    n.member("sigma").require(m.sigma >= 0 && m.sigma <= 90, "sigma (Oren-Nayar, degrees) must be in [0, 90], got " + fmt(m.sigma));
  }
  readShadingNormal(n, &m, textures, sceneDir);
  return m;
}

// Objects may say "material": "interface" without defining it: pbrt's
// no-surface material, only a boundary between media.
constexpr const char* kInterfaceMaterial = "interface";

std::vector<MaterialDesc> readMaterials(const Node& n, TextureReader* textures, const std::string& sceneDir) {
  std::vector<MaterialDesc> out;
  std::vector<std::pair<size_t, std::vector<std::string>>> mixes;
  std::vector<Node> nodes;
  n.forEachMember([&](const std::string& name, const Node& m) {
    m.require(!name.empty(), "material names must not be empty");
    std::vector<std::string> mixNames;
    out.push_back(readMaterial(m, name, textures, &mixNames, sceneDir));
    m.require(name != kInterfaceMaterial || out.back().type == MaterialDesc::Type::Interface,
              "the material name \"interface\" is reserved for {\"type\": \"interface\"} (no surface)");
    nodes.push_back(m);
    if (!mixNames.empty()) mixes.push_back({out.size() - 1, mixNames});
  });
  for (const auto& entry : mixes) {
    size_t i = entry.first;
    const std::vector<std::string>& mixNames = entry.second;  // not a structured binding: lambdas capture it
    for (size_t c = 0; c < 2; ++c) {
      auto it = std::find_if(out.begin(), out.end(), [&](const MaterialDesc& d) { return d.name == mixNames[c]; });
      Node e = nodes[i].member("materials").element(c);
      if (it == out.end()) e.fail("unknown material \"" + mixNames[c] + "\"");
      e.require(it->type != MaterialDesc::Type::Interface, "a mix cannot contain an interface material (no surface)");
      out[i].mix[c] = uint32_t(it - out.begin());
    }
  }
  // A mix may not contain itself (through other mixes either).
  for (const auto& entry : mixes) {
    size_t i = entry.first;
    std::vector<size_t> stack = {out[i].mix[0], out[i].mix[1]};
    std::vector<bool> seen(out.size(), false);
    while (!stack.empty()) {
      size_t j = stack.back();
      stack.pop_back();
      if (j == i) nodes[i].member("materials").fail("mix material \"" + out[i].name + "\" contains itself");
      if (seen[j] || out[j].type != MaterialDesc::Type::Mix) continue;
      seen[j] = true;
      stack.push_back(out[j].mix[0]);
      stack.push_back(out[j].mix[1]);
    }
  }
  return out;
}

// Objects without "material" use "default": the file's own, or else this.
constexpr const char* kDefaultMaterial = "default";

uint32_t resolveMaterial(const Node& object, std::vector<MaterialDesc>* materials) {
  std::string name = kDefaultMaterial;
  if (object.has("material")) {
    Node n = object.member("material");
    if (!n.json().is_string()) n.fail("expected a string (a material name), got " + detail::describeKind(n.json()));
    name = n.string();
  }
  for (size_t i = 0; i < materials->size(); ++i)
    if ((*materials)[i].name == name) return uint32_t(i);
  if (name == kInterfaceMaterial) {
    MaterialDesc none;
    none.type = MaterialDesc::Type::Interface;
    none.name = kInterfaceMaterial;
    materials->push_back(none);
    return uint32_t(materials->size() - 1);
  }
  if (!object.has("material")) {
    MaterialDesc grey;  // diffuse, reflectance 0.8
    grey.name = kDefaultMaterial;
    materials->push_back(grey);
    return uint32_t(materials->size() - 1);
  }
  std::vector<std::string> defined;
  for (const auto& m : *materials) defined.push_back(m.name);
  object.member("material").fail("unknown material \"" + name + "\"; " +
                                 (defined.empty() ? "no materials are defined" : "defined materials: " + joinNames(defined)));
}

// ---------------------------------------------------------------- shapes

std::string resolveMeshPath(const std::string& file, const std::string& sceneDir) {
  std::filesystem::path p(file);
  if (p.is_absolute() || sceneDir.empty()) return p.lexically_normal().string();
  return (std::filesystem::path(sceneDir) / p).lexically_normal().string();
}

// "subdivision": {"scheme": "loop", "levels": N}: the topology and the
// refined size are checked here, so that building cannot fail.
void readSubdivision(const Node& n, ShapeDesc* shape) {
  n.requireObject();
  n.expectObject({"scheme", "levels"});
  n.required("scheme").choice({"loop"}, "subdivision scheme");
  Node levels = n.required("levels");
  int64_t l = levels.integer();
  levels.require(l >= 0, "levels must be >= 0 (0 is the control mesh moved to its limit surface), got " + std::to_string(l));
  uint64_t tris = loopTriangleCount(shape->indices.size() / 3, int(std::min<int64_t>(l, 64)));
  levels.require(tris <= limits::kMaxSubdividedTriangles,
                 std::to_string(l) + " levels refine the " + std::to_string(shape->indices.size() / 3) + " triangles to " +
                     (tris == UINT64_MAX ? std::string("more than 2^64") : std::to_string(tris)) +
                     " triangles, more than the limit of " + std::to_string(limits::kMaxSubdividedTriangles) +
                     " (docs/scene-format.md, \"Limits\")");
  std::string problem = loopTopologyProblem(shape->indices, shape->vertices.size());
  n.require(problem.empty(), "the mesh cannot be Loop-subdivided: " + problem);
  shape->loopLevels = int(l);
}

void readMesh(const Node& n, const std::string& sceneDir, ShapeDesc* shape) {
  Node fileNode = n.required("file");
  std::string file = fileNode.string();
  fileNode.require(!file.empty(), "mesh file name must not be empty");
  shape->meshFile = resolveMeshPath(file, sceneDir);
  if (tMeshSource) {
    if (!(*tMeshSource)(file, &shape->vertices, &shape->indices)) fileNode.fail("no mesh \"" + file + "\" in memory");
    return;
  }
  ObjMesh mesh;
  std::string problem;
  if (!loadObjMesh(shape->meshFile, &mesh, &problem)) fileNode.fail(problem);
  shape->vertices = std::move(mesh.vertices);
  shape->indices = std::move(mesh.indices);
  shape->uvs = std::move(mesh.uvs);
  shape->normals = std::move(mesh.normals);
  if (n.has("subdivision")) {
    readSubdivision(n.member("subdivision"), shape);
    shape->uvs.clear();  // the refined triangles are new: pbrt's default uv each
    shape->normals.clear();  // and their geometric normals (docs/scene-format.md)
  }
}

// Disk: radius > 0, 0 <= inner_radius < radius, any height; cylinder:
// radius > 0, z_min < z_max; both phi_max in (0, 360] (pbrt's checks, plus
// what makes the surface empty: pbrt would render nothing there).
void readQuadric(const Node& n, ShapeDesc* s) {
  if (n.has("radius")) s->radius = readPositive(n.member("radius"), "radius");
  if (s->type == ShapeDesc::Type::Disk) {
    if (n.has("inner_radius")) {
      Node in = n.member("inner_radius");
      s->innerRadius = in.number();
      in.require(s->innerRadius >= 0, "inner_radius must be >= 0, got " + fmt(s->innerRadius));
      in.require(s->innerRadius < s->radius, "inner_radius " + fmt(s->innerRadius) + " must be below radius " + fmt(s->radius) +
                                                  " (the disk would be empty)");
    }
    if (n.has("height")) s->height = n.member("height").number();
    checkPoint(n, {s->radius, s->radius, s->height}, "disk extent");
  } else {
    if (n.has("z_min")) s->zMin = n.member("z_min").number();
    if (n.has("z_max")) s->zMax = n.member("z_max").number();
    n.require(s->zMin < s->zMax, "z_min " + fmt(s->zMin) + " must be below z_max " + fmt(s->zMax) + " (the cylinder would be empty)");
    checkPoint(n, {s->radius, std::fabs(s->zMin), std::fabs(s->zMax)}, "cylinder extent");
  }
  if (n.has("phi_max")) {
    Node p = n.member("phi_max");
    s->phiMax = p.number();
    p.require(s->phiMax > 0 && s->phiMax <= 360, "phi_max must be in (0, 360] degrees, got " + fmt(s->phiMax));
  }
}

ShapeDesc readShape(const Node& n, const std::string& sceneDir) {
  n.requireObject();
  std::string type = n.required("type").choice({"sphere", "quad", "box", "mesh", "disk", "cylinder"}, "shape type");
  ShapeDesc s;
  if (type == "sphere") {
    n.expectObject({"type", "radius", "reverse_orientation"});
    s.type = ShapeDesc::Type::Sphere;
    if (n.has("radius")) {
      s.radius = readPositive(n.member("radius"), "radius");
      checkPoint(n.member("radius"), Vec3f(s.radius), "radius");
    }
  } else if (type == "quad") {
    n.expectObject({"type", "size", "reverse_orientation"});
    s.type = ShapeDesc::Type::Quad;
    if (n.has("size")) {
      Node sz = n.member("size");
      Vec2f v = sz.vec2();
      sz.require(v.x > 0 && v.y > 0, "size must be positive in every dimension, got [" + fmt(v.x) + ", " + fmt(v.y) + "]");
      s.size = {v.x, 1.0f, v.y};  // a quad spans x and z; y is unused
      checkPoint(sz, s.size * 0.5f, "half size");
    }
  } else if (type == "box") {
    n.expectObject({"type", "size", "reverse_orientation"});
    s.type = ShapeDesc::Type::Box;
    if (n.has("size")) {
      Node sz = n.member("size");
      s.size = sz.vec3();
      sz.require(s.size.x > 0 && s.size.y > 0 && s.size.z > 0,
                 "size must be positive in every dimension, got " + formatVec(s.size));
      checkPoint(sz, s.size * 0.5f, "half size");
    }
  } else if (type == "disk") {
    n.expectObject({"type", "radius", "inner_radius", "height", "phi_max", "reverse_orientation"});
    s.type = ShapeDesc::Type::Disk;
    readQuadric(n, &s);
  } else if (type == "cylinder") {
    n.expectObject({"type", "radius", "z_min", "z_max", "phi_max", "reverse_orientation"});
    s.type = ShapeDesc::Type::Cylinder;
    readQuadric(n, &s);
  } else {
    n.expectObject({"type", "file", "subdivision", "reverse_orientation"});
    s.type = ShapeDesc::Type::Mesh;
    readMesh(n, sceneDir, &s);
  }
  if (n.has("reverse_orientation")) {
    Node r = n.member("reverse_orientation");
    r.require(r.json().is_boolean(), "expected true or false");
    s.reverseOrientation = r.json().get<bool>();
  }
  return s;
}

// ---------------------------------------------------------------- objects

// Object-space bounds, as scene/build.cpp computes them.
Bounds3f objectBounds(const ShapeDesc& shape) {
  Bounds3f b;
  switch (shape.type) {
    case ShapeDesc::Type::Sphere: b.extend(Vec3f(-shape.radius)); b.extend(Vec3f(shape.radius)); break;
    case ShapeDesc::Type::Quad: b.extend({-0.5f * shape.size.x, 0, -0.5f * shape.size.z}); b.extend({0.5f * shape.size.x, 0, 0.5f * shape.size.z}); break;
    case ShapeDesc::Type::Box: b.extend(shape.size * -0.5f); b.extend(shape.size * 0.5f); break;
    case ShapeDesc::Type::Mesh: for (Vec3f v : shape.vertices) b.extend(v); break;
    case ShapeDesc::Type::Disk: b.extend({-shape.radius, -shape.radius, shape.height}); b.extend({shape.radius, shape.radius, shape.height}); break;
    case ShapeDesc::Type::Cylinder: b.extend({-shape.radius, -shape.radius, shape.zMin}); b.extend({shape.radius, shape.radius, shape.zMax}); break;
  }
  return b;
}

std::string readName(const Node& n, const std::string& fallback) {
  if (!n.has("name")) return fallback;
  Node name = n.member("name");
  std::string s = name.string();
  name.require(!s.empty(), "name must not be empty");
  return s;
}

ObjectDesc readObject(const Node& n, std::vector<MaterialDesc>* materials, Shutter s, const std::string& sceneDir) {
  n.expectObject({"name", "shape", "material", "transform", "motion", "medium", "medium_interface"});
  ObjectDesc o;
  o.name = readName(n, n.path());
  o.shape = readShape(n.required("shape"), sceneDir);
  o.material = resolveMaterial(n, materials);
  if (n.has("transform")) o.placement = readTransform(n.member("transform"));
  if (n.has("motion")) o.motion = readMotion(n.member("motion"), s);
  checkScales(n, o.placement, o.motion);
  checkWorldBounds(n, motionOf(o.placement, o.motion, s).sweptBounds(objectBounds(o.shape)), "the object");
  return o;
}

// ---------------------------------------------------------------- lights

struct LightKind {
  const char* name;
  LightDesc::Type type;
  std::vector<std::string> keys;  // besides type, name, transform, motion
};

const std::vector<LightKind>& lightKinds() {
  static const std::vector<LightKind> kinds = {
      {"point", LightDesc::Type::Point, {"position", "power"}},
      {"spot", LightDesc::Type::Spot, {"position", "target", "direction", "cone_angle", "falloff_start", "power"}},
      {"directional", LightDesc::Type::Directional, {"direction", "irradiance"}},
      {"area", LightDesc::Type::Area, {"size", "power", "two_sided", "reverse_orientation"}},
      {"sphere", LightDesc::Type::Area, {"radius", "power", "two_sided", "reverse_orientation"}},
      {"disk", LightDesc::Type::Area, {"radius", "power", "two_sided", "reverse_orientation"}},
      {"mesh", LightDesc::Type::Area, {"file", "subdivision", "power", "two_sided", "reverse_orientation"}},
      {"environment", LightDesc::Type::Environment, {"L", "filename", "mapping", "scale"}},
  };
  return kinds;
}

void readSpot(const Node& n, LightDesc* l) {
  if (n.has("target") && n.has("direction")) n.member("direction").fail("give either \"target\" or \"direction\", not both");
  if (n.has("target")) {
    Node t = n.member("target");
    Vec3f target = t.vec3();
    t.require(!isZero(target - l->position), "spot target equals its position " + formatVec(target));
    checkPoint(t, target, "target");
    l->direction = safeNormalize(target - l->position);
  }
  if (n.has("direction")) l->direction = readDirection(n.member("direction"));
  if (n.has("cone_angle")) {
    Node c = n.member("cone_angle");
    l->coneAngle = c.number();
    c.require(l->coneAngle > 0 && l->coneAngle <= 90, "cone_angle must be in (0, 90] degrees, got " + fmt(l->coneAngle));
  }
  // Unless given, the falloff starts at 5/6 of the cone (25 of the default 30).
  l->falloffStart = l->coneAngle * (25.0f / 30.0f);
  if (n.has("falloff_start")) {
    Node f = n.member("falloff_start");
    l->falloffStart = f.number();
    f.require(l->falloffStart >= 0 && l->falloffStart <= l->coneAngle,
              "falloff_start must be in [0, cone_angle = " + fmt(l->coneAngle) + "] degrees, got " + fmt(l->falloffStart));
  }
}

void readAreaSize(const Node& n, LightDesc* l) {
  Vec2f v = n.vec2();
  n.require(v.x > 0 && v.y > 0, "size must be positive in every dimension, got [" + fmt(v.x) + ", " + fmt(v.y) + "]");
  l->areaSize = v;
}

// An environment light's radiance, scale and map (read and checked here, so
// that a missing, empty or negative map is an error at its "filename").
void readEnvironment(const Node& n, const std::string& sceneDir, LightDesc* l) {
  if (n.has("motion")) n.member("motion").fail("an environment light does not move (give \"transform\" only)");
  if (n.has("L")) l->radiance = n.member("L").color();
  if (n.has("scale")) {
    Node sc = n.member("scale");
    l->scale = sc.number();
    sc.require(l->scale >= 0 && std::isfinite(l->scale), "scale must be finite and non-negative, got " + fmt(l->scale));
  }
  if (n.has("mapping")) {
    Node m = n.member("mapping");
    if (!n.has("filename")) m.fail("\"mapping\" needs a \"filename\"");
    l->equalArea = m.choice({"latlong", "equal-area"}, "environment mapping") == "equal-area";
  }
  if (!n.has("filename")) return;
  Node f = n.member("filename");
  std::string file = f.string();
  f.require(!file.empty(), "environment map file name must not be empty");
  l->mapFile = resolveMeshPath(file, sceneDir);
  std::string problem;
  std::shared_ptr<const image::ImageRgb> map =
      lentImage(l->mapFile, l->equalArea ? "environment equal-area" : "environment latlong");
  if (!map) map = loadEnvironmentMap(l->mapFile, l->equalArea, &problem);
  if (!map) f.fail(problem);
  l->map = std::move(map);
}

bool readBool(const Node& n) {
  n.require(n.json().is_boolean(), "expected true or false");
  return n.json().get<bool>();
}

// A sphere, disk or mesh emitter's shape (the "area" rectangle reads "size").
void readEmitterShape(const Node& n, const std::string& typeName, const std::string& sceneDir, LightDesc* l) {
  if (typeName == "sphere") l->areaShape = LightDesc::AreaShape::Sphere;
  if (typeName == "disk") l->areaShape = LightDesc::AreaShape::Disk;
  if (typeName == "mesh") {
    l->areaShape = LightDesc::AreaShape::Mesh;
    l->mesh.type = ShapeDesc::Type::Mesh;
    readMesh(n, sceneDir, &l->mesh);
    n.member("file").require(!l->mesh.indices.empty(), "an emissive mesh needs at least one triangle");
  }
  if (n.has("radius")) {
    l->radius = readPositive(n.member("radius"), "radius");
    checkPoint(n.member("radius"), Vec3f(l->radius), "radius");
  }
  if (n.has("two_sided")) l->twoSided = readBool(n.member("two_sided"));
  if (n.has("reverse_orientation")) l->reverseOrientation = readBool(n.member("reverse_orientation"));
}

// The emitter's object-space box and, at each motion step, its area after
// the transform (checked > 1e-30 m^2 and finite). A sphere must scale
// uniformly, a disk alike along x and z (Embree's spheres and discs are
// round); a moving mesh may change size only uniformly (scene/light.h).
Bounds3f checkEmitterShape(const Node& n, const LightDesc& l, const Motion& m) {
  Bounds3f local;
  const char* where = l.areaShape == LightDesc::AreaShape::Mesh ? "file" : l.areaShape == LightDesc::AreaShape::Rect ? "size" : "radius";
  // Shapes by the poses' scales (the motion's steps blend rotations, which
  // shortens their axes slightly and unequally: not a change of shape).
  std::vector<Vec3f> scales = {l.placement.scale};
  for (const TransformDesc& k : l.motion.poses) scales.push_back(k.scale * l.placement.scale);
  Node at = n.has("motion") ? n.member("motion") : memberOr(n, "transform");
  for (size_t i = 0; i < scales.size(); ++i) {
    if (i == 0 && !l.motion.empty()) continue;  // the keys' products are what moves
    Vec3f sc{std::fabs(scales[i].x), std::fabs(scales[i].y), std::fabs(scales[i].z)};
    if (l.areaShape == LightDesc::AreaShape::Sphere)
      at.require(std::fabs(sc.x - sc.y) <= 1e-5f * sc.x && std::fabs(sc.x - sc.z) <= 1e-5f * sc.x,
                 "a sphere light must scale uniformly (an ellipsoid is not supported), got scale " + formatVec(scales[i]));
    if (l.areaShape == LightDesc::AreaShape::Disk)
      at.require(std::fabs(sc.x - sc.z) <= 1e-5f * sc.x,
                 "a disk light must scale alike along its local x and z (an ellipse is not supported), got " +
                     fmt(sc.x) + " and " + fmt(sc.z));
    if (l.areaShape == LightDesc::AreaShape::Mesh && i > 1) {
      // Relative triangle areas must stay those of the first key.
      Vec3f s0 = l.motion.poses[0].scale, si = l.motion.poses[i - 1].scale;
      Vec3f k{si.x / s0.x, si.y / s0.y, si.z / s0.z};
      at.require(std::fabs(k.x - k.y) <= 1e-5f * std::fabs(k.x) && std::fabs(k.x - k.z) <= 1e-5f * std::fabs(k.x),
                 "a moving mesh light may change its size only uniformly (its triangles' relative areas must stay fixed)");
    }
  }
  for (int i = 0; i < m.stepCount(); ++i) {
    const Affine3f& a = m.step(i);
    float lx = length(a.vector({1, 0, 0})), lz = length(a.vector({0, 0, 1}));
    float area = 0;
    switch (l.areaShape) {
      case LightDesc::AreaShape::Rect:
        area = length(cross(a.vector({0, 0, l.areaSize.y}), a.vector({l.areaSize.x, 0, 0})));
        break;
      case LightDesc::AreaShape::Sphere: area = 4.0f * kPi * l.radius * l.radius * lx * lx; break;
      case LightDesc::AreaShape::Disk: area = kPi * l.radius * l.radius * lx * lz; break;
      case LightDesc::AreaShape::Mesh:
        for (size_t t = 0; t + 2 < l.mesh.indices.size(); t += 3) {
          Vec3f p0 = l.mesh.vertices[l.mesh.indices[t]], p1 = l.mesh.vertices[l.mesh.indices[t + 1]],
                p2 = l.mesh.vertices[l.mesh.indices[t + 2]];
          area += 0.5f * length(cross(a.vector(p1 - p0), a.vector(p2 - p0)));
        }
        break;
    }
    memberOr(n, where).require(area > 1e-30f && std::isfinite(area),
                               "the light's area " + fmt(area) + " m^2 (after its transform) is too small for float arithmetic");
  }
  switch (l.areaShape) {
    case LightDesc::AreaShape::Rect:
      local.extend({-0.5f * l.areaSize.x, 0, -0.5f * l.areaSize.y});
      local.extend({0.5f * l.areaSize.x, 0, 0.5f * l.areaSize.y});
      break;
    case LightDesc::AreaShape::Sphere: local.extend(Vec3f(-l.radius)); local.extend(Vec3f(l.radius)); break;
    case LightDesc::AreaShape::Disk: local.extend({-l.radius, 0, -l.radius}); local.extend({l.radius, 0, l.radius}); break;
    case LightDesc::AreaShape::Mesh: for (Vec3f v : l.mesh.vertices) local.extend(v); break;
  }
  return local;
}

// Where the renderer will put the light over the shutter (scene/build.cpp,
// scene/light.cpp): in range, and an area light with a non-zero float area.
void checkLightPlacement(const Node& n, const LightDesc& l, Shutter s) {
  if (l.type == LightDesc::Type::Directional) return;  // a direction only
  if (l.type == LightDesc::Type::Environment) {        // a rotation (or mirror) only
    checkScales(n, l.placement, l.motion);
    // A stretch would make sampling densities in the light's frame wrong in
    // the world's (pbrt ignores that Jacobian); a uniform scale changes nothing.
    Vec3f a{std::fabs(l.placement.scale.x), std::fabs(l.placement.scale.y), std::fabs(l.placement.scale.z)};
    if (a.x != a.y || a.y != a.z)
      memberOr(memberOr(n, "transform"), "scale")
          .fail("an environment light's transform may rotate and mirror it, not stretch it: scale " +
                formatVec(l.placement.scale) + " is not uniform in magnitude");
    return;
  }
  checkScales(n, l.placement, l.motion);
  Motion m = motionOf(l.placement, l.motion, s);
  Bounds3f world;
  if (l.type != LightDesc::Type::Area) {
    for (int i = 0; i < m.stepCount(); ++i) world.extend(m.step(i).point(l.position));
    checkWorldBounds(n, world, "the light");
    return;
  }
  Bounds3f local = checkEmitterShape(n, l, m);
  checkWorldBounds(n, m.sweptBounds(local), "the light");
}

LightDesc readLight(const Node& n, Shutter s, const std::string& sceneDir) {
  n.requireObject();
  std::vector<std::string> names;
  for (const auto& k : lightKinds()) names.push_back(k.name);
  std::string typeName = n.required("type").choice(names, "light type");
  const LightKind& kind = *std::find_if(lightKinds().begin(), lightKinds().end(),
                                        [&](const LightKind& k) { return typeName == k.name; });
  if (kind.type == LightDesc::Type::Directional && n.has("power"))
    n.member("power").fail("a directional light takes \"irradiance\" (W/m^2), not \"power\": a sun has no finite power");
  std::vector<std::string> keys = {"type", "name", "transform", "motion", "medium"};
  keys.insert(keys.end(), kind.keys.begin(), kind.keys.end());
  n.expectObject(keys);

  LightDesc l;
  l.type = kind.type;
  l.name = readName(n, n.path());
  if (n.has("power")) l.power = n.member("power").color();
  if (n.has("irradiance")) l.power = n.member("irradiance").color();
  if (n.has("position")) {
    l.position = n.member("position").vec3();
    checkPoint(n.member("position"), l.position, "position");
  }
  if (kind.type == LightDesc::Type::Directional && n.has("direction"))
    l.direction = readDirection(n.member("direction"));
  if (kind.type == LightDesc::Type::Spot) readSpot(n, &l);
  if (kind.type == LightDesc::Type::Environment) readEnvironment(n, sceneDir, &l);
  if (n.has("size")) readAreaSize(n.member("size"), &l);
  if (kind.type == LightDesc::Type::Area) readEmitterShape(n, typeName, sceneDir, &l);
  if (n.has("transform")) l.placement = readTransform(n.member("transform"));
  if (n.has("motion")) l.motion = readMotion(n.member("motion"), s);
  checkLightPlacement(n, l, s);
  return l;
}

// ---------------------------------------------------------------- render

// A count whose range the matching flag shares (scene/limits.h).
int64_t readInRange(const Node& n, const char* what, limits::IntRange r) {
  int64_t v = n.integer();
  n.require(v >= r.lo, std::string(what) + " must be at least " + std::to_string(r.lo) + ", got " + std::to_string(v));
  n.require(v <= r.hi, std::string(what) + " " + std::to_string(v) + " is too large (at most " + std::to_string(r.hi) + ")");
  return v;
}

int readCount(const Node& n, const char* what, limits::IntRange r) { return int(readInRange(n, what, r)); }

float readFloatInRange(const Node& n, const char* what, limits::FloatRange r) {
  float v = n.number();
  n.require(v >= r.lo && v <= r.hi, std::string(what) + " must be in [" + limits::boundText(r.lo, true, true) + ", " +
                                         limits::boundText(r.hi, false, true) + "], got " + fmt(v));
  return v;
}

// kappa weighs time against space in a float metric: refuse what it cannot
// compute for this shutter (scene/limits.h).
float readKappa(const Node& n, float shutterLength) {
  float kappa = readPositive(n, "kappa");
  limits::KappaRange r = limits::kappaRange(shutterLength);
  n.require(kappa >= r.lo && kappa <= r.hi, "kappa " + fmt(kappa) + " cannot be used with a shutter of " +
                                                fmt(shutterLength) + " s: the 4D metric needs kappa in [" +
                                                limits::boundText(r.lo, true, true) + ", " +
                                                limits::boundText(r.hi, false, true) + "] (float range)");
  return kappa;
}

uint64_t readSeed(const Node& n) {
  const Json& j = n.json();
  if (j.is_number_unsigned()) return j.get<uint64_t>();
  double d = j.is_number() ? j.get<double>() : -1.0;
  // Integral floats (1e3) are accepted up to 2^53, where doubles are exact.
  if (!(d >= 0) || d != std::floor(d) || d > 9007199254740992.0)
    n.fail("seed must be a non-negative integer, got " + (j.is_number() ? j.dump() : detail::describeKind(j)));
  return uint64_t(d);
}

const std::vector<std::string> kSearches = {"twopass", "4d"};
const std::vector<std::string> kSamplers = {"random", "sobol"};
const std::vector<std::string> kFilters = {"box", "gaussian"};
const std::vector<std::string> kSpaceKernels = {"uniform", "cone", "epanechnikov"};
const std::vector<std::string> kTimeKernels = {"uniform", "epanechnikov"};

RenderSettings readRender(const Node& n, float shutterLength) {
  n.expectObject({"method", "spp", "max_spp", "contrast", "seed", "max_depth", "exposure", "photons", "global_photons",
                  "frames", "search", "k", "fraction", "kappa", "max_radius", "max_dt", "kernel_space", "kernel_time",
                  "gather", "sampler", "filter", "filter_radius", "progressive", "passes", "time_limit", "direct_only",
                  "photons_per_pixel", "volume_photons"});
  RenderSettings r;
  if (n.has("method")) r.method = n.member("method").choice(renderMethodNames(), "render method");
  if (n.has("spp")) r.spp = readCount(n.member("spp"), "spp", limits::kSpp);
  if (n.has("max_spp")) r.maxSpp = readCount(n.member("max_spp"), "max_spp", limits::kSpp);
  if (n.has("contrast")) r.contrast = readPositive(n.member("contrast"), "contrast");
  if (n.has("seed")) r.seed = readSeed(n.member("seed"));
  if (n.has("sampler")) r.sampler = n.member("sampler").choice(kSamplers, "sampler");
  if (n.has("filter")) r.filter = n.member("filter").choice(kFilters, "filter");
  if (n.has("filter_radius")) r.filterRadius = readFloatInRange(n.member("filter_radius"), "filter_radius", limits::kFilterRadius);
  if (n.has("max_depth")) r.maxDepth = readCount(n.member("max_depth"), "max_depth", limits::kMaxDepth);
  if (n.has("exposure")) r.exposure = readFloatInRange(n.member("exposure"), "exposure", limits::kExposure);
  if (n.has("photons")) r.photons = readInRange(n.member("photons"), "photons", limits::kPhotons);
  if (n.has("global_photons")) r.globalPhotons = readInRange(n.member("global_photons"), "global_photons", limits::kPhotons);
  if (n.has("volume_photons")) r.volumePhotons = readInRange(n.member("volume_photons"), "volume_photons", limits::kPhotons);
  if (n.has("frames")) r.frames = readCount(n.member("frames"), "frames", limits::kFrames);
  if (n.has("search")) r.search = n.member("search").choice(kSearches, "search");
  if (n.has("k")) r.k = readCount(n.member("k"), "k", limits::kK);
  if (n.has("fraction")) r.fraction = readFloatInRange(n.member("fraction"), "fraction", limits::kFraction);
  if (n.has("kappa")) r.kappa = readKappa(n.member("kappa"), shutterLength);
  if (n.has("max_radius")) {
    readPositive(n.member("max_radius"), "max_radius");  // the plain message for <= 0
    r.maxRadius = readFloatInRange(n.member("max_radius"), "max_radius", limits::kMaxRadius);
  }
  if (n.has("max_dt")) r.maxDt = readPositive(n.member("max_dt"), "max_dt");
  if (n.has("kernel_space")) r.kernelSpace = n.member("kernel_space").choice(kSpaceKernels, "space kernel");
  if (n.has("kernel_time")) r.kernelTime = n.member("kernel_time").choice(kTimeKernels, "time kernel");
  if (n.has("gather")) r.gather = readCount(n.member("gather"), "gather", limits::kGather);
  if (n.has("progressive")) {
    Node p = n.member("progressive");
    p.require(p.json().is_boolean(), "expected true or false");
    r.progressive = p.json().get<bool>();
  }
  if (n.has("passes")) r.passes = readCount(n.member("passes"), "passes", limits::kPasses);
  if (n.has("time_limit")) r.timeLimit = readFloatInRange(n.member("time_limit"), "time_limit", limits::kTimeLimit);
  if (n.has("direct_only")) {
    Node p = n.member("direct_only");
    p.require(p.json().is_boolean(), "expected true or false");
    r.directOnly = p.json().get<bool>();
    // Required rather than implied: a file that says direct_only and no
    // method would otherwise render with the default method, not direct light.
    p.require(!*r.directOnly || (r.method && parseRenderMethod(*r.method) == RenderMethod::PathTrace),
              "direct_only is a pathtrace setting: it needs render.method \"pathtrace\"" +
                  (r.method ? ", not \"" + *r.method + "\"" : std::string(" (none is given)")));
  }
  if (n.has("photons_per_pixel")) {
    Node p = n.member("photons_per_pixel");
    p.require(!r.photons, "give photons or photons_per_pixel, not both");
    r.photonsPerPixel = readInRange(p, "photons_per_pixel", {1, limits::kPhotons.hi});
  }
  return r;
}

// ---------------------------------------------------------------- scene

SceneDescription readScene(const Node& root, const std::string& sourcePath) {
  root.expectObject({"camera", "textures", "materials", "objects", "lights", "background", "render", "animation", "media",
                     "exterior_medium"});
  SceneDescription scene;
  scene.sourcePath = sourcePath;
  if (root.has("animation")) scene.animation = readAnimation(root.member("animation"));
  std::string sceneDir = std::filesystem::path(sourcePath).parent_path().string();
  detail::readMedia(root, sceneDir, &scene);
  scene.camera = readCamera(root.required("camera"), scene.animation);
  scene.camera.medium = detail::readMediumKey(root.required("camera"), scene);
  Shutter shutter{scene.camera.shutterOpen, scene.camera.shutterClose,
                  scene.animation ? "the animation" : "the shutter"};
  std::optional<TextureReader> textures;
  if (root.has("textures")) {
    textures.emplace(root.member("textures"), sceneDir, &scene.textures);
    textures->readAll();
  }
  if (root.has("materials")) scene.materials = readMaterials(root.member("materials"), textures ? &*textures : nullptr, sceneDir);
  Node objects = root.required("objects");
  size_t count = objects.arraySize("objects");
  for (size_t i = 0; i < count; ++i) {
    scene.objects.push_back(readObject(objects.element(i), &scene.materials, shutter, sceneDir));
    detail::readObjectMedia(objects.element(i), scene, &scene.objects.back());
  }
  if (root.has("lights")) {
    Node lights = root.member("lights");
    size_t n = lights.arraySize("lights");
    for (size_t i = 0; i < n; ++i) {
      scene.lights.push_back(readLight(lights.element(i), shutter, sceneDir));
      scene.lights.back().medium = detail::readMediumKey(lights.element(i), scene);
    }
  }
  if (root.has("background")) scene.background = root.member("background").color();
  if (root.has("render"))
    scene.render = readRender(root.member("render"), scene.animation ? float(scene.animation->shutterLength())
                                                                       : shutter.close - shutter.open);
  return scene;
}

// ---------------------------------------------------------------- text level

[[noreturn]] void failAt(const std::string& file, const std::string& text, size_t offset, const std::string& problem) {
  TextPosition p = positionOf(text, offset);
  throw Error(file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column) + ": " + problem);
}

// Checks that do not need parsed JSON: empty text, bad UTF-8, nesting depth.
void checkText(const std::string& text, const std::string& file) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error(file + ":1: the file is empty (expected a JSON object)");
  size_t bad = firstInvalidUtf8(text);
  if (bad != std::string::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", unsigned(static_cast<unsigned char>(text[bad])));
    failAt(file, text, bad, std::string("not valid UTF-8 text (byte ") + hex + "); is this a JSON scene file?");
  }
  // Before nlohmann parses: its parser recurses once per level.
  size_t deep = firstTooDeep(text, limits::kMaxJsonDepth);
  if (deep != std::string::npos)
    failAt(file, text, deep,
           "arrays and objects are nested too deeply (at most " + std::to_string(limits::kMaxJsonDepth) + " levels)");
}

// nlohmann's message minus its own "[json.exception...] parse error at ...: " prefix.
std::string syntaxDetail(const std::string& what) {
  size_t at = what.find("syntax error");
  if (at != std::string::npos) return what.substr(at);
  size_t colon = what.find("]");
  return "syntax error: " + (colon == std::string::npos ? what : what.substr(colon + 2));
}

// nlohmann rejects number literals that overflow a double (1e999) by
// spelling only; find the value to report its path and line.
[[noreturn]] void failOverflow(const std::string& text, const std::string& file, const std::string& what) {
  size_t open = what.find('\''), close = what.rfind('\'');
  std::string token = (open != std::string::npos && close > open) ? what.substr(open + 1, close - open - 1) : "";
  JsonLocator locator(text);
  Source source{file, &locator};
  source.fail(locator.findNumber(token), "number " + token + " is not finite (it overflows)");
}

Json parseJson(const std::string& text, const std::string& file) {
  checkText(text, file);
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    failAt(file, text, e.byte > 0 ? e.byte - 1 : 0, syntaxDetail(e.what()));
  } catch (const Json::out_of_range& e) {
    failOverflow(text, file, e.what());
  } catch (const Json::exception& e) {
    throw Error(file + ": invalid JSON: " + e.what());
  }
}

}  // namespace

namespace detail {
TransformDesc readPlacement(const Node& n) { return readTransform(n); }
}  // namespace detail

SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath) {
  Json doc = parseJson(jsonText, sourcePath);
  JsonLocator locator(jsonText);
  if (!locator.duplicates().empty()) {
    const auto& d = locator.duplicates().front();
    throw Error(sourcePath + ":" + std::to_string(d.line) + ": " + d.path + ": duplicate key (each key may appear only once)");
  }
  Source source{sourcePath, &locator};
  return readScene(Node(doc, "", source), sourcePath);
}

SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath, const MeshSource& meshes) {
  struct Restore {
    const MeshSource* old;
    ~Restore() { tMeshSource = old; }
  } restore{tMeshSource};
  tMeshSource = &meshes;
  return parseScene(jsonText, sourcePath);
}

SceneDescription parseScene(const std::string& jsonText, const std::string& sourcePath, const MeshSource& meshes,
                            const ImageSource& images) {
  struct Restore {
    const ImageSource* old;
    ~Restore() { tImageSource = old; }
  } restore{tImageSource};
  tImageSource = &images;
  return parseScene(jsonText, sourcePath, meshes);
}

SceneDescription loadScene(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": cannot read scene file: it is a directory");
  // A device or pipe (/dev/zero) could be read forever: only regular files.
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw Error(path + ": cannot read scene file: it is not a regular file");
  const std::string limit = std::to_string(limits::kMaxSceneFileBytes >> 20) + " MiB";
  uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits::kMaxSceneFileBytes)
    throw Error(path + ": scene file is too large (" + std::to_string(size) + " bytes; at most " + limit +
                "; put large meshes in OBJ files)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read scene file (" + std::strerror(errno) + ")");
  // Read at most one byte over the limit, in case the file grew since the check.
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk), in.gcount() > 0) {
    text.append(chunk, size_t(in.gcount()));
    if (text.size() > limits::kMaxSceneFileBytes)
      throw Error(path + ": scene file is too large (more than " + limit + ")");
  }
  if (in.bad()) throw Error(path + ": error while reading scene file");
  return parseScene(text, path);
}

}  // namespace tdpm::scene
