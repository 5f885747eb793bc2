#!/usr/bin/env bash
# The guided-denoising evaluation protocol in one command: Kodak 256×256 centre crops, Gaussian
# noise sigma 50/255 in random blobs over ~30 % of each image (protocol seed 2022), all five
# methods; plus the noise-map AUCs on procedural step/gradient images (sigma 50, 25, 15).
# JSON in build/bench/. CROP and METHODS size the `full` configuration for a CPU: it takes
# 4-5 minutes per DIP run at 64x64 on 2 quiet cores (S2S's 150k steps are a GPU job at any size):
#   scripts/eval-denoise.sh GLINT DATA 6 full 64 dip,guided-dip
#   scripts/eval-denoise.sh GLINT DATA [COUNT] [CONFIG] [CROP] [METHODS]
set -euo pipefail
USAGE="usage: eval-denoise.sh GLINT DATA [COUNT] [CONFIG] [CROP] [METHODS]"
GLINT=${1:?$USAGE}
DATA=${2:?$USAGE}
COUNT=${3:-8}
CONFIG=${4:-fast}
CROP=${5:-256}
METHODS=${6:-nlm,dip,guided-dip,s2s,guided-s2s}
OUT=build/bench
NAME=denoise-kodak-$CONFIG$([[ $CROP == 256 ]] || echo "-$CROP")
mkdir -p "$OUT"
"$GLINT" denoise eval --data "$DATA" --set kodak --count "$COUNT" --crop "$CROP" \
  --config "$CONFIG" --methods "$METHODS" --save "$OUT/$NAME" \
  --report "$OUT/$NAME.json"
for SIGMA in 50 25 15; do
  "$GLINT" denoise eval --set patterns --count 24 --methods none --sigma "$SIGMA" \
    --report "$OUT/denoise-patterns-sigma$SIGMA.json"
done
echo "eval-denoise: results in $OUT"
