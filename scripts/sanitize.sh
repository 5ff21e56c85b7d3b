#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer:
# configures build-asan with -DTDPM_SANITIZE=ON (RelWithDebInfo: -O2 -g, so
# reports have lines), builds tdpm and the tests, and runs CTest. Any
# sanitizer report fails the run (UBSan is made fatal; ASan always is).
# Run it before submitting a change that touches memory handling (stores,
# kd-tree, tracing buffers, image I/O, parsing). See README.md for the time.
#
#   scripts/sanitize.sh          # build + every test
#   scripts/sanitize.sh -R photon   # extra arguments go to ctest
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)

start=$(date +%s)
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTDPM_SANITIZE=ON -DTDPM_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j "$jobs"
built=$(date +%s)
echo "sanitize.sh: build took $(( built - start )) s"

# halt_on_error for UBSan too; no leak check exemptions: a leak is a finding.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1}
cd build-asan
status=0
ctest --output-on-failure -j "$jobs" --timeout 3000 "$@" || status=$?
echo "sanitize.sh: tests took $(( $(date +%s) - built )) s; $( [ $status -eq 0 ] && echo passed || echo FAILED )"
exit $status
