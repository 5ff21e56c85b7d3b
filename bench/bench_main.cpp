// bench/bench_main.cpp — the one main() of tdpm_bench. Every other
// bench/*.cpp only registers benchmarks (BENCHMARK(...)), so modules can add
// files without clashing.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
