#!/usr/bin/env bash
# Reproduces the shipped BoundED models (models/bounded-3c.json, models/bounded-2c.json).
#   scripts/train-bounded.sh [GLINT] [DATA] [WORK]
# Batches hold the classes in equal numbers (--balance); the non-edge decision offset is then
# tuned on the 5 % validation split (never on evaluation data).
# Training data: 600 procedural clouds (seed 1; the shapes annulus and hemisphere are held
# out for the boundary evaluation) plus bazazian/edge-rule, whose labels follow the same
# one-point-wide band as the evaluation sets. Never trained on: the evaluation clouds and their
# twins (CubeFractal2, every Frac2* noisy variant, TwoPlane90). The 3-class model also skips the
# open-surface bazazian clouds (TwoPlane*, Two22plane14Noise, IntersectionThreePlanes), whose
# unlabelled borders would teach "boundary = non-edge".
set -euo pipefail
GLINT=${1:-build/release/apps/glint/glint}
DATA=${2:-${GLINT_DATA:-../shared/data}}
WORK=${3:-build/train}
BAZAZIAN="$DATA/pointclouds/bazazian/edge-rule"
TWINS=(--exclude CubeFractal2 --exclude Frac2 --exclude TwoPlane90)
NOTES="Trained on glint edges synth (seed 1, 600 clouds, shapes annulus and hemisphere held out) \
and bazazian/edge-rule without the default-eval twins (CubeFractal2, Frac2Guass*/Frac2withNoise*, \
TwoPlane90)"

"$GLINT" edges synth -o "$WORK/synth" --count 600 --seed 1 --exclude-shapes annulus,hemisphere
"$GLINT" edges train "$WORK/synth" "$BAZAZIAN" "${TWINS[@]}" \
  --exclude TwoPlane --exclude Two22plane --exclude IntersectionThreePlanes \
  --classes 3 --seed 1 --balance --notes "$NOTES; open-surface bazazian clouds left out" \
  -o models/bounded-3c.json --report "$WORK/train-3c.json"
"$GLINT" edges train "$WORK/synth" "$BAZAZIAN" "${TWINS[@]}" \
  --classes 2 --seed 1 --balance --notes "$NOTES" \
  -o models/bounded-2c.json --report "$WORK/train-2c.json"
