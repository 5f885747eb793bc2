#!/usr/bin/env bash
# Installs every Debian 12 package glint's build needs (idempotent: only what is missing).
# Usage: scripts/install-deps.sh [--peers | --fuzz]
#   --peers adds the comparison-only libraries for bench/, --fuzz the compiler and runtime of
#   `make fuzz` (clang 14 with libFuzzer and the sanitizer runtimes; make test does not need them).
# Blender (scripts/blender-render-glb.py, a benchmark step) is not installed here:
# apt-get install blender.
set -euo pipefail

packages=(
  build-essential cmake pkg-config python3
  libeigen3-dev libnanoflann-dev libtbb-dev
  # libtorch's CPU convolutions call BLAS; OpenBLAS (OpenMP-threaded, like libtorch) instead
  # of the reference BLAS makes the denoisers' U-Net several times faster.
  libtorch-dev libopenblas0-openmp
  libopencv-dev
  libpng-dev
  libembree-dev libtinyobjloader-dev
  # glTF scene export: mesh simplification.
  libmeshoptimizer-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # The Python module (python/) and its tests; matplotlib for examples/python.
  python3-dev python3-numpy python3-pybind11 pybind11-dev python3-pytest python3-matplotlib
  # OpenCASCADE: CAD-kernel training data and STEP input for BoundED (src/cad).
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev
  # ABC's feature files (YAML) for `glint edges label --abc-features`.
  libyaml-cpp-dev
  # make package: CPack's .deb finds its shared-library dependencies with dpkg-shlibdeps and file.
  dpkg-dev file
  # The optional MPI build (-DGLINT_WITH_MPI=ON) and the MPI test, which runs mpirun.
  libopenmpi-dev openmpi-bin
  # The viewer's browser test (ctest viewer.page_in_chromium) and scripts/compare-viewer.py:
  # headless Chromium driven by puppeteer-core (~115 MB to download, ~360 MB installed).
  chromium
)
if [[ "${1:-}" == "--peers" ]]; then
  # libopenmpi-dev: Debian's PCL loads VTK, whose CMake package needs MPI's C target.
  packages+=(libopen3d-dev libpcl-dev libcgal-dev libopenmpi-dev)
fi
if [[ "${1:-}" == "--fuzz" ]]; then
  packages+=(clang-14 libfuzzer-14-dev libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The web parts (three.js viewer, glTF validator, headless-browser checks) from web/'s lock file.
install_web() {
  local web
  web="$(dirname "$0")/../web"
  [[ -d "$web/node_modules" ]] && return 0
  command -v npm >/dev/null || { echo "install-deps: npm not found; the web checks will be skipped"; return 0; }
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error)
}

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  install_web
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_web
