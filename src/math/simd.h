// math/simd.h — the one place xsimd is included. Other modules use these
// aliases so that the instruction set is chosen once, at build time.
// The batch width is pinned to AVX2 (32 bytes) whenever the compiler may use
// it, even where AVX-512 exists: machines in this fleet differ (some report
// AVX-512, most do not), and one width keeps kernels, results and benchmark
// ratios identical across them. Without AVX2: xsimd's best (SSE2 at least).
//
// Runtime dispatch (issue 9): a kernel may also have an AVX-512 version,
// written with target attributes (never required at build time) and chosen
// once at startup by activeKernel(): AVX-512 when the CPU and OS support
// avx512f + avx512bw, else the xsimd kernel above. The environment variable
// TDPM_SIMD=avx2 forces the xsimd kernel (bench and tests compare the two);
// TDPM_SIMD=avx512 asks for AVX-512 and falls back, with a note on stderr,
// where the CPU lacks it. Both kinds must return identical results.
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

// Kernels with an AVX-512 version are compiled only for x86-64 GCC/Clang.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define TDPM_HAVE_AVX512_KERNELS 1
#else
#define TDPM_HAVE_AVX512_KERNELS 0
#endif

enum class Kernel {
  Build,   // the xsimd kernel of the build-time Arch (AVX2 on this fleet)
  Avx512,  // AVX-512 (F + BW), runtime-dispatched
};

// Whether this CPU (and OS) can run the AVX-512 kernels.
bool cpuHasAvx512();
// The kernel that dispatching entry points use (fixed at first call).
Kernel activeKernel();
// "avx2" (or xsimd's name of the build Arch) / "avx512".
const char* kernelName(Kernel k);

}  // namespace tdpm::simd
