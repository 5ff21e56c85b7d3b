// scene/limits.h — owns the input limits of tdpm: what a scene file, a mesh
// file and the render command's flags may ask for. One table, read by the
// scene parser (scene/parse.cpp) and by the command line
// (cli/render_command.cpp), so that a flag and its scene key cannot drift
// apart. docs/scene-format.md ("Limits") is the user-facing version.
#pragma once
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace tdpm::scene::limits {

// ---- files
// A scene file larger than this is refused before it is read. nlohmann-json
// needs ~25 bytes of memory per byte of dense JSON (a 200 MB scene took
// 5.2 GB and 48 s before its first error), and a real scene is a few KB:
// meshes live in their own files.
constexpr uint64_t kMaxSceneFileBytes = uint64_t(16) << 20;  // 16 MiB
// A mesh file larger than this is refused before it is read (an OBJ line
// costs ~30-60 bytes per vertex/face; 1 GiB is ~20M triangles).
constexpr uint64_t kMaxMeshFileBytes = uint64_t(1) << 30;  // 1 GiB
// Most triangles one subdivided mesh may refine to (4^levels x its
// triangles): about what the largest mesh file holds, so that a small file
// asking for many levels cannot ask for more memory than a large one.
constexpr uint64_t kMaxSubdividedTriangles = uint64_t(1) << 24;
// A medium's dense density grid (4 bytes per cell, inline or from a file)
// larger than this is refused before it is allocated (also above half of
// MemAvailable; scene/parse_media.cpp): 4 GiB is a 1024^3 grid.
constexpr uint64_t kMaxDensityGridBytes = uint64_t(4) << 30;
// Textures whose inputs are textures: how deep the chain may go (the
// renderer evaluates it recursively, once per shaded hit).
constexpr size_t kMaxTextureDepth = 64;
// Deepest nesting of arrays/objects in a scene file. The deepest valid key
// path is 6 levels (objects[i].motion[j].rotate.axis[k]); checked before
// nlohmann-json parses, since nlohmann's parser recurses.
constexpr int kMaxJsonDepth = 64;

// ---- pbrt import (import/pbrt_*.cpp): the same kind of budgets as the
// JSON side, each checked before the work it bounds (docs/pbrt-import.md).
// One .pbrt file, refused by its size before it is read. Unlike JSON, a
// pbrt file may carry its meshes inline, so the bound is larger; the
// tokenizer holds ~56 bytes per token (sizeof(pbrt::Token)), about 8x the
// text for numbers written with 6 digits.
constexpr uint64_t kMaxPbrtFileBytes = uint64_t(256) << 20;  // 256 MiB
// All files of one scene together (the main file and every Include/Import,
// counted each time it is read): 26 files each including the next twice
// would otherwise read 2^25 files.
constexpr uint64_t kMaxPbrtTotalBytes = uint64_t(512) << 20;  // 512 MiB
// Include/Import statements executed while reading one scene.
constexpr int kMaxPbrtIncludes = 4096;
// AttributeBegin/TransformBegin/ObjectBegin open at once (each level keeps
// a copy of the graphics state; real scenes nest a few dozen deep).
constexpr int kMaxPbrtNesting = 1024;
// Triangles in the imported scene, counted with every ObjectInstance before
// its copy is made (100k instances of a 10k-triangle object would be 1e9).
// A triangle costs ~170 bytes from import to the built BVH (measured: 1000
// instances of a 9800-triangle object, `tdpm render -m pathtrace --spp 1
// --resolution 4x3`, peak RSS 1.66 GB against 15 MB for one instance); the
// import also refuses a scene whose triangles would not fit in the memory
// available when it began.
constexpr uint64_t kMaxPbrtTriangles = uint64_t(1) << 27;  // 134M
constexpr uint64_t kPbrtBytesPerTriangle = 170;

// ---- coordinates
// Largest absolute coordinate (metres) of anything the ray tracer sees:
// every object's vertices or sphere bounds, in object space and in world
// space over the whole shutter, lights and camera (position and target).
// Measured: a floor quad + sphere + point light + camera scene scaled by s
// (power by s^2) renders the same pathtrace/time image as at s = 1 up to
// s = 2e8 (coordinates up to 1e9) and aborts in Embree ('ray.valid()') from
// s = 5e8 on: a face normal is computed as |cross(b - a, c - a)| in float,
// which overflows at edge lengths near 4e9 (it grows as length^4). With
// every coordinate within 1e9, an edge component is at most 2e9, a cross
// component at most 8e18 and the squared length at most 1.9e38 < FLT_MAX.
constexpr float kMaxCoordinate = 1e9f;
// Scale factors (placement times keyframe scale, per axis): a transform's
// determinant (sx sy sz) and its inverse must be finite, non-zero floats
// (1e12^3 = 1e36 < FLT_MAX, 1e-12^3 = 1e-36 > FLT_MIN).
constexpr float kMinScale = 1e-12f;
constexpr float kMaxScale = 1e12f;

// Consecutive keyframes at least this fraction of the shutter apart: the
// step count divides a pair's rotation angle by its share of the shutter
// and must fit an int (motion/motion.cpp); 1e-6 leaves a factor 40 margin.
constexpr float kMinKeyframeGap = 1e-6f;

// ---- render settings: the flag and the scene key share one range
constexpr int kMaxResolution = 65536;  // pixels per side: camera.resolution and --resolution
struct IntRange {
  int64_t lo, hi;
};
constexpr IntRange kSpp{1, int64_t(1) << 20};
constexpr IntRange kMaxDepth{1, 1024};
constexpr IntRange kFrames{1, 4096};
constexpr IntRange kPasses{1, int64_t(1) << 24};  // progressive passes
constexpr IntRange kK{1, 4096};
// --volume-k: at least 2 (the k-th closes the disc; the time window needs
// neighbours strictly inside it).
constexpr IntRange kVolumeK{2, 4096};
constexpr IntRange kGather{0, 1024};
// 2^31 photons at 20 bytes is 40 GiB: more is certainly a typo.
constexpr IntRange kPhotons{0, int64_t(1) << 31};

struct FloatRange {
  float lo, hi;
};
constexpr FloatRange kFraction{1e-6f, 1.0f};
constexpr FloatRange kExposure{-64.0f, 64.0f};
// The estimators square it in float: r^2 must be a normal, finite float.
constexpr FloatRange kMaxRadius{1.1e-19f, 1.8e19f};
// Pixel filter radius in pixels (sampling/filter.h): a wider filter is a blur, not a filter.
constexpr FloatRange kFilterRadius{0.01f, 16.0f};
constexpr FloatRange kKernelFootprint{0.0f, 1000.0f};  // --kernel-footprint
constexpr FloatRange kAlpha{1e-3f, 0.999f};           // --alpha (progressive kernel shrink)
constexpr FloatRange kTimeLimit{1e-12f, 1e9f};        // --time-limit, render.time_limit (seconds)
constexpr FloatRange kCausticGuiding{0.0f, 0.95f};    // --caustic-guiding (the BSDF keeps at least 5%)

// ---- the 4D metric d^2 = |dx|^2 + kappa dt^2
// The 4D kd-tree keys time as sqrt(kappa) t in float and resolves it to one
// of photon::kTimeBins bins (photon/store.h; cli/render_command.cpp checks
// the two agree). kappa is usable when the squared time distance of one bin
// is a normal float (not flushed to zero, which loses time altogether) and
// that of the whole shutter stays far from overflow (headroom for the sum
// with |dx|^2). The usable kappa for a shutter of `length` seconds is
// [lo, hi]; a zero-length shutter has no time to weigh (any kappa > 0).
constexpr int kTimeBins = 256;
struct KappaRange {
  double lo, hi;
};
inline KappaRange kappaRange(double shutterLength) {
  const double floatMin = 1.17549435e-38, floatMax = 3.40282347e+38;
  if (!(shutterLength > 0)) return {0.0, floatMax};
  double bin = shutterLength / kTimeBins;
  return {floatMin / (bin * bin), floatMax / 4 / (shutterLength * shutterLength)};
}

// The text of a range's end point for messages, help and docs: the shortest
// "%.Ng" (N >= 3) that the range itself accepts when typed back, so that a
// message never names a bound that is refused (kappa's lower bound for 1 s
// is 7.7037e-34: "7.7e-34" is below it, so it reads "7.704e-34"). `asFloat`:
// the check rounds the typed value to float first, as flags and scene keys
// stored in float do (1e-3f is 0.0010000000475: "0.001" must be accepted).
inline std::string boundText(double bound, bool lower, bool asFloat) {
  char buf[40] = "";
  for (int digits = 3; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, bound);
    double typed = std::strtod(buf, nullptr);
    if (asFloat) typed = double(float(typed));
    if (lower ? typed >= bound : typed <= bound) break;
  }
  return buf;
}
inline std::string rangeText(FloatRange r) { return boundText(r.lo, true, true) + " to " + boundText(r.hi, false, true); }

}  // namespace tdpm::scene::limits
