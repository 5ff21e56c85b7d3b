// render/render_options.h — what a render is asked for (RenderOptions: flags
// and a scene's render block merged, cli/render_command.cpp) and what it
// reports back (RenderStats). Its own header so that the code that only
// builds or reads options (the CLI's flag merging, the fingerprint, the
// memory budget) need not include the renderer.
#pragma once
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "estimate/estimators.h"
#include "render/map_kinds.h"
#include "sampling/filter.h"
#include "sampling/sampler.h"
#include "scene/render_method.h"

namespace tdpm {

struct RenderOptions {
  RenderMethod method = RenderMethod::Time;  // what each method is: scene/render_method.h
  // Adaptive sampling: every pixel takes `spp` samples, then further
  // batches of `spp` while the relative error of its mean luminance (judged
  // from two interleaved half-buffers over its 3x3 neighbourhood, at least
  // 64 samples, see renderer.cpp) exceeds `contrast` x sqrt(n / 64) after
  // n samples, up to maxSpp.
  // maxSpp <= spp: exactly spp samples everywhere.
  int spp = 16;
  int maxSpp = 0;
  float contrast = 0.05f;
  uint64_t seed = 1;
  SamplerKind sampler = SamplerKind::Sobol;  // sampling/sampler.h
  FilterKind filter = FilterKind::Box;       // sampling/filter.h
  float filterRadius = 0.0f;                 // pixels; 0: the kind's default
  int maxDepth = 16;
  // Path tracing only: direct light only, as pbrt's "directlighting"
  // integrator. A path stops after its first non-delta vertex (next-event
  // estimation there, and its BSDF-sampled ray traced for the emission it
  // meets, the MIS pair); delta (mirror, glass) vertices before it still
  // scatter, up to maxDepth vertices in all.
  bool directOnly = false;
  // Path tracing: the share (at most) of the first two diffuse vertices'
  // continuation samples aimed where caustic photons came from
  // (render/caustic_guide.h; 0 samples the BSDF alone), and the photons
  // that guide is built from
  // (0: one per 100 camera samples, 20k to 200k).
  float causticGuiding = 0.5f;
  size_t guidePhotons = 0;

  // ---- photon methods ----
  // Stored photons wanted per map (the kinds' table, render/map_kinds.cpp,
  // points at these and at their sources below).
  size_t causticPhotons = 200000;
  size_t globalPhotons = 50000;
  // Volume photons (scattering events in media): 0, no volume map, unless
  // the scene has media (cli/render_command.cpp then defaults it to
  // kDefaultVolumePhotons; --volume-photons, render.volume_photons).
  size_t volumePhotons = 0;
  static constexpr size_t kDefaultVolumePhotons = 100000;
  // k of the volume photons' beam kernels (photon/volume_beam_map.h): the
  // disc radius is the distance to the k-th nearest volume photon. A
  // segment of length L crosses about (3/4) k L / r discs, so the query's
  // cost grows as k^(2/3); the surface estimates' k (100) made ~1,300
  // crossings a camera ray in thin fog (docs/media.md, "The beam query's
  // cost"). --volume-k; 0: kDefaultVolumeK with a fixed budget, the
  // surface k_s (as before --volume-k) for progressive passes, whose pilot
  // kernel is the median of these radii and whose measured convergence
  // (tests/test_media_progressive.cpp) was made with them: at 32 the
  // passes' mean lands 20% high instead of 30% low, and does not approach
  // pathtrace faster (docs/media.md).
  int volumeK = 0;
  static constexpr int kDefaultVolumeK = 32;
  int effectiveVolumeK() const { return volumeK > 0 ? volumeK : progressive ? estimate.ks : kDefaultVolumeK; }
  int frames = 8;                  // accumulation: in-between frames
  bool spaceTime4D = false;        // --search 4d
  float kappa = 1.0f;              // 4D metric weight
  estimate::Options estimate;      // k, ks, fraction, max radius / dt, kernels
  float maxRadiusFraction = 0.02f; // max radius when estimate.maxRadius is not set: of the scene's diagonal
  // Largest time distance kept by the two-pass search when
  // estimate.maxTimeDistance is not set, as a fraction of the shutter: the
  // nearest-in-time estimate decays only as k f / (2 dt) away from a moving
  // caustic, and those tails smear a sharp spot (Delta t_max of method.md).
  float maxDtFraction = 0.1f;
  // Two-pass time estimate seen from the camera: its space-time kernel is
  // at least this many times one eye sample's share of its pixel (pixel
  // area at the path's length x shutter / spp); 0: pure k-NN. A smaller
  // kernel resolves what the eye samples cannot, and the image turns
  // heavy-tailed (docs/photon-map.md, "The estimate's variance").
  float kernelFootprint = 1.0f;
  int gatherRays = 1;
  // The final gather's guide (Jensen 1995): each gather ray is a pair, one
  // BSDF-sampled and one drawn toward the incoming directions of the global
  // photons nearest the gather point, weighed by the balance heuristic
  // (unbiased). It removes the salt of a large room lit by a small lamp and
  // lowers the noise of an evenly lit small room. Progressive passes do not
  // use it. docs/photon-map.md, "The final gather where the global map is
  // sparse".
  bool gatherGuide = true;
  bool visualizeGlobal = false;
  // How the user set the two photon counts, for the memory-budget error:
  // the flag, or the scene key and file (cli/render_command.cpp sets these).
  std::string causticPhotonsSource = "--photons";
  std::string globalPhotonsSource = "--global-photons";
  std::string volumePhotonsSource = "--volume-photons";
  // How the image size was set, for the memory-budget error.
  std::string resolutionSource = "the camera resolution";

