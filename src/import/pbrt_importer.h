// import/pbrt_importer.h — internal to the pbrt import: the importer's
// graphics state (CTM pair for motion, attribute stack, named materials,
// textures, coordinate systems and object instances) and the Importer class
// whose statement half lives in pbrt_import.cpp and whose mapping half
// (materials, lights, shapes, motion -> SceneDescription) in pbrt_mapping.cpp.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/memory.h"
#include "import/pbrt_import.h"
#include "import/pbrt_math.h"
#include "import/pbrt_params.h"
#include "import/pbrt_tokenizer.h"
#include "scene/limits.h"

namespace tdpm::pbrt::detail {

constexpr double kPiD = 3.14159265358979323846;

struct Loc {
  std::string file;
  int line = 0;
  std::string str() const { return file + ":" + std::to_string(line); }
};

[[noreturn]] void failAt(const Loc& at, const std::string& what);
std::string fmtNum(double v);
// A relative path is looked up beside the file that names it; if it is not
// there but is beside the main scene file (pbrt's search directory), that
// one is used, so scenes written for pbrt's rule load too.
std::string resolvePath(const std::string& name, const std::string& namingFile, const std::string& mainDir);

struct MaterialSlot {
  bool interface = false;  // "" / "interface" / "none": no surface at all
  scene::MaterialDesc desc;
  int index = -1;  // in scene.materials once a shape uses it
  int mixSlots[2] = {-1, -1};  // mix: its two materials' slots
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
  // pbrt's ReverseOrientation in effect for this shape (as written: an
  // emitter's side and ShapeDesc::reverseOrientation derive from it).
  bool reverseOrientation = false;
  // The MediumInterface in effect ("" = vacuum) and where it was given.
  std::string mediumInside, mediumOutside;
  Loc mediumAt;
};

struct GraphicsState {
  Mat ctm[2];
  unsigned active = 3;  // ActiveTransform: bit 0 StartTime, bit 1 EndTime
  int material = 0;
  std::optional<AreaLight> area;
  bool reverseOrientation = false;  // toggled by ReverseOrientation; restored by AttributeEnd
  // MediumInterface "inside" "outside" (names of MakeNamedMedium, "" =
  // vacuum); restored by AttributeEnd. Resolved at the end of the import
  // (pbrt-v4 allows a medium to be made after it is named).
  std::string mediumInside, mediumOutside;
  Loc mediumAt;
};

struct StackEntry {
  GraphicsState state;
  bool attribute = true;  // AttributeBegin (true) or TransformBegin (false)
  Loc at;
};

// A Texture statement: its node in result.scene.textures, and its value
// when it is a constant (which any parameter may then use).
struct TextureValue {
  bool isFloat = false;
  bool constant = true;
  Rgb value{1, 1, 1};
  int32_t index = -1;
};

struct Statement {  // an options-block statement kept until WorldBegin
  std::string type;
  ParamSet params;
  Loc at;
  bool given = false;
  int64_t seq = 0;  // statement number in reading order (errors are reported in file order)
};

class Cursor;

// Turns a trianglemesh's windings to face its shading normals N, as pbrt
// orients such a triangle (pbrt_mapping.cpp); false when it has no N.
// Swaps the windings of the triangles whose normal disagrees with the sum
// of their corners' shading normals N (per vertex), as pbrt faces them.
void orientToNormals(const std::vector<Vec3f>& N, const std::vector<Vec3f>& verts, std::vector<uint32_t>* indices);
bool facesShadingNormals(const ShapeRecord& rec, const std::vector<Vec3f>& verts, std::vector<uint32_t>* indices);

class Importer {
 public:
  ImportResult result;

  // Reads `path` within the import's budgets (scene/limits.h): a regular
  // file (checked before open: a FIFO would block), at most
  // kMaxPbrtFileBytes, and kMaxPbrtTotalBytes for all files together.
  // `where` is the Include's "file:line: Include: " (empty for the main file).
  void parseFile(const std::string& path, int depth, const std::string& where);
  void parseText(const std::string& text, const std::string& file, int depth);
  void start() { memoryAtStart_ = availableMemoryBytes(); }
  void finish(const std::string& file);
  std::string mainDir;  // pbrt's search directory: the main scene file's
  uint64_t maxTriangles = scene::limits::kMaxPbrtTriangles;

