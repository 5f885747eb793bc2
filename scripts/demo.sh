#!/usr/bin/env bash
# The main job on bundled data: classify a default-eval cloud (PLY + picture), then evaluate
# both shipped models beside the CA baseline on all of default-eval; then guided denoising of
# a Kodak crop; then the reflectance pipeline on a small synthetic scene.
#   scripts/demo.sh GLINT DATA
set -euo pipefail
GLINT=${1:?usage: demo.sh GLINT DATA}
DATA=${2:?usage: demo.sh GLINT DATA}
OUT=build/demo
EVAL="$DATA/pointclouds/default-eval"
if [[ ! -d "$EVAL" ]]; then
  echo "demo: $EVAL not found; pass DATA=/path/to/shared/data (or set GLINT_DATA)" >&2
  exit 1
fi
mkdir -p "$OUT"
"$GLINT" edges classify "$EVAL/CubeFractal2.ply" -o "$OUT/CubeFractal2-edges.ply" \
  --png "$OUT/CubeFractal2-edges.png" --report "$OUT/classify.json"
"$GLINT" edges eval "$EVAL" --model models/bounded-3c.json --model models/bounded-2c.json \
  --report "$OUT/eval-default.json"
"$GLINT" --quiet edges synth -o "$OUT/heldout" --count 8 --seed 1000
"$GLINT" edges classify "$OUT/heldout/$(ls "$OUT/heldout" | grep -m1 '\.ply$')" \
  -o "$OUT/heldout-edges.ply" --png "$OUT/heldout-edges.png"
"$GLINT" edges eval "$OUT/heldout" --task boundary --no-baseline
# Guided denoising: a Kodak crop with noise in random blobs; noise maps, NLM and guided S2S.
KODAK="$DATA/images/kodak/kodim23.png"
"$GLINT" denoise eval --images "$KODAK" --crop 128 --methods nlm,guided-s2s --save "$OUT/denoise" \
  --report "$OUT/denoise-eval.json"
"$GLINT" denoise noise-map "$OUT/denoise/kodim23-noisy.png" -o "$OUT/denoise/kodim23-guidance-cli.png"
# The reflectance pipeline on a small synthetic scene: the bunnies (60 frames at 256x212, direct
# light with shadows) and their low-exposure light capture, rendered on the fly; lights from the
# capture; then glint reconstruct with the true poses and its own segmentation.
BUNNIES="$OUT/reflectance/bunnies"
[[ -d "$BUNNIES" ]] || "$GLINT" --quiet synth bunnies -o "$BUNNIES" --frames 60 --width 256 \
  --data "$DATA"
[[ -d "$BUNNIES-capture" ]] || "$GLINT" --quiet synth lights --scene bunnies \
  -o "$BUNNIES-capture" --frames 40 --width 256 --data "$DATA"
"$GLINT" lights "$BUNNIES-capture" -o "$OUT/reflectance/lights.json"
"$GLINT" reconstruct "$BUNNIES" --lights "$OUT/reflectance/lights.json" --gt-poses \
  --render-every 20 -o "$OUT/reflectance/result" --report "$OUT/reflectance/report.json"
echo "demo: reflectance results in $OUT/reflectance/result: mesh.ply (per-vertex albedo and"
echo "      segment), materials.json, lights.json, materials-over-time.png, and"
echo "      frames/*-overview.png (input | re-rendering | refined albedo | segments)"
echo "demo: outputs in $OUT"
