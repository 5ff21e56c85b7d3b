// sampling/sampler.h — where every random number of a render comes from.
//
// Two kinds (--sampler, scene key render.sampler):
//   random  PCG32 per pixel (core/rng.h), the camera's (x, y, t) as a Latin
//           hypercube per batch (sampling/stratified.h): the old behaviour.
//   sobol   Owen-scrambled Sobol points, padded: each group of dimensions
//           below takes the first 1-3 Sobol dimensions (sampling/sobol.h)
//           with its own index shuffle and its own scramble, both hashed
//           from (seed, pixel, group). Every group is then a well
//           stratified (0,m,s)-net on its own, and groups are independent
//           of each other, so high path depths stay as well distributed as
//           the camera's dimensions (no poor projections of high Sobol
//           dimensions). The default.
//
// Dimension order (docs/sampling.md). A consumer asks for a group by its
// id, never by a running counter, so a branch that skips a draw does not
// shift what later vertices see:
//   camera:      kCameraGroup      3D: pixel x, pixel y (in the pixel), time
//                kCameraLens       2D: the thin lens's point (camera.lens_radius)
//   vertex v (v = 0 is the camera ray's first hit), vertexGroup(v, slot):
//     kLightChoice   1D  which light (reserved: every light is sampled today)
//     kLightPosition 2D  point on the light, per light (sub = light index)
//     kBsdf          3D  2D direction, then the lobe choice (Fresnel: reflect or refract)
//     kRoulette      1D  Russian roulette
//     kGather        2D  final-gather direction (sub = gather ray index)
//   photon path (sample index = path index, "pixel" = the map's seed):
//     kPhotonLight 1D light choice, kPhotonPosition 2D, kPhotonDirection 2D,
//     kPhotonTime 1D (reserved: times stay scrambled van der Corput), then
//     vertexGroup(bounce, kBsdf / kRoulette); photon/tracer.cpp.
//
// The sample index of a pixel runs 0, 1, 2, ... across adaptive batches
// (and a later pass loop can continue it: startSample() takes any index),
// so more samples extend one sequence instead of restarting it.
// Same seed -> same numbers for any thread count or tile order: everything
// is a function of (seed, pixel, sample index, dimension).
//
// The integrators are templates over the stream type (RandomStream,
// SobolStream): the kind is chosen once per render, no virtual call per draw.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/rng.h"
#include "math/vec.h"
#include "sampling/sobol.h"
#include "sampling/stratified.h"

namespace tdpm {

enum class SamplerKind { Random, Sobol };
const char* samplerName(SamplerKind k);
// false when `name` is neither "random" nor "sobol".
bool parseSamplerKind(const std::string& name, SamplerKind& out);

namespace dims {
constexpr uint32_t kCameraGroup = 0;
enum Slot : uint32_t { kLightChoice = 0, kLightPosition, kBsdf, kRoulette, kGather, kSlotsPerVertex };
constexpr uint32_t kPhotonLight = 1, kPhotonPosition = 2, kPhotonDirection = 3, kPhotonTime = 4;
constexpr uint32_t kCameraLens = 5;
constexpr uint32_t kFirstVertexGroup = 8;
// Group id of `slot` at path vertex `vertex`; `sub` tells apart several
// draws of one slot (lights, gather rays).
constexpr uint64_t vertexGroup(int vertex, Slot slot, uint32_t sub = 0) {
  return (uint64_t(sub) << 32) | (kFirstVertexGroup + uint64_t(vertex) * kSlotsPerVertex + slot);
}
}  // namespace dims

// random: PCG32. The group id is ignored; draws are taken in order.
struct RandomStream {
  Rng* rng;
  float get1D(uint64_t) { return rng->uniform(); }
  Vec2f get2D(uint64_t) {
    float a = rng->uniform();
    return {a, rng->uniform()};
  }
  Vec3f get3D(uint64_t) {
    float a = rng->uniform(), b = rng->uniform();
    return {a, b, rng->uniform()};
  }
};

// sobol: padded, Owen-scrambled Sobol (see the top of this file).
// Cost: sampling/sobol.h's reversed-bit form; the index is reversed once
// per stream (per sample), not once per group.
struct SobolStream {
  uint64_t pixelSeed = 0;
  uint32_t index = 0;
  uint32_t reversedIndex = 0;

  SobolStream() = default;
  SobolStream(uint64_t seed, uint32_t i) : pixelSeed(seed), index(i), reversedIndex(reverseBits32(i)) {}

