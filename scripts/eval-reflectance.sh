#!/usr/bin/env bash
# The reflectance pipeline's evaluation (paper 1 §4, Tables 1-3, Figs 2 and 4) on glint's
# synthetic scenes: renders each scene (300 frames, 512x424, no shadows: the pipeline's image
# model has none) and its low-exposure light capture, estimates the lights (glint lights), then
# runs glint reconstruct with ground-truth poses:
#   - with ground-truth and with glint's own segmentation, at 2 cm observation voxels;
#   - with the paper's mean of the per-observation albedos instead of glint's median;
#   - with the HemiCNN's ks, alpha alone (the paper), without glint's lobe fit;
#   - with the modified (parabolic, lambda_d 0.1, lambda_l 0.3) and the unmodified
#     (orthographic, lambda 1) HemiCNN, ground-truth segmentation, both without the lobe fit;
#   - the same three with the networks trained on radiance hemi-images (paper 1's input)
#     instead of reflectance ones (glint's default: models/README.md);
#   - at 1 cm observation voxels (Table 3 timings);
#   - "fast": 1 cm geometry voxels instead of 5 mm (a CPU budget option, not the paper's).
# Every 10th frame (and the last) is scored; about 13 minutes on 2 cores for the three scenes
# once they are rendered. SCENES may also name "heldout" and "heldout-cubes": bunnies and cubes
# with materials no training choice was made on (scripts/heldout-scene.py), lit as their bases.
# VARIANT chooses the light transport the sequences are rendered with (the light captures are
# direct light with shadows in every variant):
#   noshadow (default) direct light without shadows, reconstructed with --shadows off (paper 1's
#                      image model, Table 1);
#   shadow             direct light with shadows;
#   bounceN            shadows and N bounces of path-traced indirect light (e.g. bounce3).
# OUT defaults to build/eval-reflectance, or build/eval-reflectance-VARIANT for the others; an
# OUT that already holds seq-SCENE and capture-SCENE is evaluated without rendering.
# Reports: OUT/<scene>-<variant>/report.json; a summary table: OUT/summary.md.
#   [VARIANT=shadow] scripts/eval-reflectance.sh GLINT DATA [OUT] [SCENES] [FRAMES]
set -euo pipefail
GLINT=${1:?usage: eval-reflectance.sh GLINT DATA [OUT] [SCENES] [FRAMES]}
DATA=${2:?usage: eval-reflectance.sh GLINT DATA [OUT] [SCENES] [FRAMES]}
VARIANT=${VARIANT:-noshadow}
case $VARIANT in
  noshadow) LIGHT_TRANSPORT=(--no-shadows) PIPELINE=(--shadows off --indirect off)
    DEFAULT_OUT=build/eval-reflectance ;;
  shadow) LIGHT_TRANSPORT=() PIPELINE=() DEFAULT_OUT=build/eval-reflectance-shadow ;;
  bounce[1-9] | bounce[1-9][0-9])
    LIGHT_TRANSPORT=(--bounces "${VARIANT#bounce}") PIPELINE=()
    DEFAULT_OUT=build/eval-reflectance-$VARIANT ;;
  *)
    echo "eval-reflectance.sh: VARIANT must be noshadow, shadow or bounceN, not '$VARIANT'" >&2
    exit 2
    ;;
esac
OUT=${3:-$DEFAULT_OUT}
SCENES=${4:-bunnies cubes office}
FRAMES=${5:-300}
MODELS=$(dirname "$0")/../models
mkdir -p "$OUT"
render_scene() {  # render_scene SCENE: OUT/seq-SCENE and OUT/capture-SCENE
  local scene=$1 seq="$OUT/seq-$1" cap="$OUT/capture-$1"
  if [[ $scene == heldout* ]]; then  # a built-in scene's geometry, lights, path; other materials
    [[ -d "$seq" ]] && return 0
    local base
    base=$(python3 "$(dirname "$0")/heldout-scene.py" base "$scene")
    render_scene "$base"
    python3 "$(dirname "$0")/heldout-scene.py" "$scene" "$OUT/seq-$base/scene.json" \
      "$OUT/$scene.json"
    "$GLINT" --quiet render "$OUT/$scene.json" -o "$seq" "${LIGHT_TRANSPORT[@]}"
    ln -sfn "capture-$base" "$cap"
    return 0
  fi
  [[ -d "$seq" ]] || "$GLINT" --quiet synth "$scene" -o "$seq" --frames "$FRAMES" \
    "${LIGHT_TRANSPORT[@]}" --data "$DATA"
  [[ -d "$cap" ]] || "$GLINT" --quiet synth lights --scene "$scene" -o "$cap" --frames 60 \
    --data "$DATA"
}
for scene in $SCENES; do
  seq="$OUT/seq-$scene"
  cap="$OUT/capture-$scene"
  render_scene "$scene"
  "$GLINT" --quiet lights "$cap" -o "$OUT/lights-$scene.json" --report "$OUT/lights-$scene-report.json"
  run() {  # run NAME ARGS...
    local name=$1
    shift
    [[ -f "$OUT/$scene-$name.json" ]] && return 0  # done in an earlier run
    "$GLINT" --quiet reconstruct "$seq" --lights "$OUT/lights-$scene.json" --gt-poses \
      -o "$OUT/$scene-$name" --report "$OUT/$scene-$name.json" "${PIPELINE[@]}" "$@" \
      > "$OUT/$scene-$name.txt"
  }
  run gtseg --gt-segmentation --model "$MODELS/hemicnn.json" --eval-every 10
  run ownseg --model "$MODELS/hemicnn.json" --eval-every 10
  run mean-albedo --gt-segmentation --model "$MODELS/hemicnn.json" --eval-every 10 \
    --albedo-average mean
  run hemicnn --gt-segmentation --model "$MODELS/hemicnn.json" --eval-every 10 \
    --specular hemicnn
  run unmodified --gt-segmentation --model "$MODELS/hemicnn-unmodified.json" --eval-every 10 \
    --specular hemicnn
  run radiance --gt-segmentation --model "$MODELS/hemicnn-radiance.json" --eval-every 10
  run hemicnn-radiance --gt-segmentation --model "$MODELS/hemicnn-radiance.json" \
    --eval-every 10 --specular hemicnn
  run unmodified-radiance --gt-segmentation --model "$MODELS/hemicnn-unmodified-radiance.json" \
    --eval-every 10 --specular hemicnn
  run gtseg-1cm --gt-segmentation --model "$MODELS/hemicnn.json" --obs-voxel 0.01 --eval-every 0
  run fast --gt-segmentation --model "$MODELS/hemicnn.json" --voxel 0.01 --eval-every 0
done
python3 "$(dirname "$0")/reflectance-summary.py" "$OUT" $SCENES > "$OUT/summary.md"
echo "eval-reflectance: reports in $OUT, summary in $OUT/summary.md"
