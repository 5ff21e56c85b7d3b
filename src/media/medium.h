// media/medium.h — the runtime participating media (issue 25): homogeneous
// media and dense density grids, as flat data (no virtual calls), and the
// two queries every integrator needs along a ray segment:
//   transmittance   T_c = exp(-integral of sigma_t,c): closed form in a
//                   homogeneous medium; ratio tracking (Novak et al. 2014)
//                   in a grid, unbiased, with Russian roulette once T is
//                   small (still unbiased);
//   free flight     where the ray first interacts: closed form
//                   (exponential) in a homogeneous medium; delta tracking
//                   against a majorant in a grid.
//
// RGB. The coefficients differ per channel, and one distance must serve all
// three. We use spectral tracking (Kutz, Habel, Li and Novak 2017, "Spectral
// and decomposition tracking", history-aware form): distances are sampled
// with one scalar majorant sigma_bar >= max_c sigma_t,c; at each tentative
// collision the event (absorb, scatter, null) is chosen with probabilities
// proportional to max_c beta_c sigma_x,c and beta is multiplied per channel
// by sigma_x,c / (sigma_bar P_x). It is unbiased for any choice of positive
// P_x where sigma_x,c > 0; choosing by the path's own weights keeps the
// weights bounded, and in a grey medium every factor is exactly 1 (plain
// delta tracking, and in a homogeneous grey medium plain exponential
// sampling with the albedo as the scattering probability). pbrt-v4 samples
// by the hero wavelength's majorant and carries the ratio of pdfs instead;
// both are unbiased, spectral tracking needs no per-path pdf bookkeeping,
// which keeps the MIS weights of render/volume_path.cpp directional only.
//
// Grids: density at cell centres, interpolated trilinearly, with samples
// outside the index range counting 0 (pbrt-v4's SampledGrid::Lookup), and
// 0 outside `bounds`. Majorants (pbrt-v4's MajorantGrid): a coarse grid
// over the same bounds (16^3 cells by default, fewer along an axis with fewer
// density cells), each cell holding the maximum density over every sample
// its trilinear footprint touches, times max_c sigma_t,c. Tracking walks it
// with a DDA and samples tentative collisions at each cell's own rate:
// unbiased like the one global majorant (every cell's bound holds at every
// point of the cell; the exponential is memoryless at cell boundaries), with
// fewer null collisions where the grid is sparse, and none at all through
// empty cells. The majorant grid lives in grid space, so it moves with the
// grid's object at the ray's time and needs no per-time bound. `majorant`
// stays the global maximum (the bound of the whole grid).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/rng.h"
#include "math/bounds.h"
#include "math/transform.h"
#include "math/vec.h"
#include "motion/motion.h"
#include "scene/description.h"

namespace tdpm::media {

struct Medium {
  enum class Kind : uint8_t { Homogeneous, Grid };
  Kind kind = Kind::Homogeneous;
  Rgb sigmaA{0.0f}, sigmaS{0.0f}, sigmaT{0.0f};  // scale applied; grid: per unit density
  float g = 0.0f;         // Henyey-Greenstein asymmetry
  float majorant = 0.0f;  // sigma_bar: >= every channel's sigma_t anywhere
  // Equal coefficients in every channel: plain delta tracking (events by
  // sigma_x / sigma_bar, beta untouched), exact where spectral tracking's
  // factors would round to 1 - 1 ulp.
  bool grey = false;
  // ---- grid
  int nx = 0, ny = 0, nz = 0;
  std::shared_ptr<const std::vector<float>> density;  // x fastest; shared by instances of one description
  Bounds3f bounds;            // grid space: the box the cells tile
  Vec3f cellsPerUnit{1.0f};   // (nx, ny, nz) / bounds' size
  // Majorant grid over `bounds`: mx * my * mz cells, x fastest, each the
  // sigma_bar of its cell (density bound x max_c sigma_t,c).
  int mx = 0, my = 0, mz = 0;
  std::shared_ptr<const std::vector<float>> majorants;
  Vec3f majorantCellsPerUnit{1.0f};  // (mx, my, mz) / bounds' size
  // Grid space from world: gridFromLocal x objectMotion(t)^-1 when moving,
  // else the one static matrix gridFromWorld.
  bool moving = false;
  Affine3f gridFromWorld;
  Affine3f gridFromLocal;
  Motion objectMotion;

  bool homogeneous() const { return kind == Kind::Homogeneous; }
};

// Cells of the majorant grid per axis unless told (min with the density
// grid's own resolution along that axis).
constexpr int kMajorantGridCells = 16;

// Builds a medium from its description. `object`: the motion of the
// object whose interior (or medium_interface) holds it, or null for a
// static medium (exterior, camera, lights). Homogeneous media ignore it.
// `majorantCells`: the majorant grid's cells per axis (1: one global
// majorant, the tracking of the first version, kept for tests and benches).
Medium makeMedium(const scene::MediumDesc& d, const Motion* object,
                  std::shared_ptr<const std::vector<float>> sharedDensity = nullptr,
                  int majorantCells = kMajorantGridCells);

// Density at a grid-space point (trilinear, 0 outside the bounds).
float gridDensity(const Medium& m, Vec3f p);

// Transmittance along o + s d, s in [0, tMax] (d a unit world direction;
// tMax may be infinite) at normalised time time01. Homogeneous media never
// touch rng.
Rgb transmittance(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Rng& rng);

struct FreeFlight {
  enum class Event : uint8_t { Escape, Scatter, Absorb };
  Event event = Event::Escape;
  float t = 0.0f;  // Scatter: where along the ray
};

// Samples the ray's first real interaction in [0, tMax] and multiplies
// beta by the spectral-tracking weights (see the top of this file). Escape:
// no interaction before tMax (beta carries the transmittance's estimate's
// weight, 1 in grey media). Absorb: the path ends.
FreeFlight sampleFreeFlight(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Rng& rng, Rgb& beta);

}  // namespace tdpm::media
