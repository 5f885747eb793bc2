#!/usr/bin/env bash
# Gathers what the CUDA integration checks need on a GPU machine that has a CUDA driver but none
# of glint's Debian packages (a lent device machine, for example): the CUDA
# integrator's tests and the fusion kernel benchmark from a GLINT_WITH_CUDA build, and the
# shared libraries they load beyond the C and C++ runtimes (for run.sh). Given a list of the
# sonames the GPU machine lacks (ldconfig -p there), also glint itself with those of its
# libraries, as DIR/glint.tar.xz (for pipeline.sh).
#   cmake --preset cuda && cmake --build build/cuda
#   scripts/gpu-fusion/pack.sh build/cuda DIR [MISSING_SONAMES]
set -euo pipefail
BUILD=${1:?usage: pack.sh BUILD DIR [MISSING_SONAMES]}
DIR=${2:?usage: pack.sh BUILD DIR [MISSING_SONAMES]}
MISSING=${3:-}
HERE=$(dirname "$0")
mkdir -p "$DIR"
programs=("$BUILD/tests/glint_fusion_cuda_tests" "$BUILD/bench/fusion/fusion_kernels")
cp "${programs[@]}" "$HERE/run.sh" "$HERE/pipeline.sh" "$DIR/"
ldd "${programs[@]}" | awk '/=> \// {print $3}' | sort -u |
  grep -v -E '/(libc|libm|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so' |
  while read -r library; do cp -L "$library" "$DIR/"; done
if [[ -n "$MISSING" ]]; then
  STAGE=$(mktemp -d)
  mkdir "$STAGE/glint"
  cp "$BUILD/apps/glint/glint" "$STAGE/glint/"
  ldd "$BUILD/apps/glint/glint" | awk '/=> \// {print $1, $3}' |
    while read -r soname library; do
      if grep -qx "$soname" "$MISSING"; then cp -L "$library" "$STAGE/glint/"; fi
    done
  tar -C "$STAGE" -cf - glint | xz -T2 -9 >"$DIR/glint.tar.xz"
  rm -rf "$STAGE"
fi
du -sh "$DIR"
