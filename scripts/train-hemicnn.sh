#!/usr/bin/env bash
# Reproduces models/hemicnn.json (modified HemiCNN: parabolic hemi-images, lambda_d 0.1,
# lambda_l 0.3) and models/hemicnn-unmodified.json (Kim et al.: orthographic, lambda 1):
# renders glint's training set (2,000 sequences, seed 1), runs it through the pipeline's own
# observation collection into hemi-images, and trains both networks (seed 1, 30,000 batches
# of 32, Adam lr 1e-4). About 20 + 6 + 13 minutes on 2 cores (the two trainings run side by side, one core each;
# the set and its hemi-images take about 9 GB on disk, each training about 2.7 GB of memory).
#   scripts/train-hemicnn.sh GLINT DATA [WORK]
set -euo pipefail
GLINT=${1:?usage: train-hemicnn.sh GLINT DATA [WORK]}
DATA=${2:?usage: train-hemicnn.sh GLINT DATA [WORK]}
WORK=${3:-build/hemicnn-training}
MODELS=$(dirname "$0")/../models
mkdir -p "$WORK"
"$GLINT" synth training -o "$WORK/train" --sequences 2000 --seed 1 --data "$DATA"
[[ -f "$WORK/hemi/parabolic/index.json" ]] || "$GLINT" hemicnn dataset "$WORK/train" -o "$WORK/hemi"
"$GLINT" hemicnn train "$WORK/hemi/parabolic" -o "$MODELS/hemicnn.json" --batches 30000 \
  --seed 1 --report "$WORK/train-modified.json" &
"$GLINT" hemicnn train "$WORK/hemi/orthographic" -o "$MODELS/hemicnn-unmodified.json" \
  --lambda-d 1 --lambda-l 1 --batches 30000 --seed 1 --report "$WORK/train-unmodified.json" &
wait %1 %2
"$GLINT" hemicnn predict "$WORK/hemi/parabolic" --model "$MODELS/hemicnn.json" \
  --report "$WORK/predict-modified.json"
"$GLINT" hemicnn predict "$WORK/hemi/orthographic" --model "$MODELS/hemicnn-unmodified.json" \
  --report "$WORK/predict-unmodified.json"
