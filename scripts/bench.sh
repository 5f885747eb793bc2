#!/usr/bin/env bash
# Runs every benchmark program and collects their JSON in build/bench/.
#   scripts/bench.sh BUILD DATA
set -euo pipefail
BUILD=${1:?usage: bench.sh BUILD DATA}
DATA=${2:?usage: bench.sh BUILD DATA}
OUT=build/bench
mkdir -p "$OUT"
"$BUILD/bench/edges/edges_throughput" --points 1000000 --repeat 3 --model models/bounded-3c.json \
  --data "$DATA" --json "$OUT/edges_throughput.json"
# The 2-class model weighs neighbours by area: one more (small-k) pass before the features.
"$BUILD/bench/edges/edges_throughput" --points 1000000 --repeat 3 --model models/bounded-2c.json \
  --data "$DATA" --json "$OUT/edges_throughput_2c.json"
# The PCL / Open3D boundary peers, where they were built (scripts/install-deps.sh --peers).
if [[ -x "$BUILD/bench/edges/boundary_peers" ]]; then
  "$BUILD/bench/edges/boundary_peers" "$DATA/pointclouds/default-eval" "$DATA/pointclouds/shrec19" \
    --json "$OUT/boundary_peers.json" >/dev/null
fi
"$BUILD/bench/denoise/denoise_speed" --json "$OUT/denoise_speed.json"
"$BUILD/bench/render/render_speed" --data "$DATA" --threads 2 --json "$OUT/render_speed.json"
"$BUILD/bench/reflectance/reflectance_kernels" --benchmark_out="$OUT/reflectance_kernels.json" \
  --benchmark_out_format=json
"$BUILD/bench/fusion/fusion_kernels" --benchmark_repetitions=5 \
  --benchmark_out="$OUT/fusion_kernels.json" --benchmark_out_format=json
echo "bench: results in $OUT (the reflectance pipeline: scripts/eval-reflectance.sh; the denoising protocol: scripts/eval-denoise.sh)"
