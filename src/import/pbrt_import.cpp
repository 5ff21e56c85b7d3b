// import/pbrt_import.cpp — the pbrt statement parser and its graphics state
// (CTM pair for motion, attribute stack, named materials / textures /
// coordinate systems, object instancing, Include/Import), and the mapping
// of each statement onto scene::SceneDescription. Tokens come from
// pbrt_tokenizer, parameter lists from pbrt_params, matrices from pbrt_math.
// docs/pbrt-import.md is the user-facing version of this file.
#include "import/pbrt_import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "import/pbrt_math.h"
#include "import/pbrt_params.h"
#include "import/pbrt_tokenizer.h"
#include "import/ply_reader.h"
#include "import/scene_json_writer.h"

namespace tdpm::pbrt {

namespace {

constexpr int kMaxIncludeDepth = 32;
constexpr double kPiD = 3.14159265358979323846;
constexpr int64_t kMaxPhotons = int64_t(1) << 31;

struct Loc {
  std::string file;
  int line = 0;
  std::string str() const { return file + ":" + std::to_string(line); }
};

[[noreturn]] void failAt(const Loc& at, const std::string& what) { throw Error(at.str() + ": " + what); }

std::string fmtNum(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string readWholeFile(const std::string& path, const std::string& where) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(where + path + ": cannot read scene file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(where + path + ": cannot read scene file (" + std::strerror(errno) + ")");
  // Not a device or a pipe (Include "/dev/zero" would never end).
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(where + path + ": cannot read scene file: not a regular file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(where + path + ": error while reading scene file");
  return text.str();
}

// A relative path is looked up beside the file that names it; if it is not
// there but is beside the main scene file (pbrt's search directory), that
// one is used, so scenes written for pbrt's rule load too.
std::string resolvePath(const std::string& name, const std::string& namingFile, const std::string& mainDir) {
  std::filesystem::path p(name);
  if (p.is_absolute()) return p.lexically_normal().string();
  std::filesystem::path local = (std::filesystem::path(namingFile).parent_path() / p).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::exists(local, ec) && !mainDir.empty()) {
    std::filesystem::path main = (std::filesystem::path(mainDir) / p).lexically_normal();
    if (std::filesystem::exists(main, ec)) return main.string();
  }
  return local.string();
}

// ------------------------------------------------------------ state types

struct MaterialSlot {
  bool interface = false;  // "" / "interface" / "none": no surface at all
  scene::MaterialDesc desc;
  int index = -1;  // in scene.materials once a shape uses it
};

struct AreaLight {
  ParamSet params;
  Loc at;
};

struct ShapeRecord {
  std::string type;
  ParamSet params;
  Mat ctm[2];
  int material = 0;
  std::optional<AreaLight> area;
  Loc at;
};

struct GraphicsState {
  Mat ctm[2];
  unsigned active = 3;  // ActiveTransform: bit 0 StartTime, bit 1 EndTime
  int material = 0;
  std::optional<AreaLight> area;
};

struct StackEntry {
  GraphicsState state;
  bool attribute = true;  // AttributeBegin (true) or TransformBegin (false)
  Loc at;
};

struct TextureValue {
  bool isFloat = false;
  Rgb value{1, 1, 1};
};

struct Statement {  // an options-block statement kept until WorldBegin
  std::string type;
  ParamSet params;
  Loc at;
  bool given = false;
};

// ------------------------------------------------------------ token cursor

class Cursor {
 public:
  Cursor(const std::vector<Token>& t, std::string file) : t_(t), file_(std::move(file)) {}
  bool done() const { return i_ >= t_.size(); }
  const Token& peek() const { return t_[i_]; }
  const Token& next() { return t_[i_++]; }
  int line() const { return done() ? (t_.empty() ? 1 : t_.back().line) : t_[i_].line; }
  const std::string& file() const { return file_; }
  Loc loc() const { return {file_, line()}; }

  double number(const std::string& stmt) {
    if (done() || peek().kind != Token::Kind::Number)
      failAt(loc(), stmt + ": expected a number" + (done() ? " before the end of the file" : ", got '" + peek().text + "'"));
    return next().number;
  }
  std::string string(const std::string& stmt) {
    if (done() || peek().kind != Token::Kind::String)
      failAt(loc(), stmt + ": expected a quoted string" + (done() ? " before the end of the file" : ", got '" + peek().text + "'"));
    return next().text;
  }
  // n numbers, optionally inside [ ] (Transform, ConcatTransform).
  std::vector<double> numbers(const std::string& stmt, size_t n) {
    bool bracket = !done() && peek().kind == Token::Kind::Open;
    if (bracket) next();
    std::vector<double> v;
    for (size_t k = 0; k < n; ++k) v.push_back(number(stmt));
    if (bracket) {
      if (done() || peek().kind != Token::Kind::Close) failAt(loc(), stmt + ": expected ']' after " + std::to_string(n) + " numbers");
      next();
    }
    return v;
  }

  ParamSet params(const std::string& stmt) {
    std::vector<Param> out;
    while (!done() && peek().kind == Token::Kind::String) {
      const Token& decl = next();
      Param p;
      p.line = decl.line;
      std::istringstream words(decl.text);
      std::string extra;
      if (!(words >> p.type >> p.name) || (words >> extra))
        failAt({file_, decl.line}, stmt + ": expected a parameter declaration \"type name\", got \"" + decl.text + "\"");
      if (p.type == "point") p.type = "point3";
      if (p.type == "vector") p.type = "vector3";
      if (p.type == "normal") p.type = "normal3";
      if (p.type == "color") p.type = "rgb";
      for (const Param& q : out)
        if (q.name == p.name) failAt({file_, decl.line}, stmt + ": parameter \"" + p.name + "\" is given twice");
      if (done()) failAt(loc(), stmt + ": parameter \"" + decl.text + "\" has no value");
      auto take = [&](const Token& v) {
        if (v.kind == Token::Kind::Number) p.numbers.push_back(v.number);
        else if (v.kind == Token::Kind::String) p.strings.push_back(v.text);
        else if (v.kind == Token::Kind::Word && (v.text == "true" || v.text == "false")) p.strings.push_back(v.text);
        else failAt({file_, v.line}, stmt + ": parameter \"" + decl.text + "\": unexpected '" + v.text + "' in its value");
      };
      if (peek().kind == Token::Kind::Open) {
        next();
        while (!done() && peek().kind != Token::Kind::Close) take(next());
        if (done()) failAt({file_, decl.line}, stmt + ": parameter \"" + decl.text + "\": missing ']'");
        next();
      } else {
        take(next());
      }
      if (!p.numbers.empty() && !p.strings.empty())
        failAt({file_, decl.line}, stmt + ": parameter \"" + decl.text + "\" mixes numbers and strings");
      out.push_back(std::move(p));
    }
    return ParamSet(std::move(out), file_, stmt);
  }

 private:
  const std::vector<Token>& t_;
  std::string file_;
  size_t i_ = 0;
};

// ------------------------------------------------------------ importer

class Importer {
 public:
  ImportResult result;

  void parseFile(const std::string& path, int depth, const std::string& where) {
    std::string text = readWholeFile(path, where);
    parseText(text, path, depth);
  }
  void parseText(const std::string& text, const std::string& file, int depth);
  void finish(const std::string& file);
  std::string mainDir;  // pbrt's search directory: the main scene file's

 private:
  // statements
  void statement(Cursor& c, const Token& word, int depth);
  void applyTransform(const Mat& m, bool replace);
  void worldBegin(const Loc& at);
  void shape(const std::string& type, ParamSet params, const Loc& at);
  void lightSource(const std::string& type, const ParamSet& ps, const Loc& at);
  void texture(const std::string& name, const std::string& kind, const std::string& type, const ParamSet& ps, const Loc& at);
  MaterialSlot makeMaterial(const std::string& type, const ParamSet& ps, const Loc& at, const std::string& name);

  // mapping
  void emitShape(const ShapeRecord& rec, const Mat ctm[2], const Loc& instanceAt);
  void emitAreaLight(const ShapeRecord& rec, const std::vector<Vec3f>& verts, const std::vector<uint32_t>& idx,
                     const Mat ctm[2]);
  struct MotionPlan {
    bool moving = false;
    Mat still;  // world' (mirrored) placement when not moving
    scene::MotionDesc keys;
  };
  MotionPlan planMotion(const Mat ctm[2], const Loc& at, const std::string& what) const;
  uint32_t materialIndex(int slot);
  std::string uniqueMaterialName(const std::string& base);
  Rgb color(const ParamSet& ps, const std::string& name, Rgb fallback) const;
  double floatParam(const ParamSet& ps, const std::string& name, double fallback) const;
  Rgb lightScale(const ParamSet& ps) const;
  void note(const Loc& at, const std::string& what);
  void requireWorld(const Loc& at, const std::string& stmt) const;
  void requireOptions(const Loc& at, const std::string& stmt) const;

  GraphicsState gs_;
  std::vector<StackEntry> stack_;
  std::vector<MaterialSlot> materials_ = {defaultMaterial()};
  std::map<std::string, int> namedMaterials_;
  std::map<std::string, TextureValue> textures_;
  std::map<std::string, Mat> coordSystems_;
  std::map<std::string, std::vector<ShapeRecord>> instances_;
  std::vector<ShapeRecord>* currentInstance_ = nullptr;
  std::string currentInstanceName_;
  std::set<std::string> materialNames_;
  std::set<std::string> notedKinds_;

  bool inWorld_ = false, sawWorld_ = false, worldEnded_ = false;
  float transformStart_ = 0, transformEnd_ = 1;
  Statement camera_, film_, sampler_, integrator_;
  Mat cameraCtm_[2];
  bool mirror_ = true;
  float shutterOpen_ = 0, shutterClose_ = 1;
  double imagingRatio_ = 1;  // pbrt-v4 film: exposure time * ISO / 100
  Loc worldAt_;

  static MaterialSlot defaultMaterial() {
    MaterialSlot s;  // pbrt's default: diffuse, reflectance 0.5
    s.desc.type = scene::MaterialDesc::Type::Diffuse;
    s.desc.albedo.color = Rgb(0.5f);
    s.desc.name = "default";
    return s;
  }
};

void Importer::note(const Loc& at, const std::string& what) {
  // One note per kind of message: a mesh-heavy scene should not print
  // thousands of identical lines.
  if (!notedKinds_.insert(what).second) return;
  result.notes.push_back(at.str() + ": " + what);
}

void Importer::requireWorld(const Loc& at, const std::string& stmt) const {
  if (!inWorld_) failAt(at, stmt + " is only allowed after WorldBegin");
}

void Importer::requireOptions(const Loc& at, const std::string& stmt) const {
  if (inWorld_ || worldEnded_) failAt(at, stmt + " is only allowed before WorldBegin");
}

void Importer::applyTransform(const Mat& m, bool replace) {
  for (int i = 0; i < 2; ++i)
    if (gs_.active & (1u << i)) gs_.ctm[i] = replace ? m : gs_.ctm[i] * m;
}

void Importer::parseText(const std::string& text, const std::string& file, int depth) {
  std::vector<Token> tokens = tokenize(text, file);
  Cursor c(tokens, file);
  while (!c.done()) {
    const Token& word = c.next();
    if (word.kind != Token::Kind::Word)
      failAt({file, word.line}, "expected a statement (such as Shape or WorldBegin), got '" + word.text + "'");
    statement(c, word, depth);
  }
}

Mat matrixFrom16(const std::vector<double>& v) {
  // pbrt lists the matrix column by column (the translation is v[12..14]).
  Mat m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m.m[i][j] = v[size_t(j * 4 + i)];
  return m;
}

void Importer::statement(Cursor& c, const Token& word, int depth) {
  const std::string& s = word.text;
  Loc at{c.file(), word.line};
  if (s == "Translate") {
    auto v = c.numbers(s, 3);
    applyTransform(Mat::translate(v[0], v[1], v[2]), false);
  } else if (s == "Scale") {
    auto v = c.numbers(s, 3);
    applyTransform(Mat::scale(v[0], v[1], v[2]), false);
  } else if (s == "Rotate") {
    auto v = c.numbers(s, 4);
    if (v[1] == 0 && v[2] == 0 && v[3] == 0) failAt(at, "Rotate: the axis must not be a zero vector");
    applyTransform(Mat::rotate(v[0], v[1], v[2], v[3]), false);
  } else if (s == "LookAt") {
    auto v = c.numbers(s, 9);
    auto m = lookAt({float(v[0]), float(v[1]), float(v[2])}, {float(v[3]), float(v[4]), float(v[5])},
                    {float(v[6]), float(v[7]), float(v[8])});
    if (!m) failAt(at, "LookAt: eye and look-at point coincide, or up is zero or parallel to the view direction");
    applyTransform(*m, false);
  } else if (s == "Transform" || s == "ConcatTransform") {
    Mat m = matrixFrom16(c.numbers(s, 16));
    if (!m.isAffine()) failAt(at, s + ": a projective matrix (last row not 0 0 0 1) cannot be mapped");
    applyTransform(m, s == "Transform");
  } else if (s == "Identity") {
    applyTransform(Mat(), true);
  } else if (s == "CoordinateSystem") {
    coordSystems_[c.string(s)] = gs_.ctm[0];
  } else if (s == "CoordSysTransform") {
    std::string name = c.string(s);
    auto it = coordSystems_.find(name);
    if (it == coordSystems_.end()) failAt(at, "CoordSysTransform: unknown coordinate system \"" + name + "\"");
    applyTransform(it->second, true);
  } else if (s == "ActiveTransform") {
    if (c.done() || c.peek().kind != Token::Kind::Word) failAt(at, "ActiveTransform: expected StartTime, EndTime or All");
    std::string w = c.next().text;
    if (w == "StartTime") gs_.active = 1;
    else if (w == "EndTime") gs_.active = 2;
    else if (w == "All") gs_.active = 3;
    else failAt(at, "ActiveTransform: expected StartTime, EndTime or All, got '" + w + "'");
  } else if (s == "TransformTimes") {
    requireOptions(at, s);
    auto v = c.numbers(s, 2);
    if (!(v[1] > v[0])) failAt(at, "TransformTimes: the end time " + fmtNum(v[1]) + " must be after the start time " + fmtNum(v[0]));
    transformStart_ = float(v[0]);
    transformEnd_ = float(v[1]);
  } else if (s == "Camera") {
    requireOptions(at, s);
    std::string type = c.string(s);
    camera_ = {type, c.params("Camera \"" + type + "\""), at, true};
    cameraCtm_[0] = gs_.ctm[0];
    cameraCtm_[1] = gs_.ctm[1];
    for (int i = 0; i < 2; ++i) {
      auto inv = gs_.ctm[i].inverse();
      if (!inv) failAt(at, "Camera: the current transform is singular");
    }
    coordSystems_["camera"] = *gs_.ctm[0].inverse();
  } else if (s == "Film" || s == "Sampler" || s == "Integrator") {
    requireOptions(at, s);
    std::string type = c.string(s);
    Statement st{type, c.params(s + " \"" + type + "\""), at, true};
    (s == "Film" ? film_ : s == "Sampler" ? sampler_ : integrator_) = std::move(st);
  } else if (s == "PixelFilter" || s == "Accelerator" || s == "ColorSpace") {
    std::string type = c.string(s);
    c.params(s + " \"" + type + "\"");
    note(at, s + " \"" + type + "\" ignored (it only changes quality; tdpm uses its own)");
  } else if (s == "WorldBegin") {
    requireOptions(at, s);
    worldBegin(at);
  } else if (s == "WorldEnd") {
    requireWorld(at, s);
    if (!stack_.empty()) failAt(stack_.back().at, "AttributeBegin/TransformBegin without a matching End before WorldEnd");
    inWorld_ = false;
    worldEnded_ = true;
  } else if (s == "AttributeBegin" || s == "TransformBegin") {
    stack_.push_back({gs_, s == "AttributeBegin", at});
  } else if (s == "AttributeEnd" || s == "TransformEnd") {
    bool attribute = s == "AttributeEnd";
    if (stack_.empty() || stack_.back().attribute != attribute)
      failAt(at, s + " without a matching " + (attribute ? "AttributeBegin" : "TransformBegin"));
    if (attribute) gs_ = stack_.back().state;
    else {
      gs_.ctm[0] = stack_.back().state.ctm[0];
      gs_.ctm[1] = stack_.back().state.ctm[1];
      gs_.active = stack_.back().state.active;
    }
    stack_.pop_back();
  } else if (s == "Include" || s == "Import") {
    std::string name = c.string(s);
    if (depth + 1 > kMaxIncludeDepth) failAt(at, s + " \"" + name + "\": nested more than 32 deep (an include cycle?)");
    parseFile(resolvePath(name, c.file(), mainDir), depth + 1, at.str() + ": " + s + ": ");
  } else if (s == "Shape") {
    requireWorld(at, s);
    std::string type = c.string(s);
    shape(type, c.params("Shape \"" + type + "\""), at);
  } else if (s == "Material") {
    requireWorld(at, s);
    std::string type = c.string(s);
    ParamSet ps = c.params("Material \"" + type + "\"");
    materials_.push_back(makeMaterial(type, ps, at, ""));
    gs_.material = int(materials_.size()) - 1;
  } else if (s == "MakeNamedMaterial") {
    requireWorld(at, s);
    std::string name = c.string(s);
    ParamSet ps = c.params("MakeNamedMaterial \"" + name + "\"");
    if (!ps.has("type")) failAt(at, "MakeNamedMaterial \"" + name + "\": missing parameter \"string type\"");
    std::string type = ps.getString("type", "");
    materials_.push_back(makeMaterial(type, ps, at, name));
    namedMaterials_[name] = int(materials_.size()) - 1;
  } else if (s == "NamedMaterial") {
    requireWorld(at, s);
    std::string name = c.string(s);
    auto it = namedMaterials_.find(name);
    if (it == namedMaterials_.end()) failAt(at, "NamedMaterial: no material named \"" + name + "\" has been made");
    gs_.material = it->second;
  } else if (s == "Texture") {
    requireWorld(at, s);
    std::string name = c.string(s), kind = c.string(s), type = c.string(s);
    texture(name, kind, type, c.params("Texture \"" + name + "\""), at);
  } else if (s == "LightSource") {
    requireWorld(at, s);
    std::string type = c.string(s);
    lightSource(type, c.params("LightSource \"" + type + "\""), at);
  } else if (s == "AreaLightSource") {
    requireWorld(at, s);
    std::string type = c.string(s);
    ParamSet ps = c.params("AreaLightSource \"" + type + "\"");
    if (type != "diffuse") failAt(at, "AreaLightSource \"" + type + "\" is not supported (only \"diffuse\")");
    gs_.area = AreaLight{std::move(ps), at};
  } else if (s == "ObjectBegin") {
    requireWorld(at, s);
    std::string name = c.string(s);
    if (currentInstance_) failAt(at, "ObjectBegin \"" + name + "\" inside the definition of \"" + currentInstanceName_ + "\"");
    stack_.push_back({gs_, true, at});
    currentInstance_ = &instances_[name];
    currentInstance_->clear();
    currentInstanceName_ = name;
  } else if (s == "ObjectEnd") {
    requireWorld(at, s);
    if (!currentInstance_) failAt(at, "ObjectEnd without ObjectBegin");
    if (stack_.empty() || !stack_.back().attribute) failAt(at, "ObjectEnd does not match the attributes of its ObjectBegin");
    gs_ = stack_.back().state;
    stack_.pop_back();
    currentInstance_ = nullptr;
  } else if (s == "ObjectInstance") {
    requireWorld(at, s);
    std::string name = c.string(s);
    if (currentInstance_) failAt(at, "ObjectInstance inside an object definition is not supported");
    auto it = instances_.find(name);
    if (it == instances_.end()) failAt(at, "ObjectInstance: no object named \"" + name + "\" has been defined");
    for (const ShapeRecord& rec : it->second) {
      Mat ctm[2] = {gs_.ctm[0] * rec.ctm[0], gs_.ctm[1] * rec.ctm[1]};
      emitShape(rec, ctm, at);
    }
  } else if (s == "ReverseOrientation") {
    failAt(at, "ReverseOrientation is not supported (tdpm cannot flip a sphere's or an emitter's orientation)");
  } else {
    failAt(at, "statement " + s + " is not supported by tdpm's pbrt import (see docs/pbrt-import.md)");
  }
}

// ------------------------------------------------------------ options block

float verticalFov(double fov, int w, int h) {
  // pbrt's fov spans the shorter image axis; tdpm's is vertical.
  if (w >= h) return float(fov);
  double t = std::tan(0.5 * fov * kPiD / 180.0) * double(h) / double(w);
  return float(2.0 * std::atan(t) * 180.0 / kPiD);
}

void Importer::worldBegin(const Loc& at) {
  inWorld_ = sawWorld_ = true;
  worldAt_ = at;
  scene::SceneDescription& sc = result.scene;
  scene::RenderSettings& r = sc.render;

  // Film
  int width = 640, height = 480;
  bool v4Film = false;
  if (film_.given) {
    const ParamSet& ps = film_.params;
    if (film_.type == "rgb" || film_.type == "gbuffer" || film_.type == "spectral") v4Film = true;
    else if (film_.type != "image") failAt(film_.at, "Film \"" + film_.type + "\" is not supported (image, rgb, gbuffer, spectral)");
    width = ps.getInt("xresolution", 640);
    height = ps.getInt("yresolution", 480);
    if (width < 1 || height < 1 || width > 65536 || height > 65536)
      failAt(film_.at, "Film: resolution " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1..65536");
    if (ps.has("filename")) result.filmFilename = ps.getString("filename", "");
    std::vector<double> crop = ps.getFloats("cropwindow");
    if (!crop.empty() && !(crop.size() == 4 && crop[0] == 0 && crop[1] == 1 && crop[2] == 0 && crop[3] == 1))
      ps.fail(*ps.find("cropwindow"), "a crop window is not supported");
    for (const char* q : {"diagonal", "maxcomponentvalue", "savefp16", "writefp16"})
      if (ps.has(q)) {
        ps.markUsed(q);
        note(film_.at, std::string("Film: \"") + q + "\" ignored (quality only)");
      }
    if (v4Film) {
      double iso = ps.getFloat("iso", 100);
      if (ps.getFloat("whitebalance", 0) != 0) ps.fail(*ps.find("whitebalance"), "white balancing is not supported");
      if (ps.getString("sensor", "cie1931") != "cie1931") ps.fail(*ps.find("sensor"), "only the cie1931 sensor is supported");
      imagingRatio_ = iso / 100.0;  // times the exposure time, below
    }
    ps.checkAllUsed();
  }
  sc.camera.width = width;
  sc.camera.height = height;

  // Camera (pbrt's default: perspective, fov 90, at the origin looking down +z)
  double fov = 90;
  if (camera_.given) {
    const ParamSet& ps = camera_.params;
    if (camera_.type != "perspective") failAt(camera_.at, "Camera \"" + camera_.type + "\" is not supported (only perspective)");
    fov = ps.has("halffov") ? 2 * ps.getFloat("halffov", 45) : ps.getFloat("fov", 90);
    if (!(fov > 0 && fov < 180)) failAt(camera_.at, "Camera: fov must be in (0, 180) degrees, got " + fmtNum(fov));
    shutterOpen_ = float(ps.getFloat("shutteropen", 0));
    shutterClose_ = float(ps.getFloat("shutterclose", 1));
    if (shutterClose_ < shutterOpen_)
      failAt(camera_.at, "Camera: shutterclose (" + fmtNum(shutterClose_) + ") is before shutteropen (" + fmtNum(shutterOpen_) + ")");
    double lens = ps.getFloat("lensradius", 0);
    if (lens > 0) ps.fail(*ps.find("lensradius"), "depth of field (lensradius > 0) is not supported");
    ps.markUsed("focaldistance");
    ps.checkAllUsed();
  }
  if (v4Film) {
    imagingRatio_ *= double(shutterClose_) - double(shutterOpen_);
    if (!(imagingRatio_ > 0))
      failAt(film_.at, "Film: pbrt-v4 scales the image by exposure time x ISO / 100, which is 0 here (zero-length shutter or iso 0)");
  }
  sc.camera.shutterOpen = shutterOpen_;
  sc.camera.shutterClose = shutterClose_;
  sc.camera.fovDegrees = verticalFov(fov, width, height);

  // The camera frame: camera-to-world C = inverse(CTM at Camera).
  Loc camAt = camera_.given ? camera_.at : at;
  Mat C[2] = {*cameraCtm_[0].inverse(), *cameraCtm_[1].inverse()};
  struct Frame3 { Vec3f pos, fwd, up; };
  Frame3 f[2];
  for (int i = 0; i < 2; ++i) {
    std::optional<Pose> p = decompose(C[i]);
    bool similar = p && std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.y)) <= 1e-5f * std::fabs(p->scale.x) &&
                   std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.z)) <= 1e-5f * std::fabs(p->scale.x);
    if (!similar) failAt(camAt, "Camera: the camera transform has shear or non-uniform scale, which distorts the image; not supported");
  }
  // pbrt's camera looks down +z with +x to the image's right and +y up:
  // a left-handed frame when C is a proper rotation. tdpm's camera is
  // right-handed (right = forward x up), so then the whole world is
  // mirrored (x -> -x): the image is the same, and mirroring is exact for
  // light transport. A camera transform that already mirrors needs nothing.
  mirror_ = C[0].det3() > 0;
  Mat W = mirror_ ? mirrorX() : Mat();
  for (int i = 0; i < 2; ++i) {
    Mat c = W * C[i];
    f[i].pos = c.point({0, 0, 0});
    f[i].fwd = normalize(c.vector({0, 0, 1}));
    f[i].up = normalize(c.vector({0, 1, 0}));
  }
  sc.camera.position = f[0].pos;
  sc.camera.target = f[0].pos + f[0].fwd;
  sc.camera.up = f[0].up;
  if (!(C[0] == C[1])) {
    if (C[0].det3() * C[1].det3() < 0 || length(f[0].fwd - f[1].fwd) > 1e-6f || length(f[0].up - f[1].up) > 1e-6f)
      failAt(camAt, "Camera: a camera that rotates during the shutter cannot be mapped exactly (tdpm interpolates "
                    "camera look-at points linearly, pbrt slerps the rotation); only a translating camera is supported");
    float t0 = transformStart_, t1 = transformEnd_;
    float a = std::max(t0, shutterOpen_), b = std::min(t1, shutterClose_);
    auto at01 = [&](float t) {
      float u = std::clamp((t - t0) / (t1 - t0), 0.0f, 1.0f);
      return lerp(f[0].pos, f[1].pos, u);
    };
    if (a < b) {
      for (float t : {a, b}) {
        Vec3f p = at01(t);
        sc.camera.motion.push_back({t, p, p + f[0].fwd, f[0].up});
      }
    } else {
      Vec3f p = at01(t1 <= shutterOpen_ ? t1 : t0 >= shutterClose_ ? t0 : a);
      sc.camera.position = p;
      sc.camera.target = p + f[0].fwd;
    }
  }

