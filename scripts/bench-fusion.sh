#!/usr/bin/env bash
# glint fusion vs Open3D's VoxelBlockGrid (CPU) on 7-Scenes redkitchen (50 frames, ground-truth
# poses) at 5 mm and 1 cm voxels, plus glint with ICP tracking (ATE), and `glint fuse` end to end.
# Results: build/bench/fusion_bench.json, build/bench/fuse_7scenes*.json and the meshes.
#   scripts/bench-fusion.sh GLINT_BUILD DATA      (DATA: the shared data root, e.g. ../shared/data)
set -euo pipefail
BUILD=${1:?usage: bench-fusion.sh GLINT_BUILD DATA}
DATA=${2:?usage: bench-fusion.sh GLINT_BUILD DATA}
SEQ="$DATA/rgbd/7scenes-50"
OUT=build/bench
mkdir -p "$OUT/fusion-meshes"
if [[ ! -x "$BUILD/bench/fusion/fusion_bench" ]]; then
  echo "bench-fusion: $BUILD/bench/fusion/fusion_bench is missing (needs Open3D: libopen3d-dev)" >&2
  exit 1
fi
"$BUILD/bench/fusion/fusion_bench" --data "$SEQ" --voxels 0.005,0.01 \
  --meshes "$OUT/fusion-meshes" --json "$OUT/fusion_bench.json"
"$BUILD/apps/glint/glint" --quiet fuse "$SEQ" -o "$OUT/fusion-meshes/fuse_gt.ply" --gt-poses \
  --report "$OUT/fuse_7scenes_gt.json"
"$BUILD/apps/glint/glint" --quiet fuse "$SEQ" -o "$OUT/fusion-meshes/fuse_tracked.ply" \
  --trajectory "$OUT/fuse_7scenes_trajectory.txt" --report "$OUT/fuse_7scenes_tracked.json"
echo "bench-fusion: results in $OUT/fusion_bench.json and $OUT/fuse_7scenes_*.json"
