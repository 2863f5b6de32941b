#!/usr/bin/env bash
# Installs the Debian packages afmkit needs (only those missing; needs root or sudo) and builds it in build/.
# Usage: scripts/bootstrap.sh          the main job: the library, the `afmkit` program and the Python module
#                                      (what `afmkit report` needs), with only the packages those need
#        scripts/bootstrap.sh --all    everything: also the packages of the tests (GoogleTest programs, pytest,
#                                      Chromium, Gwyddion, the ARM tool chains, clang for fuzzing, Dask/xarray/Zarr,
#                                      Jupyter's nbconvert + ipykernel for the example notebooks)
#                                      and every target (test programs, benchmarks): what the test command needs
#        --packages                    with either: install the packages, build nothing
# Builds with Ninja and ccache (Debian packages, installed here) in Release; docs/development.md gives the times.
set -euo pipefail
cd "$(dirname "$0")/.."
all=0
build=1
for arg in "$@"; do
  case "$arg" in
    --all) all=1 ;;
    --packages) build=0 ;;   # install the packages only (CI times that stage on its own)
    *) echo "bootstrap.sh: unknown option '$arg' (none: the main job; --all: everything, for the tests;" \
            "--packages: install only)" >&2; exit 2 ;;
  esac
done

# The main job. GoogleTest and Google Benchmark are small and let CMake configure the same tree in both modes.
packages=(build-essential cmake ninja-build ccache pkg-config
          libeigen3-dev libcli11-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev libboost-dev libpng-dev libzip-dev
          libgtest-dev libbenchmark-dev
          python3-dev pybind11-dev python3-numpy python3-matplotlib)   # the Python module and the report
if [ "$all" = 1 ]; then
  packages+=(python3-pytest
             python3-nbconvert python3-ipykernel         # tests/python/test_notebooks.py runs examples/notebooks/
             clang-14 libclang-rt-14-dev libomp-14-dev    # clang: libFuzzer targets (scripts/fuzz.sh)
             gwyddion    # gwyddion-thumbnailer: test_scan checks that Gwyddion opens the GSF / GXYZF files afmkit writes
             gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm   # the embedded filter core on a Cortex-M4F (MPS2)
             gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user       # … and on 64-bit ARM Linux (scripts/cross.sh)
             python3-xarray python3-zarr python3-distributed python3-netcdf4   # parameter studies (docs/study.md)
             python3-dask python3-fsspec python3-pandas                 # … what those recommend and studies use
             chromium chromium-driver python3-selenium)                  # the report opened in headless Chromium
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

[ "$build" = 1 ] || exit 0
# A new tree uses Ninja; a tree configured before keeps its generator (CMake refuses to switch).
generator=()
[ -f build/CMakeCache.txt ] || generator=(-G Ninja)
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ "$all" = 1 ]; then
  cmake --build build -j"$(nproc)"
else
  cmake --build build -j"$(nproc)" --target afmkit_main   # the program and the Python module
fi