  // Sampler -> spp
  if (sampler_.given) {
    const ParamSet& ps = sampler_.params;
    static const std::set<std::string> kSamplers = {"halton", "sobol", "zsobol", "paddedsobol", "pmj02bn", "independent",
                                                    "random", "02sequence", "lowdiscrepancy", "maxmindist", "stratified"};
    if (!kSamplers.count(sampler_.type)) failAt(sampler_.at, "Sampler \"" + sampler_.type + "\" is not supported");
    int spp;
    if (sampler_.type == "stratified") {
      if (!ps.has("xsamples") || !ps.has("ysamples"))
        failAt(sampler_.at, "Sampler \"stratified\": give xsamples and ysamples (pbrt-v3 and v4 defaults differ)");
      spp = ps.getInt("xsamples", 2) * ps.getInt("ysamples", 2);
      ps.markUsed("jitter");
    } else {
      spp = ps.getInt("pixelsamples", 16);
    }
    if (spp < 1) failAt(sampler_.at, "Sampler: samples per pixel must be at least 1, got " + std::to_string(spp));
    r.spp = spp;
    for (const char* q : {"seed", "randomization", "dimensions", "jitter"}) ps.markUsed(q);
    note(sampler_.at, "Sampler \"" + sampler_.type + "\": its pattern is replaced by tdpm's stratified sampler (same spp)");
    ps.checkAllUsed();
  } else {
    r.spp = 16;  // pbrt's default pixelsamples
  }