  // ---- progressive passes (render/progressive.h): time, accumulation, standard ----
  bool progressive = false;
  int passes = 0;                 // stop once this many passes are done in all (0: the time limit decides)
  double timeLimitSeconds = 0;    // > 0: stop after the pass that reaches it (this run's seconds)
  float alpha = 0;                // > 0: overrides the variant's alpha (docs/photon-map.md)
  // An animation frame rendered in passes (render/animation.h): the frame's
  // shutter in scene seconds. Every pass traces its photons over it and
  // takes its camera samples in it (the scene's shutter is the whole
  // timeline). NaN: the scene's shutter.
  float frameOpen = std::numeric_limits<float>::quiet_NaN();
  float frameClose = std::numeric_limits<float>::quiet_NaN();
  // Such a frame's passes sharing the time-invariant photons of its block
  // (docs/animation.md section 6, "Sharing"): what its passes' photons
  // depend on beyond the frame (block, --shared-photons, ...), as text for
  // the fingerprint; empty: the frame's own photons alone.
  std::string frameSharing;
  // Eye samples where the eye paths are noisy (render/sample_allocation.h):
  // every pass gives pixel p m_p in [spp, passSampleCap x spp] samples from
  // an eye-only pilot, with at most passExtraSamples x spp x pixels above
  // spp in all. 0: spp everywhere (the CLI's default for progressive renders
  // is cli/progressive_options.h's kDefaultExtraSamples).
  float passExtraSamples = 0;
  int passSampleCap = 32;
};

struct RenderStats {
  double seconds = 0;          // everything: photon passes, trees, rendering
  double photonSeconds = 0;    // tracing + tree builds
  uint64_t cameraSamples = 0;
  // Per photon map (render/map_kinds.h): stored, emitted, k-NN estimates.
  PerMap<MapStats> maps;
  double bytesPerPhoton = 0;
  // The path tracer's caustic guide (render/caustic_guide.h): photons
  // stored and emitted, its neighbour cache's bytes, seconds to build it all.
  size_t guideStored = 0;
  uint64_t guideEmitted = 0, guideBytes = 0;
  size_t guideCells = 0, guideCellsFilled = 0;  // its neighbour cache's sub-cells: all, and filled by the render
  double guideSeconds = 0;
  uint64_t standardEstimates = 0, timeEstimates = 0;
  int minSpp = 0, maxSpp = 0;  // over pixels
  uint64_t peakResidentBytes = 0;  // of the whole process, at the end of render() (core/memory.h)
  std::vector<std::string> warnings;  // for the user: empty photon maps and the like
};

// The pixel filter the options ask for (its kind's default radius when
// filterRadius is 0): every pixel loop (fixed budget, progressive pass,
// animation frame) samples its camera positions from it (render/renderer.cpp).
PixelFilter pixelFilterFor(const RenderOptions& opt);

}  // namespace tdpm
