// photon/store.cpp — encodings and bulk operations of the photon store
// (batch concatenation, permutation for the kd-tree, memory accounting).
#include "photon/store.h"

#include <tbb/parallel_for.h>

#include <cmath>

#include "core/error.h"

namespace tdpm::photon {

uint32_t encodeRgbe(Rgb c) {
  float r = c.r > 0.0f ? c.r : 0.0f;  // NaN and negatives -> 0
  float g = c.g > 0.0f ? c.g : 0.0f;
  float b = c.b > 0.0f ? c.b : 0.0f;
  float m = std::max(r, std::max(g, b));
  if (!(m >= 1e-37f)) return 0;
  if (!std::isfinite(m)) m = r = g = b = 1e37f;
  int e;
  std::frexp(m, &e);  // m = f * 2^e, f in [0.5, 1)
  // Mantissa units of 2^(e-8): the largest channel maps to [128, 256).
  // Round to nearest; if it rounds up to 256, move to the next exponent.
  float scale = std::ldexp(1.0f, 8 - e);
  uint32_t mr = uint32_t(r * scale + 0.5f), mg = uint32_t(g * scale + 0.5f), mb = uint32_t(b * scale + 0.5f);
  if (mr > 255 || mg > 255 || mb > 255) {
    ++e;
    scale *= 0.5f;
    mr = uint32_t(r * scale + 0.5f);
    mg = uint32_t(g * scale + 0.5f);
    mb = uint32_t(b * scale + 0.5f);
  }
  int eb = e + 128;
  if (eb <= 0) return 0;
  if (eb > 255) eb = 255;
  return mr | (mg << 8) | (mb << 16) | (uint32_t(eb) << 24);
}

uint16_t encodeDirection(Vec3f d) {
  float l1 = std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z);
  if (!(l1 > 0.0f)) return encodeDirection({0.0f, 0.0f, 1.0f});
  float ox = d.x / l1, oy = d.y / l1;
  if (d.z < 0.0f) {
    float nx = (1.0f - std::fabs(oy)) * (ox >= 0.0f ? 1.0f : -1.0f);
    float ny = (1.0f - std::fabs(ox)) * (oy >= 0.0f ? 1.0f : -1.0f);
    ox = nx;
    oy = ny;
  }
  auto q = [](float v) {
    int i = int(std::lround((v * 0.5f + 0.5f) * 255.0f));
    return uint16_t(i < 0 ? 0 : (i > 255 ? 255 : i));
  };
  return uint16_t(q(ox) | (q(oy) << 8));
}

TimeQuantiser::TimeQuantiser(float t0_, float t1_) : t0(t0_), t1(t1_) {
  TDPM_ASSERT(t1 > t0, "photon store needs a time range with t1 > t0 (use a nominal [0,1] without motion)");
  binWidth = (t1 - t0) / float(kTimeBins);
  invBinWidth = float(kTimeBins) / (t1 - t0);
}

void PhotonStore::reserve(size_t n) {
  x_.reserve(n);
  y_.reserve(n);
  z_.reserve(n);
  energy_.reserve(n);
  direction_.reserve(n);
  flags_.reserve(n);
}

void PhotonStore::clear() {
  x_.clear();
  y_.clear();
  z_.clear();
  energy_.clear();
  direction_.clear();
  flags_.clear();
}

void PhotonStore::shrinkToFit() {
  x_.shrink_to_fit();
  y_.shrink_to_fit();
  z_.shrink_to_fit();
  energy_.shrink_to_fit();
  direction_.shrink_to_fit();
  flags_.shrink_to_fit();
}

size_t PhotonStore::bytesAllocated() const {
  return (x_.capacity() + y_.capacity() + z_.capacity()) * sizeof(float) + energy_.capacity() * sizeof(uint32_t) +
         direction_.capacity() * sizeof(uint16_t) + flags_.capacity() * sizeof(uint16_t);
}

void PhotonStore::appendBatches(const PhotonStore* batches, size_t count) {
  std::vector<size_t> offset(count + 1);
  offset[0] = size();
  for (size_t b = 0; b < count; ++b) {
    TDPM_ASSERT(batches[b].t0() == t0() && batches[b].t1() == t1(), "photon batches must share the store's time range");
    offset[b + 1] = offset[b] + batches[b].size();
  }
  size_t total = offset[count];
  // Grow to exactly the total when a single append fills an empty store (no
  // doubling slack); when appends come in chunks past a reservation, grow by
  // half again so that each chunk does not reallocate. Then copy each batch
  // to its fixed offset: the result depends only on the batch order.
  auto grow = [total](auto& v) {
    if (v.capacity() < total) v.reserve(v.empty() ? total : std::max(total, v.capacity() + v.capacity() / 2));
    v.resize(total);
  };
  grow(x_);
  grow(y_);
  grow(z_);
  grow(energy_);
  grow(direction_);
  grow(flags_);
  tbb::parallel_for(size_t(0), count, [&](size_t b) {
    const PhotonStore& s = batches[b];
    size_t o = offset[b], n = s.size();
    std::copy_n(s.x_.data(), n, x_.data() + o);
    std::copy_n(s.y_.data(), n, y_.data() + o);
    std::copy_n(s.z_.data(), n, z_.data() + o);
    std::copy_n(s.energy_.data(), n, energy_.data() + o);
    std::copy_n(s.direction_.data(), n, direction_.data() + o);
    std::copy_n(s.flags_.data(), n, flags_.data() + o);
  });
}

namespace {
// new[i] = old[order[i]] through one scratch buffer per element size, so the
// transient memory is 4 bytes per photon on top of the store.
template <class T>
void gatherInto(std::vector<T>& v, const uint32_t* order, std::vector<T>& scratch) {
  size_t n = v.size();
  scratch.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) scratch[i] = v[order[i]];
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    std::copy(scratch.begin() + r.begin(), scratch.begin() + r.end(), v.begin() + r.begin());
  });
}
}  // namespace

void PhotonStore::permute(const uint32_t* order) {
  {
    std::vector<float> s;
    gatherInto(x_, order, s);
    gatherInto(y_, order, s);
    gatherInto(z_, order, s);
  }
  {
    std::vector<uint32_t> s;
    gatherInto(energy_, order, s);
  }
  {
    std::vector<uint16_t> s;
    gatherInto(direction_, order, s);
    gatherInto(flags_, order, s);
  }
}

}  // namespace tdpm::photon