  struct GroupSeeds {
    uint32_t shuffle, scramble[3];
  };
  // A group's seeds depend on (pixelSeed, group) only. A caller that draws
  // many samples with one pixelSeed (the photon tracer: one per map and
  // batch) may hash groups [0, tableSize) once into `table`
  // (fillSeedTable); the values are the same, only the hashing is skipped.
  const GroupSeeds* table = nullptr;
  uint32_t tableSize = 0;

  static GroupSeeds hashSeeds(uint64_t pixelSeed, uint64_t group) {
    uint64_t h1 = mix64(pixelSeed ^ mix64(group));
    uint64_t h2 = mix64(h1);
    return {uint32_t(h1), {uint32_t(h1 >> 32), uint32_t(h2), uint32_t(h2 >> 32)}};
  }
  static void fillSeedTable(uint64_t pixelSeed, GroupSeeds* out, uint32_t n) {
    for (uint32_t g = 0; g < n; ++g) out[g] = hashSeeds(pixelSeed, g);
  }
  GroupSeeds seeds(uint64_t group) const {
    if (group < tableSize) return table[group];
    return hashSeeds(pixelSeed, group);
  }
  // The shuffled index, reversed: shuffleIndex(index, seed) == reverseBits32(shuffledReversed(seed)).
  uint32_t shuffledReversed(uint32_t seed) const { return laineKarrasPermutation(reversedIndex, seed); }
  static float coord(uint32_t r, int d, uint32_t scramble) {
    return bitsToFloat01(scrambledSobolReversed(r, d, scramble));
  }
  float get1D(uint64_t group) const {
    GroupSeeds s = seeds(group);
    return coord(shuffledReversed(s.shuffle), 0, s.scramble[0]);
  }
  Vec2f get2D(uint64_t group) const {
    GroupSeeds s = seeds(group);
    uint32_t r = shuffledReversed(s.shuffle);
    return {coord(r, 0, s.scramble[0]), coord(r, 1, s.scramble[1])};
  }
  Vec3f get3D(uint64_t group) const {
    GroupSeeds s = seeds(group);
    uint32_t r = shuffledReversed(s.shuffle);
    return {coord(r, 0, s.scramble[0]), coord(r, 1, s.scramble[1]), coord(r, 2, s.scramble[2])};
  }
};

// ---- per-pixel samplers (the pixel loop's side) ----
// startBatch(first, count) before a batch of sample indices first..first+count-1;
// then for each: stream(i) and camera(i) (pixel offset + time of sample i),
// and lens(i) (the thin lens's point) when the camera has a lens.

class RandomPixelSampler {
 public:
  using Stream = RandomStream;
  RandomPixelSampler(uint64_t seed, uint64_t pixel) : seed_(seed), pixel_(pixel) {}
  void startBatch(uint32_t first, int count) {
    // Index 0 keeps the stream of the old per-pixel Rng, so a non-adaptive
    // random render is the image it always was; later batches start their
    // own stream from (seed, pixel, first index), so a pass loop can resume.
    if (first == 0) rng_.reseed(hashCombine(seed_, pixel_), 0);
    else rng_.reseed(hashCombine(seed_, pixel_, first), 0);
    first_ = first;
    camera_.resize(size_t(count));
    stratifiedCameraSamples(count, rng_, camera_.data(), strata_);
  }
  CameraSample camera(uint32_t i) const { return camera_[i - first_]; }
  // The thin lens's point of sample i, asked for only by a thin-lens camera:
  // hashed from (seed, pixel, i), not drawn from rng_, so the path stream is
  // the one a pinhole render always drew. Independent uniform, not stratified.
  Vec2f lens(uint32_t i) const {
    uint64_t h = hashCombine(hashCombine(seed_, pixel_, i), 0x1e25ull);
    return {bitsToFloat01(uint32_t(h)), bitsToFloat01(uint32_t(h >> 32))};
  }
  Stream stream(uint32_t) { return {&rng_}; }

 private:
  uint64_t seed_, pixel_;
  uint32_t first_ = 0;
  Rng rng_;
  std::vector<CameraSample> camera_;
  std::vector<uint32_t> strata_;
};

class SobolPixelSampler {
 public:
  using Stream = SobolStream;
  SobolPixelSampler(uint64_t seed, uint64_t pixel) : pixelSeed_(hashCombine(seed, pixel, 0x50b01ull)) {}
  void startBatch(uint32_t, int) {}
  Stream stream(uint32_t i) const { return {pixelSeed_, i}; }
  CameraSample camera(uint32_t i) const {
    Vec3f u = stream(i).get3D(dims::kCameraGroup);
    return {{u.x, u.y}, u.z};
  }
  Vec2f lens(uint32_t i) const { return stream(i).get2D(dims::kCameraLens); }

 private:
  uint64_t pixelSeed_;
};

}  // namespace tdpm
