// scene/description.h — the scene as plain, validated data.
// scene/parse.cpp fills it from a JSON file (every value checked, errors
// located); scene/build.cpp turns it into Embree geometry, lights, materials
// and a camera. Nothing here knows JSON or Embree. Units: metres, seconds,
// watts; angles in degrees as written in the file, converted where used.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "image/texture_image.h"
#include "math/bounds.h"
#include "math/transform.h"
#include "math/vec.h"

namespace tdpm::scene {

// Placement: world = T * R * S (scale, then rotate, then translate).
struct TransformDesc {
  Vec3f translate{0, 0, 0};
  Quaternion rotate{};  // from {"axis": [x,y,z], "angle": degrees}
  Vec3f scale{1, 1, 1};
  Affine3f matrix() const { return Affine3f::fromTRS(translate, rotate, scale); }
};

// Keyframed motion: times strictly increasing, inside the shutter, two or
// more. Between keyframes translation and scale are linear and rotation is
// slerp; before the first / after the last the end pose holds. The motion is
// combined with the static placement P by parts (motion/motion.h):
//   world(t) = Translate(P.t + k.t(t)) * Rotate(k.r(t) * P.r) * Scale(k.s(t) * P.s)
// so keyframe rotations and scales act about the object's placed centre.
struct MotionDesc {
  std::vector<float> times;
  std::vector<TransformDesc> poses;
  bool empty() const { return times.empty(); }
};

struct TextureDesc {
  enum class Kind { Constant, Checker };
  Kind kind = Kind::Constant;
  Rgb color{0.8f, 0.8f, 0.8f};   // constant colour, or checker colour A
  Rgb color2{0.2f, 0.2f, 0.2f};  // checker colour B
  float scale = 1.0f;            // checker cell size in object space (m)
};

// A texture's input: another texture (an index into
// SceneDescription::textures, always lower than the user's own) or, when
// texture < 0, the constant value.
struct TexInput {
  int32_t texture = -1;
  Rgb value{1, 1, 1};
};

// A named texture ("textures" in the JSON, pbrt's Texture statement).
// Evaluated at a hit's (u, v) (scene/texture.h); every kind gives RGB, a
// float texture R = G = B.
struct TextureDef {
  enum class Kind { Constant, Image, Scale, Mix, Checkerboard, Checker3D };
  enum class Wrap { Repeat, Clamp, Black };
  enum class Filter { Bilinear, Point };
  std::string name;
  Kind kind = Kind::Constant;
  bool isFloat = false;  // a float texture: an image gives its first channel
  // constant: a.value; scale: a x b; mix: (1 - amount) a + amount b (amount a
  // float); checkerboard (2D in (s, t)) and checker3d (object space): a on
  // even cells, b on odd ones.
  TexInput a, b, amount;
  // (s, t) = (uscale u + udelta, vscale v + vdelta): image, checkerboard.
  float uscale = 1, vscale = 1, udelta = 0, vdelta = 0;
  // image: the file (resolved against the scene's folder), its 8-bit
  // encoding, lookups, and v = scale x texel, then 1 - v clamped at 0 when
  // inverted (pbrt-v4's order). Texels are read by the parser / importer,
  // once per (file, encoding) however many textures use them.
  std::string file;
  image::TexelEncoding encoding;
  Wrap wrap = Wrap::Repeat;
  Filter filter = Filter::Bilinear;
  float scale = 1;
  bool invert = false;
  std::shared_ptr<const image::ImageRgb> image;
  float cell = 1;  // checker3d: cell size (m), cells centred as the inline "checker"
};

// ---- participating media (docs/scene-format.md "media"; issue 25) ----
// A named medium. Coefficients are per scene unit (1/m): sigma = scale x
// sigma_{a,s} (homogeneous) or scale x sigma_{a,s} x density(x) (grid).
// JSON: "media": {"fog": {"type": "homogeneous", "sigma_a": [r,g,b],
// "sigma_s": [r,g,b], "scale": 1, "g": 0}, "smoke": {"type": "grid", ...,
// "resolution": [nx, ny, nz], "density": [nx*ny*nz numbers, x fastest],
// (or "file": "smoke.vdb", "grid": "density"), "bounds": [[x0,y0,z0],
// [x1,y1,z1]], "transform": {...}}}.
struct DensityGridDesc {
  // Density at cell centres, x fastest then y then z, every value >= 0 and
  // finite; interpolated trilinearly (pbrt's uniformgrid / nanovdb media),
  // zero outside `bounds`.
  int nx = 0, ny = 0, nz = 0;
  std::vector<float> density;
  Bounds3f bounds{{0, 0, 0}, {1, 1, 1}};  // medium space: the box the cells tile
  std::string file;          // as resolved against the scene's directory; empty: inline
  std::string gridName = "density";  // the grid read from `file` (OpenVDB / NanoVDB)
};

struct MediumDesc {
  enum class Type { Homogeneous, Grid };
  Type type = Type::Homogeneous;
  std::string name;
  Rgb sigmaA{0, 0, 0}, sigmaS{0, 0, 0};  // >= 0 each, per scene unit
  float scale = 1.0f;                    // >= 0
  float g = 0.0f;                        // Henyey-Greenstein asymmetry, in (-1, 1)
  DensityGridDesc grid;                  // Type::Grid
  // Grid: medium-to-world (or medium-to-object for a medium inside an
  // object, which then moves with the object); homogeneous media ignore it.
  TransformDesc placement;
};

// Which media meet at a surface (pbrt's MediumInterface): the medium on the
// side the normal points into (outside) and on the other (inside). Index
// into SceneDescription::media, or -1 for vacuum. An object without one
// (present == false) is no medium boundary: a ray keeps its medium across it.
struct MediumInterfaceDesc {
  bool present = false;
  int32_t inside = -1, outside = -1;
};

struct MaterialDesc {
  // Conductor .. Mix: pbrt's materials (scene/material.h, docs/scene-format.md).
  // Interface: no surface at all (pbrt's "interface"), only a boundary
  // between media (issue 25: media/, JSON "material": "interface").
  enum class Type { Diffuse, Mirror, Dielectric, Metal, Plastic,
                    Conductor, RoughDielectric, Uber, Substrate, CoatedDiffuse, CoatedConductor, Mix, Interface };
  Type type = Type::Diffuse;
  std::string name;
  TextureDesc albedo;          // diffuse: reflectance; plastic, uber, substrate, coateddiffuse: base colour
  Rgb specular{1, 1, 1};       // mirror/metal: reflectance; dielectric: tint; uber, substrate: Ks
  float ior = 1.5f;            // dielectric and plastic coating, >= 1; uber's Fresnel, coatings
  float roughness = 0.2f;      // metal, plastic: GGX alpha in (0, 1]; the new types: in [0, 1] (0 = smooth)
  Rgb eta{1, 1, 1}, k{0, 0, 0};  // conductor, coated conductor's base: complex IOR (absolute)
  float baseRoughness = 0.0f;  // coated conductor: the conductor's GGX alpha in [0, 1]
  float thickness = 0.01f;     // coated: the layer's thickness (pbrt-v4's units: optical depth)
  int32_t thicknessTexture = -1;  // coated: a float texture for thickness when >= 0 (values >= 0)
  // Diffuse: Oren-Nayar roughness sigma in degrees, [0, 90] (pbrt-v3's
  // matte; 0 is Lambert), or a float texture for it when sigmaTexture >= 0.
  float sigma = 0.0f;
  int32_t sigmaTexture = -1;
  uint32_t mix[2] = {0, 0};    // mix: indices into SceneDescription::materials
  float amount = 0.5f;         // mix: probability of mix[1], in [0, 1]
  // Mix, per channel (pbrt-v3's Spectrum amount; JSON "amount": [r, g, b] or
  // a spectrum texture): f = (1 - a) f(mix[0]) + a f(mix[1]) in each channel,
  // a = amountRgb or, when amountTexture >= 0, that spectrum texture.
  bool amountPerChannel = false;
  Rgb amountRgb{0.5f, 0.5f, 0.5f};
  // Diffuse / plastic: a named texture (index into SceneDescription::
  // textures, a spectrum one) that replaces albedo when >= 0.
  int32_t albedoTexture = -1;
  // Mirror, metal, dielectric (and pbrt's glass): a spectrum texture for
  // `specular` when >= 0; conductor, coated conductor: its reflectance (the "color" form);
  // uber, substrate: Ks.
  int32_t specularTexture = -1;
  // Every material with a roughness: a float texture (index into
  // SceneDescription::textures) for `roughness` when >= 0, remapped per hit
  // (pbrt's remaproughness: none, pbrt-v3's polynomial, pbrt-v4's sqrt).
  int32_t roughnessTexture = -1;
  int32_t baseRoughnessTexture = -1;  // coated conductor: a float texture for baseRoughness, same remap
  // Conductor, coated conductor: spectrum textures for eta / k (absolute
  // indices, as the constants) when >= 0; either may be textured alone.
  int32_t etaTexture = -1, kTexture = -1;
  int32_t amountTexture = -1;  // mix: a float texture for amount when >= 0
  int32_t iorTexture = -1;     // dielectric (rough or not), uber: a float texture for ior when >= 0
  enum class Remap { None, PbrtV3, PbrtV4 };
  Remap roughnessRemap = Remap::None;
  // Any material but mix and interface: a float texture (index into
  // SceneDescription::textures) displacing the surface by bumpScale x its
  // value when >= 0 (JSON "bump"), and / or a tangent-space normal map read
  // as linear RGB (JSON "normal_map"; pbrt-v4's normalmap wins over a bump).
  int32_t bumpTexture = -1;
  float bumpScale = 1.0f;
  std::string normalMapFile;
  std::shared_ptr<const image::ImageRgb> normalMap;
};

struct ShapeDesc {
  enum class Type { Sphere, Quad, Box, Mesh, Disk, Cylinder };
  Type type = Type::Sphere;
  float radius = 1.0f;         // sphere, centred at the local origin; disk, cylinder
  // Disk (z = height, innerRadius <= r <= radius) and cylinder (r = radius,
  // zMin <= z <= zMax) in pbrt's frame, cut to phi in [0, phiMax] (degrees,
  // (0, 360]); scene/quadric.h.
  float innerRadius = 0.0f;
  float height = 0.0f;
  float zMin = -1.0f, zMax = 1.0f;
  float phiMax = 360.0f;
  // Flip the surface's normal (pbrt's ReverseOrientation): which side is
  // outside for glass, and the emitting side of an emitter. Without it the
  // normal is the shape's own (sphere, cylinder: outward; disk: +z; quad:
  // +y; box: outward; mesh: (p1 - p0) x (p2 - p0)), transformed as a normal.
  bool reverseOrientation = false;
  Vec3f size{1, 1, 1};         // quad: size.x by size.z in the local x-z plane,
                               // normal +y; box: full extents, centred
  std::string meshFile;        // mesh: path as resolved against the scene dir
  // Mesh: triangles loaded from meshFile (object space).
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle
  // Mesh: Loop subdivision levels (scene/subdivision.h), -1 for none. The
  // vertices and indices above stay the control mesh; scene/build.cpp refines.
  int loopLevels = -1;
  // Mesh: (u, v) per triangle corner (3 per triangle, as indices), or empty:
  // each triangle gets pbrt's default (0,0), (1,0), (1,1).
  std::vector<Vec2f> uvs;
  // Mesh: shading normals per triangle corner (3 per triangle, as uvs; OBJ
  // vn, pbrt "N", PLY nx/ny/nz), object space as given (not normalised:
  // pbrt interpolates them as they are), or empty: the geometric normal.
  std::vector<Vec3f> normals;
};

struct ObjectDesc {
  std::string name;
  ShapeDesc shape;
  uint32_t material = 0;  // index into SceneDescription::materials
  TransformDesc placement;
  MotionDesc motion;
  // Media on its two sides. JSON "medium": "fog" (a closed shape's interior;
  // outside = the scene's exterior medium) or "medium_interface": {"inside":
  // name | null, "outside": name | null} (any shape, as pbrt).
  MediumInterfaceDesc media;
};

struct LightDesc {
  enum class Type { Point, Spot, Directional, Area, Environment };
  Type type = Type::Point;
  std::string name;
  // Point, spot, area: total emitted power (W) per channel.
  // Directional: irradiance (W/m^2) on a surface facing the light; see
  // docs/scene-format.md for why a sun has no finite power.
  Rgb power{100, 100, 100};
  Vec3f position{0, 0, 0};     // point, spot
  Vec3f direction{0, -1, 0};   // spot axis, directional travel direction (normalised)
  float coneAngle = 30.0f;     // spot: total half-angle (degrees), (0, 90]
  float falloffStart = 25.0f;  // spot: half-angle where falloff begins, <= coneAngle
  // Area lights of every shape are Type::Area; JSON names them "area"
  // (rectangle), "sphere", "disk" and "mesh".
  enum class AreaShape { Rect, Sphere, Disk, Mesh };
  AreaShape areaShape = AreaShape::Rect;
  Vec2f areaSize{1, 1};        // area rect: in the local x-z plane, emits toward local -y
  float radius = 1.0f;         // sphere (emits outward), disk (local x-z plane, emits toward -y)
  ShapeDesc mesh;              // mesh: file, vertices, indices, loopLevels (type Mesh); ccw side emits
  bool twoSided = false;       // area: both sides emit, power split equally
  bool reverseOrientation = false;  // area: the other side emits (sphere: inward)
  TransformDesc placement;     // area: its placement; environment: light-to-world
                               // (translation ignored); others: identity unless given
  MotionDesc motion;           // any light but an environment may move
  // Environment: radiance = scale x radiance x the map's texel (1 without a map).
  Rgb radiance{1, 1, 1};
  float scale = 1.0f;
  std::string mapFile;         // as resolved against the scene's directory; empty: constant
  bool equalArea = false;      // mapFile is pbrt-v4's square equal-area map (else lat-long)
  // The map's texels as lat-long (converted when equalArea), read and
  // checked by the parser (or the pbrt importer).
  std::shared_ptr<const image::ImageRgb> map;
  // The medium the light emits into (photons start in it): index into
  // SceneDescription::media, -1 vacuum; JSON "medium", default the exterior.
  int32_t medium = -1;
};

struct CameraKeyframe {
  float time = 0;
  Vec3f position{0, 0, 0};
  Vec3f target{0, 0, -1};
  Vec3f up{0, 1, 0};
};

struct CameraDesc {
  Vec3f position{0, 0, 5};
  Vec3f target{0, 0, 0};
  Vec3f up{0, 1, 0};
  float fovDegrees = 45.0f;       // vertical field of view, (0, 180)
  int width = 640, height = 480;  // >= 1 each
  float shutterOpen = 0.0f, shutterClose = 1.0f;  // close >= open
  std::vector<CameraKeyframe> motion;  // empty: static; else >= 2, times increasing, inside the shutter
  // Thin lens (depth of field): lens radius in metres (0: pinhole) and the
  // distance along the view direction of the plane in focus (> 0).
  float lensRadius = 0.0f;
  float focalDistance = 1.0f;
  // The medium the camera sits in: index into SceneDescription::media, -1
  // vacuum; JSON camera "medium", default the exterior medium.
  int32_t medium = -1;
};

// Render settings stored in the scene. Each is optional: command-line flags
// override them, and what neither gives takes the renderer's default
// (render/renderer.h, RenderOptions), so every default lives in one place.
struct RenderSettings {
  std::optional<std::string> method;  // pathtrace | static | accumulation | standard | time
  std::optional<int> spp;             // first (and per-batch) samples per pixel, >= 1
  std::optional<int> maxSpp;          // adaptive maximum, >= 1
  std::optional<float> contrast;      // adaptive threshold, > 0
  std::optional<uint64_t> seed;
  std::optional<std::string> sampler; // random | sobol
  std::optional<std::string> filter;  // box | gaussian
  std::optional<float> filterRadius;  // pixels, (0, 16]
  std::optional<int> maxDepth;        // path vertices, >= 1
  std::optional<bool> directOnly;     // pathtrace: direct light only (RenderOptions::directOnly)
  std::optional<float> exposure;      // PNG preview: stops
  // photon methods
  std::optional<int64_t> photons;         // caustic photons stored, >= 0
  // Caustic photons per pixel of the rendered image (pbrt's sppm
  // photonsperiteration -1): photons = this x width x height, the
  // resolution after --resolution. Not with `photons`.
  std::optional<int64_t> photonsPerPixel;
  std::optional<int64_t> globalPhotons;   // global photons stored, >= 0
  std::optional<int64_t> volumePhotons;   // volume photons stored (scenes with media), >= 0
  std::optional<int> frames;              // accumulation, >= 1
  std::optional<std::string> search;      // twopass | 4d
  std::optional<int> k;                   // photons in the spatial search, >= 1
  std::optional<float> fraction;          // two-pass: part kept in time, (0, 1]
  std::optional<float> kappa;             // 4D metric weight, > 0
  std::optional<float> maxRadius;         // > 0, scene units
  std::optional<float> maxDt;             // > 0, seconds
  std::optional<std::string> kernelSpace; // uniform | cone | epanechnikov
  std::optional<std::string> kernelTime;  // uniform | epanechnikov
  std::optional<int> gather;              // final-gather rays per sample, >= 0
  // progressive passes (render/progressive.h)
  std::optional<bool> progressive;
  std::optional<int> passes;              // >= 1
  std::optional<float> timeLimit;         // seconds, > 0
};

// An animation (docs/scene-format.md, "animation"): frame i exposes
// [i / fps, i / fps + (shutterAngle / 360) / fps] seconds; every keyframe
// time lies in [0, frames / fps], which is then the camera's shutter (the
// whole timeline, so the scene is built once for every frame).
struct AnimationDesc {
  double fps = 24;             // > 0
  int frames = 1;              // >= 1
  double shutterAngle = 180;   // degrees, (0, 360]
  double duration() const { return double(frames) / fps; }
  double frameOpen(int i) const { return double(i) / fps; }
  double frameClose(int i) const { return frameOpen(i) + (shutterAngle / 360.0) / fps; }
  double shutterLength() const { return (shutterAngle / 360.0) / fps; }
};

struct SceneDescription {
  std::string sourcePath;  // the JSON file, as given
  std::optional<AnimationDesc> animation;  // absent: one frame, camera.shutter
  CameraDesc camera;
  std::vector<TextureDef> textures;  // inputs before the textures that use them
  std::vector<MaterialDesc> materials;
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  std::vector<MediumDesc> media;
  // The medium everywhere outside every object's interior (JSON
  // "exterior_medium": a name): index into media, -1 vacuum.
  int32_t exteriorMedium = -1;
  Rgb background{0, 0, 0};  // radiance of rays that escape
  RenderSettings render;
};

}  // namespace tdpm::scene