  // Integrator -> method
  std::string integ = integrator_.given ? integrator_.type : "path";
  const ParamSet& ip = integrator_.params;
  Loc iat = integrator_.given ? integrator_.at : at;
  int maxDepth = integrator_.given ? ip.getInt("maxdepth", 5) : 5;
  if (maxDepth < 1) failAt(iat, "Integrator: maxdepth " + std::to_string(maxDepth) + " (emission only) is not supported; tdpm needs at least 1");
  r.maxDepth = maxDepth;
  if (integ == "path" || integ == "volpath") {
    r.method = "pathtrace";
    for (const char* q : {"regularize", "lightsampler", "rrthreshold"})
      if (ip.has(q)) {
        ip.markUsed(q);
        note(iat, std::string("Integrator: \"") + q + "\" ignored (quality only)");
      }
  } else if (integ == "sppm") {
    // The progressive method does not exist yet: the photon count of all
    // iterations goes into one pass of the time-dependent photon method.
    int iterations = ip.getInt("numiterations", 64);
    int perIteration = ip.getInt("photonsperiteration", -1);
    double radius = ip.getFloat("radius", 1.0);
    if (iterations < 1) failAt(iat, "Integrator \"sppm\": numiterations must be at least 1");
    if (!(radius > 0)) failAt(iat, "Integrator \"sppm\": radius must be positive");
    int64_t per = perIteration > 0 ? perIteration : int64_t(width) * height;
    r.method = "time";
    r.photons = std::min(kMaxPhotons, per * iterations);
    r.maxRadius = float(radius);
    ip.markUsed("seed");
    note(iat, "Integrator \"sppm\" mapped to tdpm's time-dependent photon method with photons = photonsperiteration x "
              "numiterations = " + std::to_string(*r.photons) + " and max radius = radius (see docs/pbrt-import.md)");
  } else {
    failAt(iat, "Integrator \"" + integ + "\" is not supported (path, volpath, sppm)");
  }
  if (integrator_.given) ip.checkAllUsed();

