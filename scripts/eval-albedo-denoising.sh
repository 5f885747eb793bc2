#!/usr/bin/env bash
# The kd atlas with and without --denoise-albedo against the ground truth (docs/benchmarks.md,
# "Albedo atlas denoising"). Per scene: the shadowless rendering (FRAMES frames, the paper's
# image model), lights estimated from the scene's light capture, a reconstruction with
# ground-truth poses and the defaults, then `glint export --denoise-albedo --albedo-truth`, whose
# report holds the atlas's kd L1 / PSNR before and after, for well-observed (>= 15 stored
# observations) and poorly observed texels. Reports: OUT/<scene>-export.json.
#   scripts/eval-albedo-denoising.sh GLINT DATA [OUT] [SCENES] [FRAMES]
set -euo pipefail
GLINT=${1:?usage: eval-albedo-denoising.sh GLINT DATA [OUT] [SCENES] [FRAMES]}
DATA=${2:?usage: eval-albedo-denoising.sh GLINT DATA [OUT] [SCENES] [FRAMES]}
OUT=${3:-build/eval-albedo-denoising}
SCENES=${4:-bunnies office}
FRAMES=${5:-100}
mkdir -p "$OUT"
for scene in $SCENES; do
  [[ -d "$OUT/seq-$scene" ]] ||
    "$GLINT" --quiet synth "$scene" -o "$OUT/seq-$scene" --frames "$FRAMES" --no-shadows --data "$DATA"
  [[ -d "$OUT/capture-$scene" ]] ||
    "$GLINT" --quiet synth lights --scene "$scene" -o "$OUT/capture-$scene" --frames 60 --data "$DATA"
  [[ -f "$OUT/lights-$scene.json" ]] ||
    "$GLINT" --quiet lights "$OUT/capture-$scene" -o "$OUT/lights-$scene.json"
  [[ -f "$OUT/$scene/materials.json" ]] ||
    "$GLINT" --quiet reconstruct "$OUT/seq-$scene" --lights "$OUT/lights-$scene.json" --gt-poses \
      --shadows off --indirect off -o "$OUT/$scene" --report "$OUT/$scene-reconstruct.json"
  [[ -f "$OUT/$scene-export.json" ]] ||
    "$GLINT" export "$OUT/$scene" -o "$OUT/$scene-denoised.glb" --denoise-albedo \
      --albedo-truth "$OUT/seq-$scene" --report "$OUT/$scene-export.json"
done
