// scene/render_method.h — the rendering methods as a type: one enum, the one
// parser of their names (a scene's render.method and --method alike), and
// one table of what each method is. Everything that depends on the method
// asks the table (renderMethodTraits) instead of comparing names, so adding
// a method is one enum value and one row (tests/test_render_method.cpp also
// fails on a method-name string comparison anywhere else in src/).
// In scene/ because the scene parser validates render.method against these
// names; the renderer and the CLI above it use the same table.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tdpm {

enum class RenderMethod : uint8_t { PathTrace, Static, Accumulation, Standard, Time };
inline constexpr int kRenderMethodCount = 5;

// What the default progressive kernel shrink (alpha of render/progressive.h)
// is sized for: the space-time kernel (disc x window, d = 3) or the spatial
// one (disc, d = 2).
enum class KernelShrink : uint8_t { Spatial, SpaceTime };

struct RenderMethodTraits {
  RenderMethod method;
  const char* name;               // as the user writes it
  // Caustic and global photon maps gathered by the PhotonIntegrator (the
  // path tracer traces only its own small caustic guide).
  bool photonMaps;
  // Photons carry times spread over the shutter where the scene moves;
  // false: static traces at shutter open, accumulation at each frame's instant.
  bool spreadsPhotonsInTime;
  // Where the scene moves, the time-dependent estimate (two-pass or 4D
  // search) replaces the standard one.
  bool timeDependentEstimate;
  // Renders N in-between frames at instants, each with 1/N of the photons
  // and samples, and averages them (--frames).
  bool inBetweenFrames;
  bool progressive;               // --progressive passes
  bool animation;                 // an animation's frames
  KernelShrink defaultShrink;     // progressive default alpha
};

// The table row of `m` (every value has one).
const RenderMethodTraits& renderMethodTraits(RenderMethod m);
inline const char* renderMethodName(RenderMethod m) { return renderMethodTraits(m).name; }
// The one parser: a method's name -> its value; nullopt for any other text.
std::optional<RenderMethod> parseRenderMethod(const std::string& name);
// Every name, in table order (for the scene parser's choice).
std::vector<std::string> renderMethodNames();
// "pathtrace | static | accumulation | standard | time" (for --help and errors),
// or with another separator.
std::string renderMethodList(const char* separator = " | ");

}  // namespace tdpm
