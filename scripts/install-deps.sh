#!/usr/bin/env bash
# Installs the Debian 12 packages orthoface needs; does nothing for packages already present.
# Usage: scripts/install-deps.sh        (as root, or with sudo available)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev opencv-data libeigen3-dev libosmesa6-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev libtinygltf-dev libcli11-dev
  libv4l-dev v4l-utils libcamera-dev chromium
  libopenmpi-dev openmpi-bin
  assimp-utils
  libcgal-dev  # bench/analysis_bench only: exact geodesics as the accuracy reference
  libdlib-dev  # vision: the face detector of the input check; judge/: the real-photo judge
  libdlib-data  # judge/ only (benchmarks, tests): the judge's 68-point predictor
  opencv-doc  # bench/scene_bench only: its sample photographs are the real scenes behind sim heads
  clang-format  # scripts/run.sh test: every source as .clang-format says
  clang libclang-rt-14-dev  # scripts/run.sh fuzz: libFuzzer and the sanitizers of clang 14
  python3-dev python3-numpy python3-pybind11  # python/: the `import orthoface` module + tests
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
  "${missing[@]}"
