#!/usr/bin/env bash
# Installs the Debian 12 packages lumislab needs (only those missing) and builds it into build/.
# Usage: scripts/setup.sh [extra cmake args]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev nlohmann-json3-dev libcli11-dev libopenexr-dev
  libopencv-dev libceres-dev libgtest-dev
  # calibrate camera: ChArUco boards (OpenCV 4.6's aruco module)
  libopencv-contrib-dev
  libglfw3-dev libosmesa6-dev python3-glad libassimp-dev
  # lib/lightfield: the exact CPU reference's ray casting (Embree 3)
  libembree-dev
  # lib/photo: camera RAW and DNG (LibRaw), EXIF (libexif), PNG, JPEG and TIFF files (libpng,
  # libjpeg-turbo, libtiff; colour JPEGs decoded with their fractional codes)
  libraw-dev libexif-dev libtiff-dev libjpeg-dev libpng-dev zlib1g-dev
  # acquire: the gphoto2 camera driver (libgphoto2 over USB and PTP/IP)
  libgphoto2-dev
  # preview: the window's on-screen controls (Dear ImGui 1.86 with its GLFW and OpenGL 3 backends);
  # lib/lightfield: scene files' textures (stb_image)
  libimgui-dev libstb-dev
  # pipelines/Snakefile: batch conversion as a workflow that also runs on a cluster
  snakemake
  # tests/e2e/slurm_test.cc: the Slurm profile on a one-node cluster
  # (pipelines/slurm/local-cluster.sh: slurmctld, slurmd, the client commands, munge)
  slurm-wlm munge
  xvfb xauth x11-apps
  # scripts/test.sh's sanitizer and fuzz builds: clang 14, its sanitizer and libFuzzer
  # run-times, llvm-symbolizer for the stack traces (fuzz/README.md)
  clang libclang-rt-14-dev llvm
  # scripts/test.sh's format stage
  clang-format
  # the linker of every build here (scripts/test.sh's too): several times faster than ld.bfd,
  # and each build links about 70 executables
  lld
  # tests/export/independent_readers_test.cc: three.js's IESLoader runs under node; the
  # EULUMDAT and TM-25 layout readers (tests/export/readers/*.py) under python3
  nodejs python3
  # lumislab-export report --pdf, and the report's browser check (tests/export/report_test.cc):
  # headless Chromium prints the HTML to PDF and screenshots it
  chromium
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm: Debian's package, unless an npm is there already (a nodejs package from elsewhere that
# bundles its own npm conflicts with Debian's)
command -v npm >/dev/null 2>&1 || missing+=(npm)
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

jobs=$(nproc)
# Unity build: a library's sources compiled eight to a translation unit, so the heavy headers
# (OpenCV, Ceres, Eigen) are parsed once per batch, not once per file: a build from scratch,
# which is what CI pays twice, takes much less time. Pass -DCMAKE_UNITY_BUILD=OFF for file-by-file
# rebuilds while developing.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON \
  -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld "$@" >/dev/null
cmake --build build -j "$jobs"

# three.js (tests/export/readers/package.json, a pinned version) into build/npm for the
# independent IES reader test; without the npm registry the test installs it itself or skips,
# saying why.
mkdir -p build/npm
if ! cmp -s tests/export/readers/package.json build/npm/package.json ||
  [ ! -f build/npm/node_modules/three/examples/jsm/loaders/IESLoader.js ]; then
  cp tests/export/readers/package.json build/npm/package.json
  (cd build/npm && timeout 300 npm install --no-audit --no-fund >/dev/null 2>&1) ||
    echo "setup: npm could not install three into build/npm (registry not reachable?);" \
      "export.IndependentReaders.ThreeJsIesLoaderReadsEveryIesFile will try again or skip"
fi
