// import/pbrt_import.cpp — the pbrt statement parser: tokens (pbrt_tokenizer)
// to statements with their parameter lists (pbrt_params), the graphics
// state they change (CTM pair, attributes, named things, Include/Import,
// object instances) and the options block (camera, film, sampler,
// integrator) applied at WorldBegin. Shapes, materials and lights are
// mapped onto the SceneDescription in pbrt_mapping.cpp.
// docs/pbrt-import.md is the user-facing version of both files.
#include "import/pbrt_import.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/memory.h"
#include "core/regular_file.h"
#include "import/pbrt_importer.h"
#include "sampling/filter.h"
#include "scene/limits.h"

namespace tdpm::pbrt::detail {

namespace {
constexpr int kMaxIncludeDepth = 32;
constexpr int64_t kMaxPhotons = int64_t(1) << 31;
}  // namespace

void failAt(const Loc& at, const std::string& what) { throw Error(at.str() + ": " + what); }

std::string fmtNum(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void Importer::parseFile(const std::string& path, int depth, const std::string& where) {
  namespace L = scene::limits;
  RegularFileCheck f = checkRegularFile(path);
  if (!f.ok) throw Error(where + path + ": cannot read scene file: " + f.problem);
  if (f.size > L::kMaxPbrtFileBytes)
    throw Error(where + path + ": pbrt file is too large (" + std::to_string(f.size) + " bytes; at most " +
                std::to_string(L::kMaxPbrtFileBytes >> 20) + " MiB per file; put large meshes in PLY files)");
  if (f.size > L::kMaxPbrtTotalBytes - bytesRead_)
    throw Error(where + path + ": the scene's files together are larger than " + std::to_string(L::kMaxPbrtTotalBytes >> 20) +
                " MiB (" + std::to_string(bytesRead_) + " bytes read before this " + std::to_string(f.size) +
                "-byte file; is a file included many times?)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(where + path + ": cannot read scene file (" + std::strerror(errno) + ")");
  // Read at most one chunk over the budget, in case the file grew since the stat.
  const uint64_t budget = std::min(L::kMaxPbrtFileBytes, L::kMaxPbrtTotalBytes - bytesRead_);
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk), in.gcount() > 0) {
    text.append(chunk, size_t(in.gcount()));
    if (text.size() > budget) throw Error(where + path + ": pbrt file grew past its size limit while being read");
  }
  if (in.bad()) throw Error(where + path + ": error while reading scene file");
  bytesRead_ += text.size();
  result.inputFiles.push_back(path);
  parseText(text, path, depth);
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

void Importer::note(const Loc& at, const std::string& what) {
  // One note per kind of message: a mesh-heavy scene should not print
  // thousands of identical lines.
  if (!notedKinds_.insert(what).second) return;
  result.notes.push_back(at.str() + ": " + what);
}

void Importer::checkNesting(const Loc& at, const std::string& stmt) const {
  if (stack_.size() >= size_t(scene::limits::kMaxPbrtNesting))
    failAt(at, stmt + ": AttributeBegin/TransformBegin/ObjectBegin nested more than " +
                   std::to_string(scene::limits::kMaxPbrtNesting) + " deep");
}

// Adds n triangles to the scene's count (with !add: only checks), refusing before the copy is made
// when the count passes kMaxPbrtTriangles or its estimated memory the
// memory available when the import began.
void Importer::countTriangles(uint64_t n, const Loc& at, const std::string& what, bool add) {
  namespace L = scene::limits;
  uint64_t total = triangles_ + n;
  if (total > maxTriangles)
    failAt(at, what + ": the scene would have " + std::to_string(total) + " triangles, more than tdpm's limit of " +
                   std::to_string(maxTriangles) + " (instanced copies count in full)");
  if (memoryAtStart_ > 0 && total * L::kPbrtBytesPerTriangle > memoryAtStart_)
    failAt(at, what + ": the scene would have " + std::to_string(total) + " triangles, about " +
                   std::to_string((total * L::kPbrtBytesPerTriangle) >> 20) + " MiB, more than the " +
                   std::to_string(memoryAtStart_ >> 20) + " MiB of memory available");
  if (add) triangles_ = total;
}

void Importer::requireWorld(const Loc& at, const std::string& stmt) const {
  if (!inWorld_) failAt(at, stmt + " is only allowed after WorldBegin");
}

// PixelFilter -> render.filter / filter_radius. tdpm's filters are pbrt-v4's
// box and Gaussian (sigma 0.5 px), square, sampled by importance
// (sampling/filter.h). pbrt-v3 spells radii xwidth/ywidth, v4
// xradius/yradius; v3's Gaussian exp(-alpha x^2) with its default alpha 2
// is sigma 0.5. Without a PixelFilter: a v4 film (rgb, gbuffer, spectral)
// means pbrt-v4, whose default is the Gaussian of radius 1.5; otherwise
// the box of radius 0.5 (pbrt-v3's default, and tdpm's).
void Importer::mapPixelFilter(scene::RenderSettings& r, bool v4Film) {
  if (!pixelFilter_.given) {
    if (v4Film) {
      r.filter = "gaussian";
      r.filterRadius = 1.5f;
    }
    return;
  }
  const ParamSet& ps = pixelFilter_.params;
  const Loc& at = pixelFilter_.at;
  const std::string& type = pixelFilter_.type;
  bool gaussian = type == "gaussian";
  if (type != "box" && !gaussian) {
    for (const char* q : {"xwidth", "ywidth", "xradius", "yradius", "B", "C", "tau", "alpha", "sigma"}) ps.markUsed(q);
    note(at, "PixelFilter \"" + type + "\" is not supported: tdpm's box filter (one pixel) is used");
    ps.checkAllUsed();
    return;
  }
  // A radius not given takes its version's default; the Gaussian's is 2 in
  // pbrt-v3 and 1.5 in v4 (the box's 0.5 in both). The version shows in the
  // parameter names and the film ("image" is v3's); otherwise v4.
  bool v3 = ps.has("xwidth") || ps.has("ywidth") || ps.has("alpha") || (film_.given && film_.type == "image");
  float fallback = gaussian ? (v3 ? 2.0f : 1.5f) : 0.5f;
  auto radius = [&](const char* v3Name, const char* v4Name) {
    if (ps.has(v3Name) && ps.has(v4Name))
      ps.fail(*ps.find(v4Name), std::string("give either \"") + v3Name + "\" (pbrt-v3) or \"" + v4Name + "\" (pbrt-v4), not both");
    return float(ps.has(v3Name) ? ps.getFloat(v3Name, fallback) : ps.getFloat(v4Name, fallback));
  };
  float rx = radius("xwidth", "xradius");
  float ry = radius("ywidth", "yradius");
  for (float v : {rx, ry})
    if (!(v >= scene::limits::kFilterRadius.lo && v <= scene::limits::kFilterRadius.hi))
      failAt(at, "PixelFilter \"" + type + "\": radius " + fmtNum(v) + " is outside [" + fmtNum(scene::limits::kFilterRadius.lo) +
                     ", " + fmtNum(scene::limits::kFilterRadius.hi) + "] pixels");
  if (rx != ry) note(at, "PixelFilter \"" + type + "\": x and y radii differ (" + fmtNum(rx) + ", " + fmtNum(ry) +
                             "); tdpm's filters are square, the larger is used");
  if (gaussian) {
    if (ps.has("alpha") && ps.has("sigma")) ps.fail(*ps.find("sigma"), "give either \"alpha\" (pbrt-v3) or \"sigma\" (pbrt-v4), not both");
    double sigma = ps.has("alpha") ? 1.0 / std::sqrt(2.0 * std::max(ps.getFloat("alpha", 2), 1e-30))
                                   : ps.getFloat("sigma", kGaussianFilterSigma);
    if (std::fabs(sigma - kGaussianFilterSigma) > 1e-6)
      note(at, "PixelFilter \"gaussian\": sigma " + fmtNum(sigma) + " px is not supported (tdpm's Gaussian has sigma " +
                   fmtNum(kGaussianFilterSigma) + "); the radius is kept");
  }
  ps.checkAllUsed();
  r.filter = type;
  r.filterRadius = std::max(rx, ry);
}

void Importer::requireOptions(const Loc& at, const std::string& stmt) const {
  if (inWorld_ || worldEnded_) failAt(at, stmt + " is only allowed before WorldBegin");
}

void Importer::applyTransform(const Mat& m, bool replace) {
  for (int i = 0; i < 2; ++i)
    if (gs_.active & (1u << i)) gs_.ctm[i] = replace ? m : gs_.ctm[i] * m;
}

void Importer::parseText(const std::string& text, const std::string& file, int depth) {
  std::vector<Token> tokens;
  try {
    tokens = tokenize(text, file);
  } catch (const std::bad_alloc&) {
    throw Error(file + ": out of memory while reading its " + std::to_string(text.size()) + " bytes");
  }
  // The ObjectInstance statements still to come in this file, per object:
  // the triangle pre-flight counts them all at the first copy whose size
  // is known, instead of building copies until the budget runs out.
  std::map<std::string, uint64_t> pending;
  for (size_t i = 0; i + 1 < tokens.size(); ++i)
    if (tokens[i].kind == Token::Kind::Word && tokens[i].text == "ObjectInstance" && tokens[i + 1].kind == Token::Kind::String)
      ++pending[tokens[i + 1].text];
  pendingInstances_.push_back(std::move(pending));
  Cursor c(tokens, file);
  while (!c.done()) {
    const Token& word = c.next();
    if (word.kind != Token::Kind::Word)
      failAt({file, word.line}, "expected a statement (such as Shape or WorldBegin), got '" + word.text + "'");
    ++statementCount_;
    try {
      statement(c, word, depth);
    } catch (const std::bad_alloc&) {
      // Under a memory limit (ulimit -v) the budgets below may not be
      // reached first: still say where.
      failAt({file, word.line}, word.text + ": out of memory while importing this statement");
    }
  }
  pendingInstances_.pop_back();
}

static Mat matrixFrom16(const std::vector<double>& v) {
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
    camera_ = {type, c.params("Camera \"" + type + "\""), at, true, statementCount_};
    cameraCtm_[0] = gs_.ctm[0];
    cameraCtm_[1] = gs_.ctm[1];
    for (int i = 0; i < 2; ++i) {
      auto inv = gs_.ctm[i].inverse();
      if (!inv) failAt(at, "Camera: the current transform is singular");
    }
    coordSystems_["camera"] = *gs_.ctm[0].inverse();
    // pbrt (v3 and v4): the camera sits in the outside medium current at Camera.
    cameraMedium_ = gs_.mediumOutside;
    cameraMediumAt_ = gs_.mediumOutside.empty() ? at : gs_.mediumAt;
  } else if (s == "MakeNamedMedium") {
    std::string name = c.string(s);
    makeNamedMedium(name, c.params("MakeNamedMedium \"" + name + "\""), at);
  } else if (s == "MediumInterface") {
    // One name: the same medium on both sides (pbrt-v4); two: inside, outside.
    std::string inside = c.string(s), outside = inside;
    if (!c.done() && c.peek().kind == Token::Kind::String) outside = c.string(s);
    gs_.mediumInside = inside;
    gs_.mediumOutside = outside;
    gs_.mediumAt = at;
  } else if (s == "Film" || s == "Sampler" || s == "Integrator" || s == "PixelFilter") {
    requireOptions(at, s);
    std::string type = c.string(s);
    Statement st{type, c.params(s + " \"" + type + "\""), at, true, statementCount_};
    (s == "Film" ? film_ : s == "Sampler" ? sampler_ : s == "Integrator" ? integrator_ : pixelFilter_) = std::move(st);
  } else if (s == "Accelerator" || s == "ColorSpace") {
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
    checkNesting(at, s);
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
    if (++includes_ > scene::limits::kMaxPbrtIncludes)
      failAt(at, s + " \"" + name + "\": more than " + std::to_string(scene::limits::kMaxPbrtIncludes) +
                     " Include/Import statements in one scene (files that include each other repeatedly?)");
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
    size_t before = result.scene.lights.size();
    lightSource(type, c.params("LightSource \"" + type + "\""), at);
    // pbrt: a light sits in the outside medium current at its statement.
    for (size_t i = before; i < result.scene.lights.size(); ++i)
      lightMedium(gs_.mediumOutside, gs_.mediumAt, i, result.scene.lights[i].name);
  } else if (s == "AreaLightSource") {
    requireWorld(at, s);
    std::string type = c.string(s);
    ParamSet ps = c.params("AreaLightSource \"" + type + "\"");
    // pbrt-v3 also accepts "area" for its (only) diffuse area light.
    if (type != "diffuse" && type != "area")
      failAt(at, "AreaLightSource \"" + type + "\" is not supported (only \"diffuse\", or pbrt-v3's alias \"area\")");
    gs_.area = AreaLight{std::move(ps), at};
  } else if (s == "ObjectBegin") {
    requireWorld(at, s);
    std::string name = c.string(s);
    if (currentInstance_) failAt(at, "ObjectBegin \"" + name + "\" inside the definition of \"" + currentInstanceName_ + "\"");
    checkNesting(at, s);
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
    // Pre-flight: once an object's triangle count is known (its first
    // instance), this copy and the later ones in this file are counted
    // before this one is made.
    uint64_t later = 0;
    if (!pendingInstances_.empty()) {
      uint64_t& p = pendingInstances_.back()[name];
      if (p > 0) --p;
      later = p;
    }
    auto preflight = [&](uint64_t perCopy) {
      if (perCopy == 0) return;
      uint64_t copies = std::min<uint64_t>(later, (uint64_t(1) << 62) / perCopy);
      countTriangles(perCopy * (1 + copies), at,
                     "ObjectInstance \"" + name + "\"" + (copies ? " (with its " + std::to_string(later) + " later copies in this file)" : ""),
                     false);
    };
    auto known = instanceTriangles_.find(name);
    if (known != instanceTriangles_.end()) preflight(known->second);
    uint64_t before = triangles_;
    for (const ShapeRecord& rec : it->second) {
      Mat ctm[2] = {gs_.ctm[0] * rec.ctm[0], gs_.ctm[1] * rec.ctm[1]};
      emitShape(rec, ctm, at);
    }
    if (known == instanceTriangles_.end()) {
      instanceTriangles_[name] = triangles_ - before;
      // The copies still to come, counted now that one copy's size is known.
      uint64_t perCopy = triangles_ - before;
      if (perCopy > 0 && later > 0) {
        uint64_t copies = std::min<uint64_t>(later, (uint64_t(1) << 62) / perCopy);
        countTriangles(perCopy * copies, at,
                       "ObjectInstance \"" + name + "\" (its " + std::to_string(later) + " later copies in this file)", false);
      }
    }
  } else if (s == "ReverseOrientation") {
    // pbrt toggles the flag in the graphics state (AttributeEnd restores
    // it, TransformEnd does not); each Shape records it (pbrt_mapping.cpp).
    requireWorld(at, s);
    gs_.reverseOrientation = !gs_.reverseOrientation;
  } else {
    failAt(at, "statement " + s + " is not supported by tdpm's pbrt import (see docs/pbrt-import.md)");
  }
}

// ------------------------------------------------------------ options block

namespace {
// The error of the options statement that comes first in the file (by
// statement number; a statement not given counts as last).
struct FirstError {
  int64_t seq = std::numeric_limits<int64_t>::max();
  std::string what;
  bool any = false;
  template <class F>
  void run(const Statement& st, F&& f) {
    try {
      f();
    } catch (const Error& e) {
      int64_t s = st.given ? st.seq : std::numeric_limits<int64_t>::max();
      if (!any || s < seq) {
        seq = s;
        what = e.what();
        any = true;
      }
    }
  }
  void rethrow() const {
    if (any) throw Error(what);
  }
};
}  // namespace

static float verticalFov(double fov, int w, int h) {
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

  // The options statements are mapped here in the order their values
  // depend on each other (Film, Camera, Sampler, PixelFilter, Integrator).
  // A failing one is recorded and the others still run, so that the error
  // reported is the first in the file, as for every other statement.
  FirstError first;

  // Film
  int width = 640, height = 480;
  bool v4Film = false;
  first.run(film_, [&] {
  if (film_.given) {
    const ParamSet& ps = film_.params;
    if (film_.type == "rgb" || film_.type == "gbuffer" || film_.type == "spectral") v4Film = true;
    else if (film_.type != "image") failAt(film_.at, "Film \"" + film_.type + "\" is not supported (image, rgb, gbuffer, spectral)");
    int w = ps.getInt("xresolution", 640), h = ps.getInt("yresolution", 480);
    if (w < 1 || h < 1 || w > 65536 || h > 65536)
      failAt(film_.at, "Film: resolution " + std::to_string(w) + "x" + std::to_string(h) + " is outside 1..65536");
    width = w;
    height = h;
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
    } else if (ps.has("scale")) {
      // pbrt-v3's image film multiplies every pixel by "scale": exact as a
      // factor on every light (light transport is linear).
      double scale = ps.getFloat("scale", 1);
      if (!(scale > 0)) ps.fail(*ps.find("scale"), "must be positive, got " + fmtNum(scale));
      imagingRatio_ = scale;
      filmFactorWhat_ = "pbrt-v3's Film \"image\" scales the image by \"scale\"";
    }
    ps.checkAllUsed();
  }
  });
  sc.camera.width = width;
  sc.camera.height = height;