  gs_.ctm[0] = gs_.ctm[1] = Mat();
  coordSystems_["world"] = Mat();
}

// ------------------------------------------------------------ materials / textures

double roughnessToAlphaV3(double r) {
  double x = std::log(std::max(r, 1e-3));
  return 1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x + 0.000640711 * x * x * x * x;
}

Rgb Importer::color(const ParamSet& ps, const std::string& name, Rgb fallback) const {
  const Param* p = ps.find(name);
  if (!p) return fallback;
  p->used = true;
  if (p->type == "rgb") {
    if (p->numbers.size() != 3) ps.fail(*p, "expected 3 numbers");
    return {float(p->numbers[0]), float(p->numbers[1]), float(p->numbers[2])};
  }
  if (p->type == "float") {
    if (p->numbers.size() != 1) ps.fail(*p, "expected 1 number");
    return Rgb(float(p->numbers[0]));
  }
  if (p->type == "texture") {
    if (p->strings.size() != 1) ps.fail(*p, "expected one texture name");
    auto it = textures_.find(p->strings[0]);
    if (it == textures_.end()) ps.fail(*p, "no texture named \"" + p->strings[0] + "\" has been defined");
    return it->second.value;
  }
  if (p->type == "spectrum" || p->type == "blackbody")
    ps.fail(*p, "spectral values are not supported; give \"rgb " + name + "\"");
  ps.fail(*p, "expected rgb, float or texture");
}

