#!/usr/bin/env bash
# Installs the Debian packages afmkit needs (only those missing; needs root or sudo) and builds it in build/.
# Usage: scripts/bootstrap.sh            (Release build, both cores)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake libeigen3-dev libcli11-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev
          libboost-dev libgtest-dev libbenchmark-dev libpng-dev pkg-config
          clang-14 libclang-rt-14-dev libomp-14-dev    # clang: libFuzzer targets (scripts/fuzz.sh)
          gwyddion    # gwyddion-thumbnailer: test_scan checks that Gwyddion opens the GSF / GXYZF files afmkit writes
          gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm   # the embedded filter core on a Cortex-M4F (MPS2)
          gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user       # … and on 64-bit ARM Linux (scripts/cross.sh)
          python3-dev pybind11-dev python3-numpy python3-matplotlib python3-pytest   # the Python module and its tests
          python3-xarray python3-zarr python3-distributed python3-netcdf4   # parameter studies (docs/study.md)
          chromium chromium-driver python3-selenium)                  # the report opened in headless Chromium
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
