#!/usr/bin/env bash
# One-stop set-up for tdpm on Debian 12: installs the Debian packages that are
# missing, builds build/tdpm (Release), then either renders the default scene
# or runs every test. Idempotent: a second run installs nothing and rebuilds
# only what changed.
#
#   scripts/setup.sh render   # install + build + render scenes/glass-ball.json
#   scripts/setup.sh test     # install + build + a fixed-seed fuzzing run per target
#                             # (scripts/fuzz.sh) + all tests (CTest)
#   scripts/setup.sh build    # install + build only
set -euo pipefail

mode=${1:-render}
case "$mode" in
  render|test|build) ;;
  -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
  *) echo "setup.sh: unknown mode '$mode' (expected render, test or build)" >&2; exit 2 ;;
esac

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

packages=(g++ cmake make pkg-config
  libtbb-dev libembree-dev libxsimd-dev libopenexr-dev libpng-dev
  doctest-dev nlohmann-json3-dev libtinyobjloader-dev libcli11-dev
  libnanoflann-dev libbenchmark-dev openimageio-tools
  libopenmpi-dev openmpi-bin  # distributed rendering under mpirun (docs/distributed.md)
  libopenvdb-dev libnanovdb-dev libboost-iostreams-dev  # media density grid files (OpenVDB's headers need Boost)
  clang libclang-rt-14-dev)  # libFuzzer + sanitizer runtimes (scripts/fuzz.sh); only recommended by clang

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup.sh: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
# render needs only the executable (not the tests and benchmarks); test and
# build make everything.
if [ "$mode" = render ]; then
  cmake --build build -j "$jobs" --target tdpm
else
  cmake --build build -j "$jobs"
fi

case "$mode" in
  render)
    build/tdpm render scenes/glass-ball.json -o glass-ball.exr
    ;;
  test)
    # A short fuzzing run of the four loaders (scene, EXR, pbrt, PFM/HDR/PNG) with a fixed
    # seed and input count (CI does not fail by luck, a failure replays;
    # about 1.5 min with its clang build on 2 cores: 53 s of build and 29 s of fuzzing on a clean clone), first, so that
    # CTest's summary is the last thing printed.
    scripts/fuzz.sh --ci && echo "setup.sh: fuzzing: no findings" || { echo "setup.sh: fuzzing FAILED (see above)" >&2; exit 1; }
    (cd build && ctest --output-on-failure -j "$jobs")
    ;;
esac