double Importer::floatParam(const ParamSet& ps, const std::string& name, double fallback) const {
  const Param* p = ps.find(name);
  if (!p) return fallback;
  if (p->type == "texture") {
    p->used = true;
    auto it = p->strings.size() == 1 ? textures_.find(p->strings[0]) : textures_.end();
    if (it == textures_.end() || !it->second.isFloat) ps.fail(*p, "expected a float texture");
    return it->second.value.r;
  }
  if (p->type == "spectrum" && p->numbers.size() == 1) {  // v4 allows a constant spectrum for eta
    p->used = true;
    return p->numbers[0];
  }
  return ps.getFloat(name, fallback);
}

void Importer::texture(const std::string& name, const std::string& kind, const std::string& type, const ParamSet& ps,
                       const Loc& at) {
  bool isFloat = kind == "float";
  if (!isFloat && kind != "spectrum" && kind != "color" && kind != "rgb")
    failAt(at, "Texture \"" + name + "\": unknown texture kind \"" + kind + "\" (float or spectrum)");
  TextureValue t;
  t.isFloat = isFloat;
  if (type == "constant") {
    t.value = isFloat ? Rgb(float(floatParam(ps, "value", 1.0))) : color(ps, "value", Rgb(1.0f));
  } else if (type == "checkerboard") {
    failAt(at, "Texture \"" + name + "\": checkerboard is not supported: pbrt's checkerboard is laid out in (u, v), "
               "tdpm's checker in object-space (x, y, z), and the two do not agree in general");
  } else {
    failAt(at, "Texture \"" + name + "\": type \"" + type + "\" is not supported (constant)");
  }
  ps.checkAllUsed();
  textures_[name] = t;
}

