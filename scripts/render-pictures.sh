#!/usr/bin/env bash
# One frame of each built-in synthetic scene (and of the light-capture sequence and the first
# training sequence) as PNGs: rgb, depth (false colour), kd, ks, alpha in OUTDIR/<scene>/.
#   scripts/render-pictures.sh GLINT OUTDIR [DATA]      e.g. build/release/apps/glint/glint docs/render
set -euo pipefail
GLINT=${1:?usage: render-pictures.sh GLINT OUTDIR [DATA]}
OUT=${2:?usage: render-pictures.sh GLINT OUTDIR [DATA]}
DATA=${3:-${GLINT_DATA:-../shared/data}}
for scene in cubes bunnies office; do
  "$GLINT" synth "$scene" --preview --data "$DATA" -o "$OUT/$scene"
done
"$GLINT" synth lights --scene bunnies --preview --data "$DATA" -o "$OUT/lights-bunnies"
"$GLINT" synth training --preview --data "$DATA" --width 256 -o "$OUT/training-seq0"
echo "render-pictures: $(ls "$OUT"/*/*.png | wc -l) PNGs in $OUT"