 private:
  // statements
  void statement(Cursor& c, const Token& word, int depth);
  void applyTransform(const Mat& m, bool replace);
  void worldBegin(const Loc& at);
  void shape(const std::string& type, ParamSet params, const Loc& at);
  void lightSource(const std::string& type, const ParamSet& ps, const Loc& at);
  void environmentLight(const ParamSet& ps, const Mat& M, const Loc& at);
  void texture(const std::string& name, const std::string& kind, const std::string& type, const ParamSet& ps, const Loc& at);
  MaterialSlot makeMaterial(const std::string& type, const ParamSet& ps, const Loc& at, const std::string& name);

  // participating media (pbrt_media.cpp)
  void makeNamedMedium(const std::string& name, const ParamSet& ps, const Loc& at);
  void mediumCoefficients(scene::MediumDesc& m, const ParamSet& ps, const std::string& what, bool v3);
  void mediumPlacement(scene::MediumDesc& m, const Loc& at, const std::string& what);
  void mediumGrid(scene::MediumDesc& m, const std::string& type, const ParamSet& ps, const Loc& at, const std::string& what);
  // A name a shape, light or the camera uses, resolved by resolveMedia()
  // once every statement is read (then -1 for "", the index otherwise).
  struct MediumRef {
    enum class Kind { ObjectInside, ObjectOutside, Light, Camera };
    Kind kind;
    size_t index;  // into scene.objects / scene.lights
    std::string name;
    Loc at;        // the MediumInterface (or Camera) statement
    std::string user;  // "Shape \"sphere\" at f:12", for the message
  };
  std::vector<MediumRef> mediumRefs_;
  void objectMedia(const ShapeRecord& rec, size_t object);
  void lightMedium(const std::string& outside, const Loc& at, size_t light, const std::string& user);
  void resolveMedia();
  uint32_t interfaceMaterialIndex();
  std::map<std::string, int> namedMedia_;  // name -> index in scene.media
  std::string cameraMedium_;
  Loc cameraMediumAt_;
  int interfaceMaterial_ = -1;

  // mapping
  void emitShape(const ShapeRecord& rec, const Mat ctm[2], const Loc& instanceAt);
  // Sphere and disk emitters (pbrt_mapping.cpp); the radiance and power
  // shared by every emitter; the light pushed with its material note.
  void emitRoundLight(const ShapeRecord& rec, const Mat ctm[2]);
  Rgb areaLightL(const ShapeRecord& rec, double area, bool twoSided);
  void pushAreaLight(const ShapeRecord& rec, scene::LightDesc l);
  void emitAreaLight(const ShapeRecord& rec, const std::vector<Vec3f>& verts, const std::vector<uint32_t>& idx,
                     const Mat ctm[2]);
  struct MotionPlan {
    bool moving = false;
    Mat still;  // world' (mirrored) placement when not moving
    scene::MotionDesc keys;
  };
  MotionPlan planMotion(const Mat ctm[2], const Loc& at, const std::string& what) const;
  // A texture statement's input parameter `name` (a texture, or a value).
  scene::TexInput texInput(const ParamSet& ps, const std::string& name, bool isFloat, Rgb fallback,
                           const std::string& what) const;
  void imageTexture(scene::TextureDef& t, const ParamSet& ps, const Loc& at, const std::string& what);
  void shadingNormalParams(const ParamSet& ps, const Loc& at, const std::string& label, scene::MaterialDesc& m);
  // A reflectance that may be any spectrum texture: sets *index (a texture
  // that varies; the value returned is then a placeholder) or returns the value.
  Rgb textureParam(const ParamSet& ps, const std::string& name, Rgb fallback, int32_t* index) const;
  // A texture that varies on parameter `name`, of the kind isFloat: its
  // index (the parameter marked used); -1 when the parameter is absent, a
  // value or a constant texture (read as values). `what` names the
  // parameter's use in the error for a texture of the other kind.
  // translucent's Kd or Ks (*value, or *texture when >= 0) times its
  // reflect: the product of two constants, or else a new scale texture node
  // named `name` (then *texture).
  void translucentLobe(const std::string& name, Rgb* value, int32_t* texture, Rgb reflect, int32_t reflectTexture);
  int32_t varyingTexture(const ParamSet& ps, const std::string& name, bool isFloat, const std::string& what) const;
  uint32_t materialIndex(int slot);
  std::string uniqueMaterialName(const std::string& base);
  Rgb color(const ParamSet& ps, const std::string& name, Rgb fallback) const;
  double floatParam(const ParamSet& ps, const std::string& name, double fallback) const;
  // "spectrum" / "blackbody" values reduced to RGB or to one number (an eta)
  // once, at load (pbrt_spectrum.cpp, import/spectrum.h).
  Rgb spectrumColor(const ParamSet& ps, const Param& p) const;
  double spectrumFloat(const ParamSet& ps, const Param& p) const;
  Rgb lightScale(const ParamSet& ps) const;
  void noteLightSamples(const ParamSet& ps, const Loc& at, const std::string& what);
  void note(const Loc& at, const std::string& what);
  void requireWorld(const Loc& at, const std::string& stmt) const;
  void requireOptions(const Loc& at, const std::string& stmt) const;
  void mapPixelFilter(scene::RenderSettings& r, bool v4Film);
  void checkNesting(const Loc& at, const std::string& stmt) const;
  void countTriangles(uint64_t n, const Loc& at, const std::string& what, bool add = true);
  // Camera "perspective" lensradius / focaldistance (pbrt_camera.cpp).
  void readThinLens(const ParamSet& ps);
  // bdpt / mlt: pathtrace or time, by the scene's lights and surfaces (pbrt_import.cpp).
  void chooseBidirectionalMethod();
  bool bidirectional_ = false;
  Loc bidirectionalAt_;