float reflectanceAtNormal(double eta, double k) {
  return float(((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k));
}

void checkReflectance(const ParamSet& ps, const std::string& name, Rgb c) {
  if (c.r < 0 || c.g < 0 || c.b < 0 || c.maxComponent() > 1) {
    if (const Param* p = ps.find(name)) ps.fail(*p, "reflectance must be in [0, 1] per channel (energy conservation)");
    throw Error(ps.file() + ": " + ps.statement() + ": " + name + " must be in [0, 1]");
  }
}

MaterialSlot Importer::makeMaterial(const std::string& type, const ParamSet& ps, const Loc& at, const std::string& name) {
  using T = scene::MaterialDesc::Type;
  MaterialSlot slot;
  scene::MaterialDesc& m = slot.desc;
  std::string label = name.empty() ? type : name;
  auto roughness = [&](bool v3, double fallback, double* alpha) {
    double u = floatParam(ps, "uroughness", floatParam(ps, "roughness", fallback));
    double v = floatParam(ps, "vroughness", floatParam(ps, "roughness", fallback));
    if (u != v) failAt(at, label + ": anisotropic roughness (uroughness != vroughness) is not supported");
    bool remap = ps.getBool("remaproughness", true);
    if (u < 0) failAt(at, label + ": roughness must not be negative");
    *alpha = !remap || u == 0 ? u : (v3 ? roughnessToAlphaV3(u) : std::sqrt(u));
    if (*alpha > 1) failAt(at, label + ": roughness maps to GGX alpha " + fmtNum(*alpha) + " > 1, which tdpm does not support");
  };
  if (type == "" || type == "interface" || type == "none") {
    slot.interface = true;
  } else if (type == "matte" || type == "diffuse") {
    m.type = T::Diffuse;
    std::string key = type == "matte" ? "Kd" : "reflectance";
    m.albedo.color = color(ps, key, Rgb(0.5f));
    checkReflectance(ps, key, m.albedo.color);
    if (type == "matte" && floatParam(ps, "sigma", 0) != 0) failAt(at, label + ": Oren-Nayar roughness (sigma > 0) is not supported");
  } else if (type == "mirror") {
    m.type = T::Mirror;
    m.specular = color(ps, "Kr", Rgb(0.9f));
    checkReflectance(ps, "Kr", m.specular);
  } else if (type == "glass" || type == "dielectric") {
    m.type = T::Dielectric;
    double eta = floatParam(ps, "eta", ps.has("index") ? floatParam(ps, "index", 1.5) : 1.5);
    if (!(eta >= 1)) failAt(at, label + ": eta " + fmtNum(eta) + " below 1 is not supported");
    m.ior = float(eta);
    double alpha;
    roughness(type == "glass", 0, &alpha);
    if (alpha != 0) failAt(at, label + ": rough glass is not supported (roughness must be 0)");
    if (type == "glass") {
      Rgb kr = color(ps, "Kr", Rgb(1.0f)), kt = color(ps, "Kt", Rgb(1.0f));
      if (kr.r != kt.r || kr.g != kt.g || kr.b != kt.b)
        failAt(at, label + ": Kr and Kt differ; tdpm's dielectric has one tint for reflection and transmission");
      checkReflectance(ps, "Kr", kr);
      m.specular = kr;
    }
  } else if (type == "metal" || type == "conductor") {
    bool v3 = type == "metal";
    Rgb r0;
    if (!v3 && ps.has("reflectance")) {
      r0 = color(ps, "reflectance", Rgb(1.0f));
    } else {
      if (!ps.has("eta") || !ps.has("k"))
        failAt(at, label + ": give \"rgb eta\" and \"rgb k\" (pbrt's default is spectral copper, which tdpm cannot represent)");
      Rgb eta = color(ps, "eta", Rgb(1.0f)), k = color(ps, "k", Rgb(0.0f));
      for (int i = 0; i < 3; ++i) r0[i] = reflectanceAtNormal(eta[i], k[i]);
    }
    checkReflectance(ps, "reflectance", r0);
    double alpha;
    roughness(v3, v3 ? 0.01 : 0.0, &alpha);
    if (alpha == 0) {
      m.type = T::Mirror;  // a smooth conductor: its Fresnel curve becomes the constant normal-incidence value
      m.specular = r0;
    } else {
      m.type = T::Metal;
      m.specular = r0;
      m.roughness = float(std::max(alpha, 1e-3));
    }
    note(at, label + ": conductor approximated by its reflectance at normal incidence (Schlick) with GGX alpha " +
                 fmtNum(alpha) + " (see docs/pbrt-import.md)");
  } else if (type == "plastic" || type == "coateddiffuse") {
    bool v3 = type == "plastic";
    m.type = T::Plastic;
    std::string key = v3 ? "Kd" : "reflectance";
    m.albedo.color = color(ps, key, Rgb(v3 ? 0.25f : 0.5f));
    checkReflectance(ps, key, m.albedo.color);
    double alpha;
    roughness(v3, v3 ? 0.1 : 0.0, &alpha);
    m.roughness = float(std::max(alpha, 1e-3));
    if (v3) {
      color(ps, "Ks", Rgb(0.25f));
      m.ior = 1.5f;
    } else {
      double eta = floatParam(ps, "eta", 1.5);
      if (!(eta >= 1)) failAt(at, label + ": eta below 1 is not supported");
      m.ior = float(eta);
      Rgb albedo = color(ps, "albedo", Rgb(0.0f));
      if (!albedo.isBlack()) failAt(at, label + ": a coating with a scattering albedo is not supported");
      for (const char* q : {"thickness", "g", "maxdepth", "nsamples"}) ps.markUsed(q);
    }
    note(at, label + ": " + type + " approximated by tdpm's plastic (Lambert base under a GGX dielectric coating, ior " +
                 fmtNum(m.ior) + (v3 ? "; Ks ignored" : "; thickness ignored") + ")");
  } else {
    failAt(at, "material type \"" + type + "\" is not supported (see docs/pbrt-import.md)");
  }
  ps.markUsed("type");
  ps.checkAllUsed();
  m.name = name;  // unique names are given when a shape first uses the material
  return slot;
}

std::string Importer::uniqueMaterialName(const std::string& base) {
  std::string name = base;
  for (int i = 2; materialNames_.count(name); ++i) name = base + "#" + std::to_string(i);
  materialNames_.insert(name);
  return name;
}

uint32_t Importer::materialIndex(int slot) {
  MaterialSlot& s = materials_[size_t(slot)];
  if (s.index < 0) {
    scene::MaterialDesc d = s.desc;
    d.name = uniqueMaterialName(d.name.empty() ? "material" + std::to_string(slot) : d.name);
    result.scene.materials.push_back(d);
    s.index = int(result.scene.materials.size()) - 1;
  }
  return uint32_t(s.index);
}

// ------------------------------------------------------------ lights

Rgb Importer::lightScale(const ParamSet& ps) const {
  const Param* p = ps.find("scale");
  if (!p) return Rgb(1.0f);
  return color(ps, "scale", Rgb(1.0f));  // float (v4) or rgb (v3)
}

Rgb nonNegative(const ParamSet& ps, const std::string& name, Rgb c) {
  if (c.r < 0 || c.g < 0 || c.b < 0) {
    if (const Param* p = ps.find(name)) ps.fail(*p, "must be non-negative in every channel");
  }
  return c;
}

void Importer::lightSource(const std::string& type, const ParamSet& ps, const Loc& at) {
  if (currentInstance_) failAt(at, "LightSource inside an object definition is not supported");
  Mat W = mirror_ ? mirrorX() : Mat();
  Mat M = W * gs_.ctm[0];
  if (!(gs_.ctm[0] == gs_.ctm[1]))
    note(at, "LightSource: lights do not move in pbrt; the StartTime transform is used (as pbrt does)");
  Rgb sc = lightScale(ps);
  double power = ps.has("power") ? ps.getFloat("power", -1) : -1;
  scene::LightDesc l;
  l.name = "LightSource \"" + type + "\" (" + at.str() + ")";
  if (type == "point") {
    Rgb I = nonNegative(ps, "I", color(ps, "I", Rgb(1.0f))) * sc;
    if (power > 0) I = I * float(power / (4 * kPiD));
    l.type = scene::LightDesc::Type::Point;
    l.position = M.point(ps.getPoint("from", {0, 0, 0}));
    l.power = I * float(4 * kPiD);
  } else if (type == "spot") {
    Rgb I = nonNegative(ps, "I", color(ps, "I", Rgb(1.0f))) * sc;
    double cone = ps.getFloat("coneangle", 30), delta = ps.getFloat("conedeltaangle", 5);
    if (!(cone > 0 && cone <= 90)) failAt(at, "LightSource \"spot\": coneangle must be in (0, 90] degrees for tdpm, got " + fmtNum(cone));
    if (!(delta >= 0 && delta <= cone)) failAt(at, "LightSource \"spot\": conedeltaangle must be in [0, coneangle], got " + fmtNum(delta));
    double cosT = std::cos(cone * kPiD / 180), cosS = std::cos((cone - delta) * kPiD / 180);
    if (power > 0) I = I * float(power / (2 * kPiD * ((1 - cosS) + (cosS - cosT) / 2)));  // pbrt-v4's k_e
    Vec3f from = ps.getPoint("from", {0, 0, 0}), to = ps.getPoint("to", {0, 0, 1});
    Vec3f dir = M.vector(to - from);
    if (!(length(dir) > 0)) failAt(at, "LightSource \"spot\": from and to coincide");
    std::optional<Pose> p = decompose(M);
    if (!p || std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.y)) > 1e-5f * std::fabs(p->scale.x) ||
        std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.z)) > 1e-5f * std::fabs(p->scale.x))
      failAt(at, "LightSource \"spot\": a non-uniform scale or shear would distort the cone; not supported");
    l.type = scene::LightDesc::Type::Spot;
    l.position = M.point(from);
    l.direction = canonicalDirection(normalize(dir));
    l.coneAngle = float(cone);
    l.falloffStart = float(cone - delta);
    float solid = float(2 * kPiD * ((1 - cosS) + (cosS - cosT) / 5));  // tdpm's exact integral of the quartic falloff
    l.power = I * solid;
    if (delta > 0)
      note(at, "LightSource \"spot\": the falloff band uses pbrt-v3's quartic curve; pbrt-v4 uses smoothstep there");
  } else if (type == "distant") {
    if (power > 0) failAt(at, "LightSource \"distant\": \"power\" depends on pbrt's scene radius; give L instead");
    Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * sc;
    Vec3f from = ps.getPoint("from", {0, 0, 0}), to = ps.getPoint("to", {0, 0, 1});
    Vec3f dir = M.vector(to - from);
    if (!(length(dir) > 0)) failAt(at, "LightSource \"distant\": from and to coincide");
    l.type = scene::LightDesc::Type::Directional;
    l.direction = canonicalDirection(normalize(dir));  // pbrt's light travels from "from" toward "to"
    l.power = L;                   // irradiance on a surface facing the light
  } else if (type == "infinite") {
    if (ps.has("filename") || ps.has("mapname")) failAt(at, "LightSource \"infinite\": an environment map is not supported (constant L only)");
    if (power > 0 || ps.has("illuminance")) failAt(at, "LightSource \"infinite\": \"power\"/\"illuminance\" is not supported; give L");
    Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * sc;
    for (const char* q : {"nsamples", "samples"}) ps.markUsed(q);
    ps.checkAllUsed();
    result.scene.background = result.scene.background + L;
    return;
  } else {
    failAt(at, "LightSource \"" + type + "\" is not supported (point, spot, distant, infinite)");
  }
  ps.checkAllUsed();
  result.scene.lights.push_back(l);
}

// ------------------------------------------------------------ shapes

void Importer::shape(const std::string& type, ParamSet params, const Loc& at) {
  ShapeRecord rec{type, std::move(params), {gs_.ctm[0], gs_.ctm[1]}, gs_.material, gs_.area, at};
  if (currentInstance_) {
    if (rec.area) failAt(at, "Shape: area lights inside an object definition are not supported (pbrt ignores them too)");
    currentInstance_->push_back(std::move(rec));
    return;
  }
  Mat ctm[2] = {gs_.ctm[0], gs_.ctm[1]};
  emitShape(rec, ctm, {});
}

struct Geometry {
  bool sphere = false;
  float radius = 1;
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;
};

std::vector<Vec3f> readPoints(const ParamSet& ps, const std::string& name) {
  const Param* p = ps.find(name);
  if (!p) throw Error(ps.file() + ": " + ps.statement() + ": missing parameter \"point3 " + name + "\"");
  if (p->type != "point3") ps.fail(*p, "expected type point3");
  std::vector<double> v = ps.getFloats(name);
  if (v.empty() || v.size() % 3) ps.fail(*p, "expected a non-empty multiple of 3 numbers, got " + std::to_string(v.size()));
  std::vector<Vec3f> out;
  for (size_t i = 0; i < v.size(); i += 3) out.push_back({float(v[i]), float(v[i + 1]), float(v[i + 2])});
  return out;
}

std::vector<uint32_t> readIndices(const ParamSet& ps, size_t vertexCount, size_t per, const std::string& what) {
  const Param* p = ps.find("indices");
  std::vector<uint32_t> out;
  if (!p) {
    if (vertexCount != per)
      throw Error(ps.file() + ": " + ps.statement() + ": missing parameter \"integer indices\" (only a single " + what +
                  " of " + std::to_string(per) + " points may omit it)");
    for (uint32_t i = 0; i < per; ++i) out.push_back(i);
    return out;
  }
  std::vector<int64_t> v = ps.getInts("indices");
  if (v.empty() || v.size() % per)
    ps.fail(*p, "expected a non-empty multiple of " + std::to_string(per) + " indices, got " + std::to_string(v.size()));
  for (int64_t i : v) {
    if (i < 0 || uint64_t(i) >= vertexCount)
      ps.fail(*p, "index " + std::to_string(i) + " is out of range (there are " + std::to_string(vertexCount) + " points)");
    out.push_back(uint32_t(i));
  }
  return out;
}

