// photon/store.h — the photon store: a plain structure-of-arrays container
// of photons (position, radiant energy, incident direction, quantised time,
// flag bits) and the compact encodings it uses. It knows nothing of scenes,
// lights or renderers, so the same container serves surface photons, volume
// photons, one map shared by many frames and a progressive variant.
//
// Layout, per photon (20 bytes, nothing else; the kd-tree of photon/kdtree.h
// reorders these arrays in place and stores only its split axis in `flags`):
//   x, y, z     3 x float   12 B   position
//   energy      uint32       4 B   radiant energy Q in joules, RGBE (Ward),
//                                   rounded to nearest (zero-mean error)
//   direction   uint16       2 B   unit vector towards where the photon came
//                                   from (the BRDF's w_i), octahedral 8+8 bits
//   flags       uint16       2 B   bits 0-7  time bin q of [t0, t1] (256 bins)
//                                   bits 8-9  kd-tree split axis (x, y, z, t)
//                                   bits 10-15 free for the caller (userFlags)
// A photon's time is the centre of its bin, t0 + (q + 0.5) * (t1 - t0) / 256,
// so the quantisation error is at most (t1 - t0) / 512. Estimators treat the
// photon as spread uniformly over its bin (docs/photon-map.md), which is why
// the quantisation adds no bias.
//
// Threads: add() is not thread-safe. Each thread fills its own PhotonStore
// (a batch) with the same time range, and appendBatches() concatenates them
// in batch-index order, so the result does not depend on thread timing.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "math/vec.h"

namespace tdpm::photon {

// ---- encodings ----

// Shared-exponent RGB (Ward's RGBE): 8-bit mantissas and a shared 8-bit
// exponent, range 2^-128 .. 2^127, enough for joules of a single photon.
// Mantissas are rounded to nearest, so the error of every channel is at most
// 1/256 of the largest channel (half a unit of >= 128) and has zero mean. Negative or NaN input is 0.
uint32_t encodeRgbe(Rgb c);
inline Rgb decodeRgbe(uint32_t v) {
  uint32_t e = v >> 24;
  if (e == 0) return Rgb(0.0f);
  // 2^(e - 128 - 8) built directly as float bits; e - 136 is >= -135, and
  // denormal results are not needed (photons that dim are 0 anyway).
  int ex = int(e) - 136;
  float scale;
  if (ex >= -126) {
    uint32_t bits = uint32_t(ex + 127) << 23;
    std::memcpy(&scale, &bits, 4);
  } else {
    scale = std::ldexp(1.0f, ex);
  }
  return {float(v & 0xFF) * scale, float((v >> 8) & 0xFF) * scale, float((v >> 16) & 0xFF) * scale};
}

// Octahedral unit-vector encoding (Cigolle et al. 2014), 8 bits per axis:
// at most ~1.2 degrees of error, uniform over the sphere (Jensen's theta/phi
// bytes are coarse near the poles).
uint16_t encodeDirection(Vec3f d);
inline Vec3f decodeDirection(uint16_t v) {
  float ox = float(v & 0xFF) * (2.0f / 255.0f) - 1.0f;
  float oy = float(v >> 8) * (2.0f / 255.0f) - 1.0f;
  float z = 1.0f - std::fabs(ox) - std::fabs(oy);
  if (z < 0.0f) {
    float nx = (1.0f - std::fabs(oy)) * (ox >= 0.0f ? 1.0f : -1.0f);
    float ny = (1.0f - std::fabs(ox)) * (oy >= 0.0f ? 1.0f : -1.0f);
    ox = nx;
    oy = ny;
  }
  float inv = 1.0f / std::sqrt(ox * ox + oy * oy + z * z);
  return {ox * inv, oy * inv, z * inv};
}

// ---- flag bits ----
constexpr uint16_t kTimeMask = 0x00FF;
constexpr int kAxisShift = 8;
constexpr uint16_t kAxisMask = 0x0300;
constexpr int kUserShift = 10;
constexpr uint16_t kUserMask = 0xFC00;  // 6 bits for the caller
constexpr int kTimeBins = 256;

// The time range [t0, t1] of a store and its 256 bins. Requires t1 > t0: a
// scene without motion should not use time at all, and if it does it must
// pass a nominal range (e.g. [0, 1]) so energies stay Q = power * ts / n.
struct TimeQuantiser {
  float t0 = 0.0f, t1 = 1.0f;
  float binWidth = 1.0f / 256.0f;  // (t1 - t0) / 256, seconds
  float invBinWidth = 256.0f;

