// math/simd.cpp — the runtime choice between the xsimd (build-time) kernels
// and their AVX-512 versions (see math/simd.h).
#include "math/simd.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace tdpm::simd {

bool cpuHasAvx512() {
#if TDPM_HAVE_AVX512_KERNELS
  // GCC/Clang check the OS's XCR0 (ZMM state enabled) as well as CPUID.
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw");
#else
  return false;
#endif
}

namespace {
Kernel chooseKernel() {
  const char* env = std::getenv("TDPM_SIMD");
  const bool has512 = cpuHasAvx512();
  if (env && *env && std::strcmp(env, "auto") != 0) {
    if (std::strcmp(env, "avx2") == 0 || std::strcmp(env, "build") == 0) return Kernel::Build;
    if (std::strcmp(env, "avx512") == 0) {
      if (has512) return Kernel::Avx512;
      std::fprintf(stderr, "tdpm: TDPM_SIMD=avx512 but this CPU has no AVX-512 (F+BW); using %s\n",
                   kernelName(Kernel::Build));
      return Kernel::Build;
    }
    std::fprintf(stderr, "tdpm: TDPM_SIMD=%s is not one of auto, avx2, avx512; using auto\n", env);
  }
  return has512 ? Kernel::Avx512 : Kernel::Build;
}
}  // namespace

Kernel activeKernel() {
  static const Kernel k = chooseKernel();
  return k;
}

const char* kernelName(Kernel k) { return k == Kernel::Avx512 ? "avx512" : Arch::name(); }

}  // namespace tdpm::simd