  // Camera (pbrt's default: perspective, fov 90, at the origin looking down +z)
  double fov = 90;
  first.run(camera_, [&] {
  if (camera_.given) {
    const ParamSet& ps = camera_.params;
    if (camera_.type != "perspective") failAt(camera_.at, "Camera \"" + camera_.type + "\" is not supported (only perspective)");
    fov = ps.has("halffov") ? 2 * ps.getFloat("halffov", 45) : ps.getFloat("fov", 90);
    if (!(fov > 0 && fov < 180)) failAt(camera_.at, "Camera: fov must be in (0, 180) degrees, got " + fmtNum(fov));
    shutterOpen_ = float(ps.getFloat("shutteropen", 0));
    shutterClose_ = float(ps.getFloat("shutterclose", 1));
    if (shutterClose_ < shutterOpen_)
      failAt(camera_.at, "Camera: shutterclose (" + fmtNum(shutterClose_) + ") is before shutteropen (" + fmtNum(shutterOpen_) + ")");
    readThinLens(ps);
    ps.checkAllUsed();
  }
  });
  first.run(film_, [&] {
  if (v4Film) {
    imagingRatio_ *= double(shutterClose_) - double(shutterOpen_);
    if (!(imagingRatio_ > 0))
      failAt(film_.at, "Film: pbrt-v4 scales the image by exposure time x ISO / 100, which is 0 here (zero-length shutter or iso 0)");
  }
  });
  sc.camera.shutterOpen = shutterOpen_;
  sc.camera.shutterClose = shutterClose_;
  sc.camera.fovDegrees = verticalFov(fov, width, height);

