#!/usr/bin/env bash
# Shadows and interreflections in the reflectance pipeline (reflectance/light_transport.h).
# Renders each scene three ways (FRAMES frames, 512x424):
#   a  direct light without shadows (the input of eval-reflectance.sh),
#   b  direct light with shadows (the renderer's default),
#   c  shadows and BOUNCES bounces of indirect light (`glint synth --bounces`; skipped where the
#      binary has no such option and OUT/seq-SCENE-c is not there already),
# estimates the lights once per scene from its light capture (glint lights), and reconstructs
# each rendering with glint's own segmentation, ground-truth poses and 2 cm observation voxels,
# scored every 10th frame against the ground truth:
#   before    --shadows off --indirect off (the paper's image model),
#   after     --shadows on --shadow-test off --indirect off (shadow rays alone),
#   indirect  the same with --indirect on --indirect-scale off (the gather as it is),
#   scaled    the same with --indirect on --indirect-scale on (the gather scaled by what the
#             voxels no light reaches show),
#   tested    --shadows on --shadow-test on --indirect on --indirect-scale on (the scaled gather
#             and the shadow test),
#   glossy    the same with --indirect-specular sky (the gathered light mirrored by the lobe as
#             an even sky),
#   mirror    the same with --indirect-specular mirror (the lobe mirrors what its rays meet),
#   shrinkage the defaults: the same with --albedo-shrinkage on (the refined albedo pulled
#             towards its segment's by the gather's error),
# (the variants with the gather but not the lobe's reflection: --indirect-specular off; those
# with the gather before shrinkage: --albedo-shrinkage off),
#   before-unseen  --indirect off --unseen-light on,
#   unseen    --shadows on --shadow-test off --indirect off --unseen-light on,
#   indirect-unseen  the same with --indirect on --indirect-scale off,
# plus, for the timing tables, the defaults on each rendering b at 1 cm and 2 cm with
# ground-truth segmentation (TIMING_SCENES). Reports: OUT/<scene>-<render>-<variant>.json;
# summary: OUT/summary.md (scripts/light-transport-summary.py).
#   scripts/eval-light-transport.sh GLINT DATA [OUT] [SCENES] [FRAMES] [TIMING_SCENES]
set -euo pipefail
GLINT=${1:?usage: eval-light-transport.sh GLINT DATA [OUT] [SCENES] [FRAMES] [TIMING_SCENES]}
DATA=${2:?usage: eval-light-transport.sh GLINT DATA [OUT] [SCENES] [FRAMES] [TIMING_SCENES]}
OUT=${3:-build/eval-light-transport}
SCENES=${4:-bunnies office}
FRAMES=${5:-300}
TIMING_SCENES=${6:-cubes bunnies office}
BOUNCES=${BOUNCES:-3}
MODEL=$(dirname "$0")/../models/hemicnn.json
mkdir -p "$OUT"
render() {  # render SCENE R: OUT/seq-SCENE-R
  local scene=$1 r=$2 seq="$OUT/seq-$1-$2"
  [[ -d "$seq" ]] && return 0
  case $r in
    a) "$GLINT" --quiet synth "$scene" -o "$seq" --frames "$FRAMES" --no-shadows --data "$DATA" ;;
    b) "$GLINT" --quiet synth "$scene" -o "$seq" --frames "$FRAMES" --data "$DATA" ;;
    c) if "$GLINT" synth --help | grep -q -- --bounces; then
         "$GLINT" --quiet synth "$scene" -o "$seq" --frames "$FRAMES" --bounces "$BOUNCES" \
           --data "$DATA"
       else
         echo "eval-light-transport: $GLINT has no synth --bounces; skipping $seq" >&2
         return 1
       fi ;;
  esac
}
lights() {  # lights SCENE: OUT/lights-SCENE.json
  local scene=$1
  [[ -d "$OUT/capture-$scene" ]] ||
    "$GLINT" --quiet synth lights --scene "$scene" -o "$OUT/capture-$scene" --frames 60 \
      --data "$DATA"
  [[ -f "$OUT/lights-$scene.json" ]] ||
    "$GLINT" --quiet lights "$OUT/capture-$scene" -o "$OUT/lights-$scene.json"
}
reconstruct() {  # reconstruct SCENE R NAME ARGS...
  local scene=$1 r=$2 name=$3
  shift 3
  [[ -f "$OUT/$scene-$r-$name.json" ]] && return 0  # done in an earlier run
  "$GLINT" --quiet reconstruct "$OUT/seq-$scene-$r" --lights "$OUT/lights-$scene.json" \
    --gt-poses --model "$MODEL" -o "$OUT/$scene-$r-$name" --report "$OUT/$scene-$r-$name.json" \
    "$@" > "$OUT/$scene-$r-$name.txt"
}
for scene in $SCENES; do
  lights "$scene"
  for r in a b c; do
    render "$scene" "$r" || continue
    reconstruct "$scene" "$r" before --shadows off --indirect off --eval-every 10
    reconstruct "$scene" "$r" after --shadows on --shadow-test off --indirect off --eval-every 10
    reconstruct "$scene" "$r" indirect --shadows on --shadow-test off --indirect on \
      --indirect-scale off --indirect-specular off --albedo-shrinkage off --eval-every 10
    reconstruct "$scene" "$r" scaled --shadows on --shadow-test off --indirect on \
      --indirect-scale on --indirect-specular off --albedo-shrinkage off --eval-every 10
    reconstruct "$scene" "$r" tested --shadows on --shadow-test on --indirect on \
      --indirect-scale on --indirect-specular off --albedo-shrinkage off --eval-every 10
    reconstruct "$scene" "$r" glossy --shadows on --shadow-test on --indirect on \
      --indirect-scale on --indirect-specular sky --albedo-shrinkage off --eval-every 10
    reconstruct "$scene" "$r" mirror --shadows on --shadow-test on --indirect on \
      --indirect-scale on --indirect-specular mirror --albedo-shrinkage off --eval-every 10
    reconstruct "$scene" "$r" shrinkage --shadows on --shadow-test on --indirect on \
      --indirect-scale on --indirect-specular mirror --albedo-shrinkage on --eval-every 10
    reconstruct "$scene" "$r" before-unseen --shadows off --indirect off --unseen-light on \
      --eval-every 10
    reconstruct "$scene" "$r" unseen --shadows on --shadow-test off --indirect off \
      --unseen-light on --eval-every 10
    reconstruct "$scene" "$r" indirect-unseen --shadows on --shadow-test off --indirect on \
      --indirect-scale off --indirect-specular off --albedo-shrinkage off --unseen-light on \
      --eval-every 10
  done
done
for scene in $TIMING_SCENES; do
  lights "$scene"
  render "$scene" b
  reconstruct "$scene" b timing-2cm --gt-segmentation --eval-every 0
  reconstruct "$scene" b timing-1cm --gt-segmentation --obs-voxel 0.01 --eval-every 0
done
python3 "$(dirname "$0")/light-transport-summary.py" "$OUT" > "$OUT/summary.md"
echo "eval-light-transport: reports in $OUT, summary in $OUT/summary.md"