  TimeQuantiser() = default;
  TimeQuantiser(float t0_, float t1_);
  float shutterLength() const { return t1 - t0; }
  uint8_t quantise(float t) const {
    float u = (t - t0) * invBinWidth;
    if (!(u > 0.0f)) return 0;  // also NaN
    if (u >= 255.0f) return 255;
    return uint8_t(int(u));  // truncation == floor for u > 0
  }
  // Query time in bin units, clamped to [0, 256]: bin q spans [q, q + 1).
  float binUnits(float t) const {
    float u = (t - t0) * invBinWidth;
    return !(u > 0.0f) ? 0.0f : (u > 256.0f ? 256.0f : u);
  }
  float binCentre(int q) const { return t0 + (float(q) + 0.5f) * binWidth; }
  float binStart(int q) const { return t0 + float(q) * binWidth; }
};

class PhotonStore {
 public:
  PhotonStore() = default;
  PhotonStore(float t0, float t1) : time_(t0, t1) {}

  // ---- filling ----
  void reserve(size_t n);
  void clear();          // keeps capacity (progressive passes reuse it)
  void shrinkToFit();    // capacity == size, so bytesPerPhoton is exact
  // wi: unit direction towards where the photon came from; energy in joules.
  void add(Vec3f p, Rgb energy, Vec3f wi, float time, uint8_t userFlags = 0) {
    x_.push_back(p.x);
    y_.push_back(p.y);
    z_.push_back(p.z);
    energy_.push_back(encodeRgbe(energy));
    direction_.push_back(encodeDirection(wi));
    flags_.push_back(uint16_t(time_.quantise(time) | (uint16_t(userFlags & 0x3F) << kUserShift)));
  }
  // A photon copied from another store as it is encoded there, with time bin
  // `bin` of this store's range (animations: segments of one time grid
  // merged into a frame's map, render/animation.cpp). The axis bits clear.
  void addEncoded(float x, float y, float z, uint32_t energy, uint16_t direction, uint16_t flags, uint8_t bin) {
    x_.push_back(x);
    y_.push_back(y);
    z_.push_back(z);
    energy_.push_back(energy);
    direction_.push_back(direction);
    flags_.push_back(uint16_t((flags & kUserMask) | bin));
  }
  // Concatenate batches (each filled by one thread, same time range) after
  // the photons already here, in the order of `batches`; copies in parallel.
  void appendBatches(const PhotonStore* batches, size_t count);
  void appendBatches(const std::vector<PhotonStore>& batches) { appendBatches(batches.data(), batches.size()); }

  // ---- reading ----
  size_t size() const { return x_.size(); }
  bool empty() const { return x_.empty(); }
  const TimeQuantiser& time() const { return time_; }
  float t0() const { return time_.t0; }
  float t1() const { return time_.t1; }
  float shutterLength() const { return time_.shutterLength(); }

  Vec3f position(size_t i) const { return {x_[i], y_[i], z_[i]}; }
  Rgb energy(size_t i) const { return decodeRgbe(energy_[i]); }
  Vec3f direction(size_t i) const { return decodeDirection(direction_[i]); }
  uint8_t timeBin(size_t i) const { return uint8_t(flags_[i] & kTimeMask); }
  float time(size_t i) const { return time_.binCentre(timeBin(i)); }
  int splitAxis(size_t i) const { return (flags_[i] & kAxisMask) >> kAxisShift; }
  uint8_t userFlags(size_t i) const { return uint8_t(flags_[i] >> kUserShift); }

  // Raw arrays for the hot loops (kd-tree, estimators).
  const float* xs() const { return x_.data(); }
  const float* ys() const { return y_.data(); }
  const float* zs() const { return z_.data(); }
  const uint32_t* energies() const { return energy_.data(); }
  const uint16_t* directions() const { return direction_.data(); }
  const uint16_t* flags() const { return flags_.data(); }

  // Memory actually held (capacities, not sizes), and per stored photon.
  size_t bytesAllocated() const;
  double bytesPerPhoton() const { return empty() ? 0.0 : double(bytesAllocated()) / double(size()); }

  // ---- for the kd-tree builder ----
  // Reorder so that new[i] = old[order[i]]; order is a permutation.
  void permute(const uint32_t* order);
  void setSplitAxis(size_t i, int axis) {
    flags_[i] = uint16_t((flags_[i] & ~kAxisMask) | (uint16_t(axis) << kAxisShift));
  }

  // ---- for whole stores exchanged between processes (render over MPI) ----
  struct RawArrays {
    float *x, *y, *z;
    uint32_t* energy;
    uint16_t *direction, *flags;
  };
  // Resizes to n photons and returns the arrays, for a caller that fills
  // every element (the capacity is then exactly n).
  RawArrays resizeForFill(size_t n) {
    for (auto* v : {&x_, &y_, &z_}) v->resize(n);
    energy_.resize(n);
    direction_.resize(n);
    flags_.resize(n);
    return {x_.data(), y_.data(), z_.data(), energy_.data(), direction_.data(), flags_.data()};
  }

 private:
  TimeQuantiser time_;
  std::vector<float> x_, y_, z_;
  std::vector<uint32_t> energy_;
  std::vector<uint16_t> direction_;
  std::vector<uint16_t> flags_;
};

}  // namespace tdpm::photon