  // The camera frame: camera-to-world C = inverse(CTM at Camera).
  first.run(camera_, [&] {
  Loc camAt = camera_.given ? camera_.at : at;
  Mat C[2] = {*cameraCtm_[0].inverse(), *cameraCtm_[1].inverse()};
  struct Frame3 { Vec3f pos, fwd, up; };
  Frame3 f[2];
  for (int i = 0; i < 2; ++i) {
    std::string degenerate = scaleProblem(C[i]);
    if (!degenerate.empty()) failAt(camAt, "Camera: the camera transform is unusable: " + degenerate);
    std::optional<Pose> p = decompose(C[i]);
    bool similar = p && std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.y)) <= 1e-5f * std::fabs(p->scale.x) &&
                   std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.z)) <= 1e-5f * std::fabs(p->scale.x);
    if (!similar) failAt(camAt, "Camera: the camera transform has shear or non-uniform scale, which distorts the image; not supported");
    // pbrt's lens radius and focal distance are camera-space lengths.
    if (i == 0) {
      sc.camera.lensRadius = float(lensRadius_ * std::fabs(p->scale.x));
      sc.camera.focalDistance = float(focalDistance_ * std::fabs(p->scale.x));
    }
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

  });

  // Sampler -> spp
  first.run(sampler_, [&] {
  if (sampler_.given) {
    const ParamSet& ps = sampler_.params;
    static const std::set<std::string> kSamplers = {"halton", "sobol", "zsobol", "paddedsobol", "pmj02bn", "independent",
                                                    "random", "02sequence", "lowdiscrepancy", "maxmindist", "stratified"};
    if (!kSamplers.count(sampler_.type)) failAt(sampler_.at, "Sampler \"" + sampler_.type + "\" is not supported");
    // In 64 bits: xsamples 65536 x ysamples 65536 wrapped to 0 in int and
    // was called "at least 1, got 0" (issue 27 item 17).
    int64_t spp;
    std::string what;
    if (sampler_.type == "stratified") {
      if (!ps.has("xsamples") || !ps.has("ysamples"))
        failAt(sampler_.at, "Sampler \"stratified\": give xsamples and ysamples (pbrt-v3 and v4 defaults differ)");
      int64_t x = ps.getInt("xsamples", 2), y = ps.getInt("ysamples", 2);
      if (x < 1 || y < 1)
        failAt(sampler_.at, "Sampler \"stratified\": xsamples and ysamples must be at least 1, got " + std::to_string(x) +
                                " and " + std::to_string(y));
      spp = x * y;
      what = "xsamples " + std::to_string(x) + " x ysamples " + std::to_string(y) + " = " + std::to_string(spp);
      ps.markUsed("jitter");
    } else {
      spp = ps.getInt("pixelsamples", 16);
      what = "pixelsamples " + std::to_string(spp);
    }
    if (spp < 1) failAt(sampler_.at, "Sampler: samples per pixel must be at least 1, got " + what);
    if (spp > scene::limits::kSpp.hi)
      failAt(sampler_.at, "Sampler \"" + sampler_.type + "\": " + what + " samples per pixel is more than tdpm's limit of " +
                              std::to_string(scene::limits::kSpp.hi) + " (2^20, as --spp and render.spp)");
    r.spp = int(spp);
    for (const char* q : {"seed", "randomization", "dimensions", "jitter"}) ps.markUsed(q);
    note(sampler_.at, "Sampler \"" + sampler_.type + "\": its pattern is replaced by tdpm's own sampler (same spp)");
    ps.checkAllUsed();
  } else {
    r.spp = 16;  // pbrt's default pixelsamples
  }
  });

  first.run(pixelFilter_, [&] { mapPixelFilter(r, v4Film); });

  // Integrator -> method
  first.run(integrator_, [&] {
  std::string integ = integrator_.given ? integrator_.type : "path";
  const ParamSet& ip = integrator_.params;
  Loc iat = integrator_.given ? integrator_.at : at;
  int maxDepth = integrator_.given ? ip.getInt("maxdepth", 5) : 5;
  if (maxDepth < 1) failAt(iat, "Integrator: maxdepth " + std::to_string(maxDepth) + " (emission only) is not supported; tdpm needs at least 1");
  r.maxDepth = maxDepth;
  auto qualityOnly = [&](std::initializer_list<const char*> names) {
    for (const char* q : names)
      if (ip.has(q)) {
        ip.markUsed(q);
        note(iat, std::string("Integrator: \"") + q + "\" ignored (quality only)");
      }
  };
  if (integ == "path" || integ == "volpath") {
    // tdpm's pathtrace is a volumetric path tracer (delta and ratio
    // tracking, next-event estimation through media, MIS): pbrt's volpath.
    r.method = "pathtrace";
    if (integ == "volpath") note(iat, "Integrator \"volpath\" mapped to pathtrace (tdpm's path tracer traces media)");
    qualityOnly({"regularize", "lightsampler", "rrthreshold"});
  } else if (integ == "directlighting") {
    r.method = "pathtrace";
    r.directOnly = true;
    qualityOnly({"strategy"});
    note(iat, "Integrator \"directlighting\" mapped to pathtrace with render.direct_only: direct light at the first "
              "non-specular surface, through perfect-specular bounces up to maxdepth, as pbrt");
  } else if (integ == "bdpt" || integ == "mlt") {
    // Decided in finish(), once the lights and materials are known.
    r.method = "pathtrace";
    bidirectional_ = true;
    bidirectionalAt_ = iat;
    qualityOnly({"regularize", "lightsampler", "visualizestrategies", "visualizeweights", "bootstrapsamples", "chains",
                 "mutationsperpixel", "largestepprobability", "sigma"});
  } else if (integ == "sppm") {
    // The progressive method does not exist yet: the photon count of all
    // iterations goes into one pass of the time-dependent photon method.
    int iterations = ip.getInt("numiterations", 64);
    int perIteration = ip.getInt("photonsperiteration", -1);
    double radius = ip.getFloat("radius", 1.0);
    if (iterations < 1) failAt(iat, "Integrator \"sppm\": numiterations must be at least 1");
    if (!(radius > 0)) failAt(iat, "Integrator \"sppm\": radius must be positive");
    r.method = "time";
    std::string count;
    if (perIteration > 0) {
      int64_t per = perIteration;
      if (per > kMaxPhotons / iterations)
        failAt(iat, "Integrator \"sppm\": photonsperiteration x numiterations = " + std::to_string(per) + " x " +
                        std::to_string(iterations) + " photons is more than tdpm's limit of " + std::to_string(kMaxPhotons) +
                        " (render.photons)");
      r.photons = per * iterations;
      result.settingSources["photons"] = iat.str() + ": Integrator \"sppm\" (photonsperiteration x numiterations)";
      count = "photons = photonsperiteration x numiterations = " + std::to_string(*r.photons);
    } else {
      // pbrt's -1: one photon per pixel per iteration, of the image rendered
      // (--resolution included), so the count is fixed at render time.
      r.photonsPerPixel = iterations;
      result.settingSources["photons"] = iat.str() + ": Integrator \"sppm\" (photonsperiteration -1: numiterations per pixel)";
      count = "photons = numiterations (" + std::to_string(iterations) + ") x the rendered image's pixels (render.photons_per_pixel)";
    }
    r.maxRadius = float(radius);
    ip.markUsed("seed");
    note(iat, "Integrator \"sppm\" mapped to tdpm's time-dependent photon method with " + count +
              " and max radius = radius (see docs/pbrt-import.md)");
  } else {
    failAt(iat, "Integrator \"" + integ + "\" is not supported (path, volpath, directlighting, bdpt, mlt, sppm)");
  }
  if (integrator_.given) ip.checkAllUsed();
  });
  first.rethrow();

  gs_.ctm[0] = gs_.ctm[1] = Mat();
  coordSystems_["world"] = Mat();
}

