// bench/bench_main.cpp — the one main() of tdpm_bench. Every other
// bench/*.cpp only registers benchmarks (BENCHMARK(...)), so modules can add
// files without clashing. main() adds the CPU to the run's JSON context
// (cpu_model, cpu_isa, simd_kernel): bench/check picks the baseline of the
// run's own CPU model with them (bench/README.md).
#include <benchmark/benchmark.h>

#include <fstream>
#include <string>

#include "math/simd.h"

namespace {
// "model name" and the AVX flags that matter to our kernels, from /proc/cpuinfo.
void addCpuContext() {
  std::string model = "unknown", flags;
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    auto value = [&] {
      auto c = line.find(':');
      return c == std::string::npos ? std::string() : line.substr(line.find_first_not_of(" \t", c + 1));
    };
    if (model == "unknown" && line.rfind("model name", 0) == 0) model = value();
    if (flags.empty() && line.rfind("flags", 0) == 0) flags = " " + value() + " ";
    if (model != "unknown" && !flags.empty()) break;
  }
  std::string isa;
  for (const char* f : {"avx2", "fma", "avx512f", "avx512bw", "avx512vl"})
    if (flags.find(std::string(" ") + f + " ") != std::string::npos) isa += (isa.empty() ? "" : ",") + std::string(f);
  benchmark::AddCustomContext("cpu_model", model);
  benchmark::AddCustomContext("cpu_isa", isa.empty() ? "none" : isa);
  benchmark::AddCustomContext("simd_kernel", tdpm::simd::kernelName(tdpm::simd::activeKernel()));
}
}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  addCpuContext();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