// Appends quads (a, b, c, d in the file's corner order) as two triangles:
// exact only for flat parallelograms, where pbrt-v3's triangle split and
// pbrt-v4's bilinear patch agree.
void addQuads(const std::vector<Vec3f>& P, const std::vector<uint32_t>& quads, const Loc& at, const std::string& what,
              std::vector<uint32_t>* triangles) {
  for (size_t i = 0; i < quads.size(); i += 4) {
    Vec3f a = P[quads[i]], b = P[quads[i + 1]], c = P[quads[i + 2]], d = P[quads[i + 3]];
    float scale = std::max({length(b - a), length(d - a), 1e-30f});
    if (length((a + c) - (b + d)) > 1e-5f * scale)
      failAt(at, what + ": quad " + std::to_string(i / 4) + " is not a flat parallelogram (pbrt-v3 and v4 would render it differently)");
    triangles->insert(triangles->end(), {quads[i], quads[i + 1], quads[i + 2], quads[i], quads[i + 2], quads[i + 3]});
  }
}

Geometry makeGeometry(const ShapeRecord& rec, const std::function<void(const std::string&)>& note, const std::string& mainDir) {
  const ParamSet& ps = rec.params;
  Geometry g;
  if (rec.type == "sphere") {
    g.sphere = true;
    double r = ps.getFloat("radius", 1);
    if (!(r > 0)) failAt(rec.at, "Shape \"sphere\": radius must be positive, got " + fmtNum(r));
    double zmin = ps.getFloat("zmin", -r), zmax = ps.getFloat("zmax", r), phimax = ps.getFloat("phimax", 360);
    if (zmin > -r || zmax < r || phimax < 360)
      failAt(rec.at, "Shape \"sphere\": partial spheres (zmin, zmax, phimax) are not supported");
    g.radius = float(r);
  } else if (rec.type == "trianglemesh" || rec.type == "bilinearmesh") {
    bool bilinear = rec.type == "bilinearmesh";
    std::vector<Vec3f> P = readPoints(ps, "P");
    std::vector<uint32_t> idx = readIndices(ps, P.size(), bilinear ? 4 : 3, bilinear ? "patch" : "triangle");
    for (const char* q : {"N", "uv", "S", "st", "faceIndices"})
      if (ps.has(q)) {
        ps.markUsed(q);
        note(std::string("Shape \"") + rec.type + "\": \"" + q + "\" ignored (tdpm shades with the geometric normal)");
      }
    g.vertices = P;
    if (!bilinear) {
      g.indices = idx;
    } else {
      // A bilinear patch (p00, p10, p01, p11) is flat and equal to two
      // triangles exactly when it is a parallelogram.
      for (size_t i = 0; i < idx.size(); i += 4) {
        Vec3f p00 = P[idx[i]], p10 = P[idx[i + 1]], p01 = P[idx[i + 2]], p11 = P[idx[i + 3]];
        Vec3f gap = (p00 + p11) - (p10 + p01);
        float scale = std::max({length(p10 - p00), length(p01 - p00), 1e-30f});
        if (length(gap) > 1e-5f * scale)
          failAt(rec.at, "Shape \"bilinearmesh\": patch " + std::to_string(i / 4) +
                             " is not a flat parallelogram; only those are exactly two triangles");
        g.indices.insert(g.indices.end(), {idx[i], idx[i + 1], idx[i + 3], idx[i], idx[i + 3], idx[i + 2]});
      }
    }
  } else if (rec.type == "plymesh") {
    std::string file = ps.getString("filename", "");
    if (file.empty()) failAt(rec.at, "Shape \"plymesh\": missing parameter \"string filename\"");
    if (ps.has("displacement")) failAt(rec.at, "Shape \"plymesh\": displacement is not supported");
    ps.markUsed("edgelength");
    PlyMesh ply;
    try {
      ply = readPly(resolvePath(file, rec.at.file, mainDir));
    } catch (const Error& e) {
      failAt(rec.at, std::string("Shape \"plymesh\": ") + e.what());
    }
    for (const std::string& q : ply.ignoredProperties)
      note("Shape \"plymesh\": vertex property \"" + q + "\" ignored (tdpm shades with the geometric normal)");
    g.vertices = std::move(ply.vertices);
    g.indices = std::move(ply.triangles);
    addQuads(g.vertices, ply.quads, rec.at, "Shape \"plymesh\" \"" + file + "\"", &g.indices);
  } else {
    failAt(rec.at, "Shape \"" + rec.type + "\" is not supported (sphere, trianglemesh, bilinearmesh, plymesh)");
  }
  ps.checkAllUsed();
  return g;
}

Importer::MotionPlan Importer::planMotion(const Mat ctm[2], const Loc& at, const std::string& what) const {
  MotionPlan plan;
  Mat W = mirror_ ? mirrorX() : Mat();
  if (ctm[0] == ctm[1]) {
    plan.still = W * ctm[0];
    return plan;
  }
  // pbrt splits each transform into T R S and interpolates T and S
  // linearly and R by slerp between TransformTimes; tdpm's keyframes do the
  // same, so the two poses become two keyframes (clipped to the shutter).
  std::optional<Pose> p[2];
  for (int i = 0; i < 2; ++i) {
    p[i] = decompose(ctm[i]);
    if (!p[i] || ctm[i].det3() < 0)
      failAt(at, what + ": its " + (i ? "EndTime" : "StartTime") +
                     " transform has shear, a scale along rotated axes or a mirror; pbrt would interpolate its polar "
                     "decomposition, which tdpm's keyframes cannot express");
  }
  float t0 = transformStart_, t1 = transformEnd_;
  auto poseAt = [&](float t) {
    float u = std::clamp((t - t0) / (t1 - t0), 0.0f, 1.0f);
    Pose q;
    q.translate = lerp(p[0]->translate, p[1]->translate, u);
    q.rotate = slerp(p[0]->rotate, p[1]->rotate, u);
    q.scale = lerp(p[0]->scale, p[1]->scale, u);
    return q;
  };
  auto toMat = [](const Pose& q) {
    Affine3f a = Affine3f::fromTRS(q.translate, q.rotate, q.scale);
    Mat m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) m.m[i][j] = a.m[i][j];
    return m;
  };
  float a = std::max(t0, shutterOpen_), b = std::min(t1, shutterClose_);
  if (!(a < b)) {
    // The shutter sees one pose: before the start, after the end, or an instant.
    if (t1 <= shutterOpen_) plan.still = W * ctm[1];
    else if (t0 >= shutterClose_) plan.still = W * ctm[0];
    else plan.still = W * toMat(poseAt(a));
    return plan;
  }
  plan.moving = true;
  for (float t : {a, b}) {
    Pose q = poseAt(t);
    if (mirror_) q = mirrorPose(q);
    scene::TransformDesc d;
    d.translate = q.translate;
    d.rotate = canonicalRotation(q.rotate);
    d.scale = q.scale;
    plan.keys.times.push_back(t);
    plan.keys.poses.push_back(d);
  }
  return plan;
}

bool nearlyUniform(Vec3f s) {
  float a = std::fabs(s.x);
  return std::fabs(std::fabs(s.y) - a) <= 1e-5f * a && std::fabs(std::fabs(s.z) - a) <= 1e-5f * a;
}

