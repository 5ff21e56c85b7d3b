#!/usr/bin/env bash
# Bounded libFuzzer runs of the scene loader, the EXR reader and compare's
# image dispatcher (fuzz/): builds build-fuzz with clang++ (TDPM_FUZZ=ON,
# ASan + UBSan), then runs each target on a fresh copy of its seeds. Fails
# (exit 1) on any crash, sanitizer report, leak, timeout or out-of-memory;
# the reproducer is left in build-fuzz/findings/<target>/.
#
#   scripts/fuzz.sh [SECONDS]            # explore: a random seed, SECONDS per target (default 25)
#   scripts/fuzz.sh --seed N [SECONDS]   # replay an exploring run (its seed is printed)
#   scripts/fuzz.sh --ci                 # what `scripts/setup.sh test` runs: seed 1 and a
#                                        # fixed number of inputs, so CI does not fail by
#                                        # luck and a failure replays
#
# Seeds: scenes/*.json, tests/data/*.json and fuzz/corpus/scene/ for fuzz_scene; fuzz/corpus/exr/
# (small EXRs written by tdpm or oiiotool, plus every input a run ever
# failed on, named regress-*) for fuzz_exr; fuzz/corpus/pbrt/ for fuzz_pbrt; fuzz/corpus/{pfm,hdr,png}/ for
# fuzz_image. Grown corpus copies are thrown away: the seeds stay reviewed.
set -euo pipefail

seconds=25
seed=""
runs=-1
while [ $# -gt 0 ]; do
  case "$1" in
    --ci) seed=1; runs=40000; seconds=120 ;;  # 120 s: only a cap; 40000 inputs took 12 s (scene), 6 s (exr), 5 s (pbrt) and 6 s (image) on a clean clone here (2026-11-29; on a machine loaded by other builds exr once took 111 s)
    --seed) [ $# -ge 2 ] || { echo "fuzz.sh: --seed needs a number" >&2; exit 2; }; seed=$2; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) seconds=$1 ;;
  esac
  shift
done
case "$seconds" in ''|*[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2 ;; esac
case "$seed" in *[!0-9]*) echo "fuzz.sh: --seed must be a whole number, got '$seed'" >&2; exit 2 ;; esac
[ "$seconds" -gt 0 ] || { echo "fuzz.sh: SECONDS must be positive" >&2; exit 2; }
[ -n "$seed" ] || seed=$(( (RANDOM << 15 | RANDOM) + 1 ))

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (scripts/setup.sh installs clang and libclang-rt-14-dev)" >&2; exit 1; }

jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DTDPM_FUZZ=ON \
  -DTDPM_BUILD_TESTS=OFF -DTDPM_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j "$jobs" --target fuzz_scene fuzz_exr fuzz_pbrt fuzz_image
echo "fuzz.sh: build took $(( $(date +%s) - start )) s"

work=build-fuzz/run
rm -rf "$work"
mkdir -p "$work/scene" "$work/exr" "$work/image"
cp scenes/*.json tests/data/*.json fuzz/corpus/scene/*.json "$work/scene/" 2>/dev/null || true
cp fuzz/corpus/exr/*.exr "$work/exr/"
mkdir -p "$work/pbrt" && cp fuzz/corpus/pbrt/*.pbrt "$work/pbrt/"  # seeds of fuzz_pbrt (pbrt import)
cp fuzz/corpus/pfm/* fuzz/corpus/hdr/* fuzz/corpus/png/* "$work/image/"

status=0
for target in scene exr pbrt image; do
  findings=build-fuzz/findings/$target
  mkdir -p "$findings"
  log=build-fuzz/fuzz_$target.log
  # Scenes up to 64 KB, so deep (item 7) and wide (item 8) inputs are reachable.
  max_len=""; [ "$target" = scene ] && max_len="-max_len=65536"
  # -timeout: one input taking over 10 s is a hang; -rss_limit_mb: a
  # runaway allocation is a finding too. ASan's leak check stays on.
  if build-fuzz/fuzz/fuzz_$target "$work/$target" -seed="$seed" -runs="$runs" -max_total_time="$seconds" \
       -timeout=10 -rss_limit_mb=2048 $max_len -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1; then
    done_runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo '?')
    secs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*' || echo "$seconds")
    capped=""
    [ "$runs" -gt 0 ] && [ "$done_runs" != "$runs" ] && capped=" (stopped by the ${seconds}-s cap before $runs: not a replayable run)"
    echo "fuzz.sh: fuzz_$target: ok, seed $seed, $done_runs inputs in ${secs} s$capped, coverage $cov edges, corpus $(ls "$work/$target" | wc -l) files"
  else
    status=1
    echo "fuzz.sh: fuzz_$target: FAILED (seed $seed); reproducer in $findings/, log $log:" >&2
    grep -E 'ERROR|SUMMARY|==[0-9]+==|Test unit written' "$log" | head -20 >&2 || tail -30 "$log" >&2
  fi
done
exit $status
