// render/progressive_io.h — a ProgressiveState (render/progressive_state.h)
// inside an EXR file (image/exr.h ExrFile), and back, exactly.
// Here and not in image/: image/ depends only on core and math, and the
// state is the renderer's; this file is the one place that knows how the
// state is laid out in the file (docs/progressive.md "What the EXR holds").
//
// Layout (written next to the image's own R, G, B, "spp", "variance.*"):
//  * every state layer L as a FLOAT channel "progressive.L" (floats are
//    stored as they are: bit-exact, NaN payloads and -0 included);
//  * string attributes under "tdpm/progressive/":
//      version      "1" (the layout; a reader refuses another)
//      passes       passes done, decimal
//      fingerprint  the render's fingerprint (render/fingerprint.h)
//      layers       the layer names, comma-separated (so a missing one is an error)
//      setting/NAME the fingerprinted options, as text
//      scalar/NAME  the exact scalars, as "%.17g" (reads back to the same double),
//                   named by progressiveScalars below (the one table)
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/exr.h"
#include "render/progressive_state.h"

namespace tdpm {

// Prefixes of the state's attribute and channel names.
inline constexpr const char* kProgressiveAttributePrefix = "tdpm/progressive/";
inline constexpr const char* kProgressiveLayerPrefix = "progressive.";

// The state's scalars with their names on disk (after "tdpm/progressive/
// scalar/"): the one mapping from the typed state to the file's names, in
// a fixed order. Per map kind (render/map_kinds.h name):
//   Paths   photons.<kind>_paths_per_pass
//   Kernel  kernel.<kind>.radius_1, kernel.<kind>.half_window_1, kernel.<kind>.spatial_radius_1
// and once: Total photons.emitted, photons.stored, seconds; Report
// kernel.radius, kernel.spatial_radius, kernel.half_window. A state whose
// pilot is done has every one; one whose pilot is not has none.
enum class ProgressiveScalarRole { Paths, Kernel, Total, Report };
struct ProgressiveScalar {
  std::string name;
  ProgressiveScalarRole role;
  MapKind kind;  // Paths and Kernel only
  const double* value;
};
// A kind that is part of a render only when asked (the volume map,
// render/map_kinds.h onlyWhenAsked) has its scalars only in a state whose
// settings name its count ("volume_photons": a scene with media), so a
// state without media keeps the scalars it had before; allKinds lists
// every kind's (the reader's table, before it has read the settings).
std::vector<ProgressiveScalar> progressiveScalars(const ProgressiveState& state, bool allKinds = false);

// Adds `state` to `exr` (channels and attributes as above), replacing any
// state already there. Every layer must have exr.color's pixel count, and
// layer names must be non-empty and free of commas: a bug otherwise
// (TDPM_ASSERT).
void addProgressiveState(const ProgressiveState& state, image::ExrFile& exr);
// The same, moving the layers into `exr` instead of copying them (the
// write path of a large render holds no second copy); `state` keeps its
// scalars, settings and fingerprint, its layers are left empty.
void addProgressiveState(ProgressiveState&& state, image::ExrFile& exr);

// "damaged progressive state: <path>: <what>": a file's state that cannot
// be what a render wrote (here and render/progressive_check.h).
struct DamagedStateError : Error {
  DamagedStateError(const std::string& path, const std::string& what);
};

// The state in `exr`, read from the file `path` (for messages); nullopt
// when the file carries none (no "tdpm/progressive/version" attribute).
// Another layout version throws tdpm::Error "<path>: ...". A state that is
// there but damaged (an attribute that does not parse, a listed layer
// missing or unlisted, a scalar that is not one of progressiveScalars or
// missing while others are there, a layer stored as HALF or UINT, a lossy compression
// such as DWAA, DWAB, B44 or PXR24) throws DamagedStateError naming the
// attribute or layer. Whether the values fit together and fit the render
// is checkProgressiveState's (render/progressive_check.h).
std::optional<ProgressiveState> progressiveStateOf(const image::ExrFile& exr, const std::string& path);

// "%.17g": the shortest printf format that reads back (strtod) to the same
// double for every finite value; "inf", "-inf" and "nan" for the others.
std::string exactDoubleText(double v);
// The inverse; false when `text` is not a whole number in that form.
bool parseExactDouble(const std::string& text, double& v);

}  // namespace tdpm
