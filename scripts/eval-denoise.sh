#!/usr/bin/env bash
# The guided-denoising evaluation protocol in one command: Kodak 256×256 centre crops, Gaussian
# noise sigma 50/255 in random blobs over ~30 % of each image (protocol seed 2022), all five
# methods; plus the noise-map AUCs on procedural step/gradient images (sigma 50, 25, 15).
# JSON in build/bench/.
#   scripts/eval-denoise.sh GLINT DATA [COUNT] [CONFIG]
set -euo pipefail
GLINT=${1:?usage: eval-denoise.sh GLINT DATA [COUNT] [CONFIG]}
DATA=${2:?usage: eval-denoise.sh GLINT DATA [COUNT] [CONFIG]}
COUNT=${3:-8}
CONFIG=${4:-fast}
OUT=build/bench
mkdir -p "$OUT"
"$GLINT" denoise eval --data "$DATA" --set kodak --count "$COUNT" --crop 256 --config "$CONFIG" \
  --save "$OUT/denoise-kodak-$CONFIG" --report "$OUT/denoise-kodak-$CONFIG.json"
for SIGMA in 50 25 15; do
  "$GLINT" denoise eval --set patterns --count 24 --methods none --sigma "$SIGMA" \
    --report "$OUT/denoise-patterns-sigma$SIGMA.json"
done
echo "eval-denoise: results in $OUT"
