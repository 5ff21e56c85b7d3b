// math/simd.h — the one place xsimd is included. Other modules use these
// aliases so that the instruction set is chosen once, at build time.
// The batch width is pinned to AVX2 (32 bytes) whenever the compiler may use
// it, even where AVX-512 exists: machines in this fleet differ (some report
// AVX-512, most do not), and one width keeps kernels, results and benchmark
// ratios identical across them. Without AVX2: xsimd's best (SSE2 at least).
#pragma once
#include <cstdint>
#include <xsimd/xsimd.hpp>

namespace tdpm::simd {

#if XSIMD_WITH_AVX2
using Arch = xsimd::avx2;
#else
using Arch = xsimd::default_arch;
#endif
using BatchU8 = xsimd::batch<uint8_t, Arch>;
using BatchF = xsimd::batch<float, Arch>;
using BatchI32 = xsimd::batch<int32_t, Arch>;
constexpr std::size_t kBytesPerBatch = BatchU8::size;
constexpr std::size_t kFloatsPerBatch = BatchF::size;

}  // namespace tdpm::simd
