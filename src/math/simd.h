// math/simd.h — the one place xsimd is included. Other modules use these
// aliases so that the instruction set is chosen once, at build time
// (TDPM_NATIVE: the build machine's best, AVX2 here; SSE2 otherwise).
#pragma once
#include <cstdint>
#include <xsimd/xsimd.hpp>

namespace tdpm::simd {

using Arch = xsimd::default_arch;
using BatchU8 = xsimd::batch<uint8_t, Arch>;
using BatchF = xsimd::batch<float, Arch>;
using BatchI32 = xsimd::batch<int32_t, Arch>;
constexpr std::size_t kBytesPerBatch = BatchU8::size;
constexpr std::size_t kFloatsPerBatch = BatchF::size;

}  // namespace tdpm::simd
