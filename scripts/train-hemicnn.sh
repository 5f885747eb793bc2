#!/usr/bin/env bash
# Reproduces the four shipped HemiCNN models from glint's rendered training set (2,000
# sequences, seed 1), run through the pipeline's own observation collection into hemi-images:
#   models/hemicnn.json                     modified (paper 1: parabolic, lambda_d 0.1,
#                                           lambda_l 0.3) on reflectance hemi-images (the default)
#   models/hemicnn-unmodified.json          unmodified (Kim et al.: orthographic, lambda 1),
#                                           reflectance hemi-images
#   models/hemicnn-radiance.json            modified, on radiance hemi-images (paper 1's input)
#   models/hemicnn-unmodified-radiance.json unmodified, on radiance hemi-images (Kim et al.)
# Each training: 30,000 batches of 32 sets, Adam lr 1e-4, seed 1, one core. About 11 + 3 + 2 x
# (8 to 13) minutes on 2 cores (rendering, hemi-images, then two pairs of trainings side by side,
# one core each); the set and its hemi-images take about 13 GB on disk, each training about
# 2.7 GB of memory. Each network's validation errors go to WORK/predict-*.json, and the
# reflectance networks' answers for matte greys and colours (glint hemicnn probe) to
# WORK/probe-*.json.
#   scripts/train-hemicnn.sh GLINT DATA [WORK]
set -euo pipefail
GLINT=${1:?usage: train-hemicnn.sh GLINT DATA [WORK]}
DATA=${2:?usage: train-hemicnn.sh GLINT DATA [WORK]}
WORK=${3:-build/hemicnn-training}
MODELS=$(dirname "$0")/../models
mkdir -p "$WORK"
"$GLINT" synth training -o "$WORK/train" --sequences 2000 --seed 1 --data "$DATA"
[[ -f "$WORK/hemi/parabolic-reflectance/index.json" ]] ||
  "$GLINT" hemicnn dataset "$WORK/train" -o "$WORK/hemi"
for input in reflectance radiance; do
  case $input in  # dataset folder and model file suffixes
    reflectance) folder=-reflectance suffix= ;;
    radiance) folder= suffix=-radiance ;;
  esac
  "$GLINT" hemicnn train "$WORK/hemi/parabolic$folder" -o "$MODELS/hemicnn$suffix.json" \
    --batches 30000 --seed 1 --report "$WORK/train-modified$suffix.json" &
  "$GLINT" hemicnn train "$WORK/hemi/orthographic$folder" \
    -o "$MODELS/hemicnn-unmodified$suffix.json" --lambda-d 1 --lambda-l 1 --batches 30000 \
    --seed 1 --report "$WORK/train-unmodified$suffix.json" &
  wait
  "$GLINT" hemicnn predict "$WORK/hemi/parabolic$folder" --model "$MODELS/hemicnn$suffix.json" \
    --report "$WORK/predict-modified$suffix.json"
  "$GLINT" hemicnn predict "$WORK/hemi/orthographic$folder" \
    --model "$MODELS/hemicnn-unmodified$suffix.json" \
    --report "$WORK/predict-unmodified$suffix.json"
  if [[ $input == reflectance ]]; then  # the networks' kd for matte greys and colours
    "$GLINT" hemicnn probe --model "$MODELS/hemicnn.json" --report "$WORK/probe-modified.json"
    "$GLINT" hemicnn probe --model "$MODELS/hemicnn-unmodified.json" \
      --report "$WORK/probe-unmodified.json"
  fi
done
