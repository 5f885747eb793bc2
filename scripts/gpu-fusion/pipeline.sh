#!/usr/bin/env bash
# The reflectance pipeline with TSDF integration on the GPU and on the CPU, on a GPU machine
# (glint and the libraries it lacks packed by pack.sh): renders a synthetic scene (300 frames,
# 512x424, no shadows) and its light capture once, estimates the lights, then runs `glint
# reconstruct` (ground-truth poses and segmentation) alternately with --device cuda and
# --device cpu: ROUNDS timing runs of each on 2 cores (taskset), one on all cores, and with
# EVAL=1 one of each scored at every 50th frame. Reports in OUT, a summary on stdout.
#   [GLINT_DATA=DATA] [EVAL=1] pipeline.sh DIR OUT SCENE [OBS_VOXEL_M] [ROUNDS]
# (from the repository root; bunnies and office need the meshes and textures of DATA)
set -uo pipefail
DIR=$(cd "${1:?usage: pipeline.sh DIR OUT SCENE [OBS_VOXEL_M] [ROUNDS]}" && pwd)
OUT=${2:?usage: pipeline.sh DIR OUT SCENE [OBS_VOXEL_M] [ROUNDS]}
SCENE=${3:?usage: pipeline.sh DIR OUT SCENE [OBS_VOXEL_M] [ROUNDS]}
VOXEL=${4:-0.02}
ROUNDS=${5:-2}
MODEL=${GLINT_MODEL:-models/hemicnn.json}
WORK=/tmp/glint-gpu-pipeline  # kept between calls: glint, the scenes, their lights
mkdir -p "$OUT" "$WORK"
[[ -x $WORK/glint/glint ]] || xz -dc "$DIR/glint.tar.xz" | tar -C "$WORK" -xf - || exit 1
export LD_LIBRARY_PATH=$WORK/glint${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
GLINT=$WORK/glint/glint
seq=$WORK/seq-$SCENE
lights=$WORK/lights-$SCENE.json
if [[ ! -f $lights ]]; then
  "$GLINT" --quiet synth "$SCENE" -o "$seq" --frames 300 --no-shadows || exit 1
  "$GLINT" --quiet synth lights --scene "$SCENE" -o "$WORK/capture-$SCENE" --frames 60 || exit 1
  "$GLINT" --quiet lights "$WORK/capture-$SCENE" -o "$lights" >/dev/null || exit 1
fi
reconstruct() {  # reconstruct NAME [taskset CPUS] -- ARGS...
  local name=$SCENE-$VOXEL-$1
  shift
  local prefix=()
  while [[ $1 != -- ]]; do prefix+=("$1"); shift; done
  shift
  "${prefix[@]}" "$GLINT" --quiet reconstruct "$seq" --lights "$lights" --gt-poses \
    --gt-segmentation --model "$MODEL" --obs-voxel "$VOXEL" --shadows off -o "$WORK/out" \
    --report "$OUT/$name.json" "$@" >/dev/null && echo "$name done"
}
for round in $(seq "$ROUNDS"); do
  for device in cuda cpu; do
    reconstruct "2cores-$device-$round" taskset -c 0,1 -- --device "$device" --eval-every 0 \
      --render-every 0
  done
done
for device in cuda cpu; do
  reconstruct "allcores-$device" -- --device "$device" --eval-every 0 --render-every 0
done
if [[ ${EVAL:-0} == 1 ]]; then
  for device in cuda cpu; do
    reconstruct "eval-$device" -- --device "$device" --eval-every 50
  done
fi
python3 - "$OUT" "$SCENE-$VOXEL-" <<'PY'
import json, pathlib, sys
for report in sorted(pathlib.Path(sys.argv[1]).glob(sys.argv[2] + "*.json")):
    r = json.load(open(report))
    t = r["timings_ms"]
    stages = " / ".join(f"{t[k]['median']:.1f}" for k in
                        ["geometry", "observations", "segmentation", "specular", "albedo"])
    line = f"{report.stem}: {stages}, total {t['total']['median']:.1f} ms"
    a = (r.get("evaluation") or {}).get("average")
    if a:
        line += "; L1 kd_ref {:.4f} ks {:.4f} alpha {:.4f}, refined RGB PSNR {:.2f} dB".format(
            a["kd_ref"]["l1"], a["ks"]["l1"], a["alpha"]["l1"], a["rgb_ref"]["psnr"])
    print(line)
PY