// bdpt and mlt find every path pbrt's path tracer finds, and also light
// from delta lights (point, spot, distant) through specular surfaces
// (caustics), which tdpm's path tracer cannot. So: "time" (photon mapping,
// which renders those caustics) when the scene has a delta light and a
// mirror or glass surface, else "pathtrace" (the same image, unbiased).
void Importer::chooseBidirectionalMethod() {
  using LT = scene::LightDesc::Type;
  using MT = scene::MaterialDesc::Type;
  bool deltaLight = false, specular = false;
  for (const auto& l : result.scene.lights) deltaLight |= l.type == LT::Point || l.type == LT::Spot || l.type == LT::Directional;
  for (const auto& o : result.scene.objects) {
    MT t = result.scene.materials.at(o.material).type;
    specular |= t == MT::Mirror || t == MT::Dielectric;
  }
  const std::string integ = "Integrator \"" + integrator_.type + "\"";
  if (deltaLight && specular) {
    result.scene.render.method = "time";
    note(bidirectionalAt_, integ + " mapped to tdpm's time-dependent photon method: the scene has a point, spot or "
                           "distant light and a mirror or glass surface, whose caustics a path tracer cannot find");
  } else {
    result.scene.render.method = "pathtrace";
    note(bidirectionalAt_, integ + " mapped to pathtrace (no delta light reaching a mirror or glass surface: the same image)");
  }
}