void Importer::emitShape(const ShapeRecord& rec, const Mat ctm[2], const Loc& instanceAt) {
  Geometry g = makeGeometry(rec, [&](const std::string& w) { note(rec.at, w); }, mainDir);
  const MaterialSlot& mat = materials_[size_t(rec.material)];
  if (rec.area) {
    if (g.sphere) failAt(rec.at, "Shape \"sphere\" with an AreaLightSource: tdpm's area lights are rectangles");
    emitAreaLight(rec, g.vertices, g.indices, ctm);
    return;
  }
  if (mat.interface) return;  // no surface: invisible without participating media
  scene::ObjectDesc o;
  o.name = "Shape \"" + rec.type + "\" (" + rec.at.str() + (instanceAt.file.empty() ? "" : ", instance at " + instanceAt.str()) + ")";
  MotionPlan plan = planMotion(ctm, rec.at, "Shape \"" + rec.type + "\"");
  if (g.sphere) {
    o.shape.type = scene::ShapeDesc::Type::Sphere;
    o.shape.radius = g.radius;
    if (!plan.moving) {
      std::optional<Pose> p = decompose(plan.still);
      if (!p || !nearlyUniform(p->scale))
        failAt(rec.at, "Shape \"sphere\" under a non-uniform scale or shear (an ellipsoid) is not supported");
      o.placement.translate = p->translate;
      o.placement.rotate = canonicalRotation(p->rotate);
      o.placement.scale = p->scale;
    } else {
      for (const auto& k : plan.keys.poses)
        if (!nearlyUniform(k.scale)) failAt(rec.at, "Shape \"sphere\" under a non-uniform scale (an ellipsoid) is not supported");
      o.motion = plan.keys;
    }
  } else {
    o.shape.type = scene::ShapeDesc::Type::Mesh;
    o.shape.indices = g.indices;
    if (!plan.moving) {
      // Bake the placement into the vertices (any affine map is exact). A
      // mirroring map flips the winding; swap it back so the face normal
      // keeps pbrt's orientation (which transforms normals, not windings).
      for (Vec3f v : g.vertices) o.shape.vertices.push_back(plan.still.point(v));
      if (plan.still.det3() < 0)
        for (size_t i = 0; i < o.shape.indices.size(); i += 3) std::swap(o.shape.indices[i + 1], o.shape.indices[i + 2]);
    } else {
      o.shape.vertices = g.vertices;
      o.motion = plan.keys;
    }
    for (Vec3f v : o.shape.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        failAt(rec.at, "Shape \"" + rec.type + "\": a vertex is not finite after its transform");
  }
  o.material = materialIndex(rec.material);
  result.scene.objects.push_back(std::move(o));
}

void Importer::emitAreaLight(const ShapeRecord& rec, const std::vector<Vec3f>& verts, const std::vector<uint32_t>& idx,
                             const Mat ctm[2]) {
  const ParamSet& ps = rec.area->params;
  const std::string what = "AreaLightSource (" + rec.area->at.str() + ") on Shape \"" + rec.type + "\"";
  bool twoSided = ps.getBool("twosided", false);
  if (twoSided) failAt(rec.area->at, "AreaLightSource: twosided emitters are not supported (tdpm's area lights emit from one side)");
  MotionPlan plan = planMotion(ctm, rec.at, what);
  if (plan.moving) failAt(rec.at, what + ": a moving area light is not supported");
  const Mat& M = plan.still;
  // tdpm's area light is one rectangle: the shape must be two triangles
  // covering a rectangle, both facing the same way.
  std::vector<uint32_t> corners(idx.begin(), idx.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  if (idx.size() != 6 || corners.size() != 4)
    failAt(rec.at, what + ": tdpm's area lights are rectangles; the shape must be one rectangle (2 triangles, 4 points)");
  Vec3f P[4];
  for (int i = 0; i < 4; ++i) P[i] = M.point(verts[corners[size_t(i)]]);
  int far = 1;
  for (int i = 2; i < 4; ++i)
    if (length(P[i] - P[0]) > length(P[far] - P[0])) far = i;
  int a = far == 1 ? 2 : 1, b = far == 3 ? 2 : 3;
  Vec3f e1 = P[a] - P[0], e2 = P[b] - P[0];
  float l1 = length(e1), l2 = length(e2);
  Vec3f tri[2];
  float triArea = 0;
  for (int t = 0; t < 2; ++t) {
    Vec3f p0 = verts[idx[size_t(3 * t)]], p1 = verts[idx[size_t(3 * t + 1)]], p2 = verts[idx[size_t(3 * t + 2)]];
    tri[t] = M.normal(cross(p1 - p0, p2 - p0));  // pbrt's normal: the object-space one, transformed as a normal
    triArea += 0.5f * length(cross(M.point(p1) - M.point(p0), M.point(p2) - M.point(p0)));
  }
  float rectArea = l1 * l2;
  bool rectangle = l1 > 0 && l2 > 0 && std::fabs(dot(e1, e2)) <= 1e-4f * l1 * l2 &&
                   length(P[0] + e1 + e2 - P[far]) <= 1e-4f * (l1 + l2) && std::fabs(triArea - rectArea) <= 1e-4f * rectArea &&
                   dot(tri[0], tri[1]) > 0;
  if (!rectangle) failAt(rec.at, what + ": the shape is not a rectangle of two triangles facing the same way");
  Vec3f n = normalize(tri[0]);
  Vec3f x = e1 / l1, y = -n, z = cross(x, y);
  double R[3][3] = {{x.x, y.x, z.x}, {x.y, y.y, z.y}, {x.z, y.z, z.z}};
  Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * lightScale(ps);
  double power = ps.has("power") ? ps.getFloat("power", -1) : -1;
  if (power > 0) L = L * float(power / (kPiD * rectArea));  // pbrt-v4: one side, area A
  if (ps.has("filename")) failAt(rec.area->at, "AreaLightSource: an image emitter (filename) is not supported");
  ps.checkAllUsed();
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.name = what;
  l.areaSize = {l1, l2};
  l.placement.translate = P[0] + (e1 + e2) * 0.5f;
  l.placement.rotate = canonicalRotation(quaternionFromMatrix(R));
  l.power = L * float(kPiD * rectArea);  // Lambertian: power = L pi A
  const MaterialSlot& mat = materials_[size_t(rec.material)];
  bool black = mat.interface || (mat.desc.type == scene::MaterialDesc::Type::Diffuse && mat.desc.albedo.color.isBlack());
  if (!black)
    note(rec.at, what + ": tdpm's area lights do not reflect light; the emitter's material is ignored");
  result.scene.lights.push_back(l);
}

void Importer::finish(const std::string& file) {
  if (!sawWorld_) throw Error(file + ": no WorldBegin: not a complete pbrt scene");
  if (currentInstance_) failAt(stack_.empty() ? worldAt_ : stack_.back().at, "ObjectBegin \"" + currentInstanceName_ + "\" without ObjectEnd");
  if (!stack_.empty())
    failAt(stack_.back().at, std::string(stack_.back().attribute ? "AttributeBegin" : "TransformBegin") + " without a matching End");
  if (imagingRatio_ != 1) {
    float k = float(imagingRatio_);
    for (auto& l : result.scene.lights) l.power = l.power * k;
    result.scene.background = result.scene.background * k;
    result.notes.push_back(film_.at.str() + ": Film: pbrt-v4 scales the image by exposure time x ISO / 100 = " +
                           fmtNum(imagingRatio_) + "; the import scales every light by it");
  }
}

}  // namespace

ImportResult importPbrtText(const std::string& text, const std::string& path) {
  Importer im;
  im.result.scene.sourcePath = path;
  im.mainDir = std::filesystem::path(path).parent_path().string();
  im.parseText(text, path, 0);
  im.finish(path);
  return std::move(im.result);
}

ImportResult importPbrtFile(const std::string& path) {
  Importer im;
  im.result.scene.sourcePath = path;
  im.mainDir = std::filesystem::path(path).parent_path().string();
  im.parseFile(path, 0, "");
  im.finish(path);
  return std::move(im.result);
}

bool isPbrtPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  return ext == ".pbrt";
}

}  // namespace tdpm::pbrt