  GraphicsState gs_;
  std::vector<StackEntry> stack_;
  std::vector<MaterialSlot> materials_ = {defaultMaterial()};
  std::map<std::string, int> namedMaterials_;
  std::map<std::string, TextureValue> textures_;
  // Image texels by (path, encoding): each file is read once.
  std::map<std::pair<std::string, std::string>, std::shared_ptr<const image::ImageRgb>> textureImages_;
  std::map<std::string, Mat> coordSystems_;
  std::map<std::string, std::vector<ShapeRecord>> instances_;
  std::vector<ShapeRecord>* currentInstance_ = nullptr;
  std::string currentInstanceName_;
  // "interface" is the JSON's reserved name of the no-surface material
  // (interfaceMaterialIndex); a pbrt material of that name becomes "interface#2".
  std::set<std::string> materialNames_ = {"interface"};
  std::set<std::string> notedKinds_;

  // budgets (scene/limits.h)
  uint64_t bytesRead_ = 0;
  int includes_ = 0;
  uint64_t triangles_ = 0;
  int64_t statementCount_ = 0;
  uint64_t memoryAtStart_ = 0;  // MemAvailable when the import began (0: unknown)
  std::map<std::string, uint64_t> instanceTriangles_;  // per object, once instanced
  std::vector<std::map<std::string, uint64_t>> pendingInstances_;  // per file being read: ObjectInstance statements to come

  // Where each scene.objects[i] / scene.lights[i] / the background came
  // from, to name the pbrt statement when the JSON checks refuse it.
  std::vector<Loc> objectAt_, lightAt_;
  Loc backgroundAt_;
  void validateAsJson();
  Loc locateJsonPath(const std::string& path) const;

  bool inWorld_ = false, sawWorld_ = false, worldEnded_ = false;
  float transformStart_ = 0, transformEnd_ = 1;
  Statement camera_, film_, sampler_, integrator_, pixelFilter_;
  Mat cameraCtm_[2];
  bool mirror_ = true;
  float shutterOpen_ = 0, shutterClose_ = 1;
  double lensRadius_ = 0, focalDistance_ = 1e6;  // camera space; pbrt's defaults
  double imagingRatio_ = 1;  // pbrt-v4 film: exposure time * ISO / 100; pbrt-v3 image film: "scale"
  std::string filmFactorWhat_ = "pbrt-v4 scales the image by exposure time x ISO / 100";
  // pbrt-v3 syntax (Film "image"): notes about pbrt-v4-only behaviour are left out.
  bool pbrtV3() const { return film_.given && film_.type == "image"; }
  Loc worldAt_;

  static MaterialSlot defaultMaterial() {
    MaterialSlot s;  // pbrt's default: diffuse, reflectance 0.5
    s.desc.type = scene::MaterialDesc::Type::Diffuse;
    s.desc.albedo.color = Rgb(0.5f);
    s.desc.name = "default";
    return s;
  }
};

}  // namespace tdpm::pbrt::detail