void Importer::finish(const std::string& file) {
  if (!sawWorld_) throw Error(file + ": no WorldBegin: not a complete pbrt scene");
  if (currentInstance_) failAt(stack_.empty() ? worldAt_ : stack_.back().at, "ObjectBegin \"" + currentInstanceName_ + "\" without ObjectEnd");
  if (!stack_.empty())
    failAt(stack_.back().at, std::string(stack_.back().attribute ? "AttributeBegin" : "TransformBegin") + " without a matching End");
  if (imagingRatio_ != 1) {
    float k = float(imagingRatio_);
    for (auto& l : result.scene.lights) {
      if (l.type == scene::LightDesc::Type::Environment) l.radiance = l.radiance * k;
      else l.power = l.power * k;
      const Rgb& v = l.type == scene::LightDesc::Type::Environment ? l.radiance : l.power;
      if (!std::isfinite(v.r) || !std::isfinite(v.g) || !std::isfinite(v.b))
        failAt(film_.at, "Film: " + filmFactorWhat_ + " = " + fmtNum(imagingRatio_) + ", which makes " +
                             l.name + " infinitely bright (its " +
                             (l.type == scene::LightDesc::Type::Environment ? "radiance" : "power") + " overflows a float)");
    }
    if (!result.scene.background.isBlack()) result.scene.background = result.scene.background * k;
    if (!std::isfinite(result.scene.background.r) || !std::isfinite(result.scene.background.g) ||
        !std::isfinite(result.scene.background.b))
      failAt(film_.at, "Film: " + filmFactorWhat_ + " = " + fmtNum(imagingRatio_) +
                           ", which makes the background radiance overflow a float");
    result.notes.push_back(film_.at.str() + ": Film: " + filmFactorWhat_ + " = " + fmtNum(imagingRatio_) +
                           "; the import scales every light by it");
  }
  if (bidirectional_) chooseBidirectionalMethod();
  resolveMedia();
  validateAsJson();
}

}  // namespace tdpm::pbrt::detail

namespace tdpm::pbrt {

ImportResult importPbrtText(const std::string& text, const std::string& path, uint64_t maxTriangles) {
  detail::Importer im;
  im.start();
  if (maxTriangles) im.maxTriangles = maxTriangles;
  im.result.scene.sourcePath = path;
  im.mainDir = std::filesystem::path(path).parent_path().string();
  im.parseText(text, path, 0);
  im.finish(path);
  return std::move(im.result);
}

ImportResult importPbrtFile(const std::string& path) {
  detail::Importer im;
  im.start();
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
