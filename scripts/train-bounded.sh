#!/usr/bin/env bash
# Reproduces the shipped BoundED models (models/bounded-3c.json, models/bounded-2c.json).
#   scripts/train-bounded.sh [GLINT] [DATA] [WORK]
# Training data (never the evaluation clouds or their twins):
#   * 300 CAD-kernel clouds (glint edges synth --kind cad, seed 101; the recipe `cylinder` is
#     held out for the evaluation), sampled at mesh vertices, uniformly and scan-like, 20 % cut
#     open by a plane and 15 % with faces removed, noise up to 1 spacing along the normal;
#   * bazazian/edge-rule without the default-eval twins (CubeFractal2, every Frac2* noisy
#     variant, TwoPlane90). The 3-class model also skips the open-surface bazazian clouds
#     (TwoPlane*, Two22plane14Noise, IntersectionThreePlanes), whose unlabelled borders would
#     teach "boundary = non-edge".
# The 3-class model takes the angular gap as a thirteenth input per scale (--angular-gap,
# docs/decisions.md "The angular gap as a thirteenth input of the 3-class model"); the 2-class
# model keeps the thesis's twelve, with neighbours weighed by area (--area-weights,
# docs/decisions.md "Area-weighted neighbourhoods").
# The procedural shapes of `glint edges synth` are left out: with them the CAD validation score
# below was lower (docs/decisions.md, "BoundED trains on CAD-kernel parts, not procedural shapes").
# Each model is trained with seeds 1, 2 and 3 (two trainings at a time), and so is a low-noise
# network on the clean CAD clouds alone, for the noise gate; batches hold the classes in equal
# numbers (--balance) and the non-edge decision offset is tuned on the 5 % validation split.
# Which seed ships, and whether the new models replace the old ones, is decided by
# scripts/select-bounded.py on the validation split and on a CAD validation set (seed 5001,
# disjoint from the training seed 101 and the evaluation seed 9001), by the rule written in
# models/README.md before the first training; never on default-eval or shrec19.
# scripts/select-noise-gate.py then pairs the chosen network with a low-noise one
# (`glint edges gate`) by the rule of models/README.md, "The noise gate", and
# scripts/select-sampling-gate.py with a network trained on mesh-vertex clouds alone (300 more
# parts, seed 102), behind the sampling gate, by the rule of models/README.md, "The sampling
# gate", on decision sets of seed 5301: the shipped 3-class model is such a pair.
# scripts/select-clean-vertex-gate.py gives the pair's mesh-vertex network a noise gate with an
# area-weighted low-noise network by the rule of models/README.md, "The low-noise mesh-vertex
# network": the opt-in models/bounded-3c-cad-vertices.json is that chain.
set -euo pipefail
GLINT=${1:-build/release/apps/glint/glint}
DATA=${2:-${GLINT_DATA:-../shared/data}}
WORK=${3:-build/train}
SEEDS=${SEEDS:-"1 2 3"}
BAZAZIAN="$DATA/pointclouds/bazazian/edge-rule"
TWINS=(--exclude CubeFractal2 --exclude Frac2 --exclude TwoPlane90)
OPEN_SURFACES=(--exclude TwoPlane --exclude Two22plane --exclude IntersectionThreePlanes)
NOTES="Trained on glint edges synth --kind cad (seed 101, 300 clouds, recipe cylinder held out) \
and bazazian/edge-rule without the default-eval twins (CubeFractal2, Frac2Guass*/Frac2withNoise*, \
TwoPlane90)"
NICE=(nice -n 10)

mkdir -p "$WORK/models"
[[ -f "$WORK/cad/manifest.json" ]] ||
  "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad" --count 300 --seed 101 \
    --recipes block,plate,extrusion,turned --plane-cut 0.2 --faces-removed 0.15 \
    --noise 0,0,0.25,0.5,1 --min-points 3000 --max-points 30000

train() {  # name classes seed notes data-and-excludes...
  local name=$1 classes=$2 seed=$3 notes=$4
  shift 4
  "${NICE[@]}" "$GLINT" --quiet edges train "$@" --classes "$classes" --seed "$seed" --balance \
    --notes "$notes" -o "$WORK/models/$name.json" --report "$WORK/models/train-$name.json" \
    > "$WORK/models/train-$name.log" 2>&1
}
DATA_3C=("$WORK/cad" "$BAZAZIAN" "${TWINS[@]}" "${OPEN_SURFACES[@]}" --angular-gap)
DATA_2C=("$WORK/cad" "$BAZAZIAN" "${TWINS[@]}" --area-weights)
for seed in $SEEDS; do
  [[ -f "$WORK/models/bounded-3c-s$seed.json" ]] ||
    train "bounded-3c-s$seed" 3 "$seed" "$NOTES" "${DATA_3C[@]}" &
  [[ -f "$WORK/models/bounded-2c-s$seed.json" ]] ||
    train "bounded-2c-s$seed" 2 "$seed" "$NOTES" "${DATA_2C[@]}" &
  wait
done

# With AREA_WEIGHTS=1 also the 3-class model with area-weighted neighbourhoods (docs/decisions.md
# "Area-weighted neighbourhoods"), seeds 1, 2 and 3, for scripts/eval-bounded-cad.sh; they are
# not candidates of the selection below.
if [[ ${AREA_WEIGHTS:-0} == 1 ]]; then
  for seed in $SEEDS; do
    [[ -f "$WORK/models/bounded-3c-area-s$seed.json" ]] ||
      train "bounded-3c-area-s$seed" 3 "$seed" "$NOTES" "${DATA_3C[@]}" --area-weights
  done
fi

# 300 more parts (seed 102) sampled only at mesh vertices: with the mesh-vertex clouds of the
# first set, the training data of the sampling gate's networks (below).
[[ -f "$WORK/cad-vertices/manifest.json" ]] ||
  "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad-vertices" --count 300 --seed 102 \
    --recipes block,plate,extrusion,turned --plane-cut 0.2 --faces-removed 0.15 \
    --noise 0,0,0.25,0.5,1 --min-points 3000 --max-points 30000 --sampling vertices

# With MESH_VERTICES=1 also both models trained on those parts beside their own data
# (docs/decisions.md "More mesh-vertex clouds in training"), seeds 1, 2 and 3, for
# scripts/eval-bounded-cad.sh; they are not candidates of the selection.
if [[ ${MESH_VERTICES:-0} == 1 ]]; then
  VERTEX_NOTES="$NOTES; plus 300 clouds of seed 102 sampled at mesh vertices"
  for seed in $SEEDS; do
    [[ -f "$WORK/models/bounded-3c-vertices-s$seed.json" ]] ||
      train "bounded-3c-vertices-s$seed" 3 "$seed" "$VERTEX_NOTES" "$WORK/cad" \
        "$WORK/cad-vertices" "${DATA_3C[@]:1}" &
    [[ -f "$WORK/models/bounded-2c-vertices-s$seed.json" ]] ||
      train "bounded-2c-vertices-s$seed" 2 "$seed" "$VERTEX_NOTES" "$WORK/cad" \
        "$WORK/cad-vertices" "${DATA_2C[@]:1}" &
    wait
  done
fi

# The low-noise networks of the noise gate: the clean CAD parts alone (noise 0; the bazazian
# clouds are left out, docs/decisions.md "The noise gate: built, not shipped").
mapfile -t CLEAN < <(/usr/bin/python3 -c '
import json, sys
folder = sys.argv[1]
for cloud in json.load(open(folder + "/manifest.json"))["clouds"]:
    if cloud["noise_spacings"] == 0: print(folder + "/" + cloud["file"])' "$WORK/cad")
CLEAN_NOTES="Low-noise network: the clean clouds (noise 0) of glint edges synth --kind cad \
(seed 101, 300 clouds, recipe cylinder held out)"
for seed in $SEEDS; do
  for classes in 3 2; do
    name="bounded-${classes}c-clean-s$seed"
    inputs=(--area-weights)  # a gated pair's networks take the same features
    [[ $classes == 3 ]] && inputs=(--angular-gap)
    [[ -f "$WORK/models/$name.json" ]] ||
      train "$name" "$classes" "$seed" "$CLEAN_NOTES" "${CLEAN[@]}" "${inputs[@]}" &
  done
  wait
done

# The mesh-vertex networks of the sampling gate: mesh-vertex clouds alone, every noise level (the
# bazazian clouds are left out; docs/decisions.md "The sampling gate").
mapfile -t VERTEX_CLOUDS < <(/usr/bin/python3 -c '
import json, sys
folder = sys.argv[1]
for cloud in json.load(open(folder + "/manifest.json"))["clouds"]:
    if cloud["sampling"] == "vertices": print(folder + "/" + cloud["file"])' "$WORK/cad")
MESH_VERTEX_NOTES="Mesh-vertex network: the mesh-vertex clouds of glint edges synth --kind cad \
(seed 101) and 300 clouds of seed 102 sampled at mesh vertices"
for seed in $SEEDS; do
  for classes in 3 2; do
    name="bounded-${classes}c-mesh-vertex-s$seed"
    inputs=(--area-weights)
    [[ $classes == 3 ]] && inputs=(--angular-gap)
    [[ -f "$WORK/models/$name.json" ]] ||
      train "$name" "$classes" "$seed" "$MESH_VERTEX_NOTES" "${VERTEX_CLOUDS[@]}" \
        "$WORK/cad-vertices" "${inputs[@]}" &
  done
  wait
done

# The low-noise network behind the mesh-vertex network's noise gate: the 3-class mesh-vertex
# network's data and inputs with neighbours weighed by area (docs/decisions.md "A low-noise
# area-weighted network for clean mesh-vertex clouds").
for seed in $SEEDS; do
  name="bounded-3c-mesh-vertex-area-s$seed"
  [[ -f "$WORK/models/$name.json" ]] ||
    train "$name" 3 "$seed" "$MESH_VERTEX_NOTES; area-weighted neighbourhoods" \
      "${VERTEX_CLOUDS[@]}" "$WORK/cad-vertices" --angular-gap --area-weights
done

# The CAD validation set of the selection rule (seed 5001: neither trained on nor evaluated).
[[ -f "$WORK/cad-val/manifest.json" ]] ||
  "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad-val" --count 40 --seed 5001 \
    --sampling vertices,uniform --noise 0,0.5,1 --min-points 4000 --max-points 40000
[[ -f "$WORK/cad-val-cut/manifest.json" ]] ||
  "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad-val-cut" --count 40 --seed 5001 \
    --sampling vertices,uniform --noise 0,0.5,1 --plane-cut 1 --min-points 4000 --max-points 40000
/usr/bin/python3 "$(dirname "$0")/select-bounded.py" "$GLINT" "$WORK" models
/usr/bin/python3 "$(dirname "$0")/select-noise-gate.py" "$GLINT" "$WORK" models
# The decision sets of the sampling gate (seed 5301: 180 parts, scans included).
for opening in closed cut; do
  set_dir="$WORK/cad-dec"
  cut=0
  [[ $opening == cut ]] && set_dir="$WORK/cad-dec-cut" && cut=1
  [[ -f "$set_dir/manifest.json" ]] ||
    "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$set_dir" --count 180 --seed 5301 \
      --sampling vertices,uniform,scan --noise 0,0.5,1 --plane-cut "$cut" --min-points 4000 \
      --max-points 40000
done
/usr/bin/python3 "$(dirname "$0")/select-sampling-gate.py" "$GLINT" "$WORK" models "$DATA"
# The decision sets of the low-noise mesh-vertex network: seed 5501 (as 5301's) and seed 5601
# (mesh vertices, clean or at 0.25 spacing; the second test of the rule).
for opening in closed cut; do
  cut=0 suffix=""
  [[ $opening == cut ]] && cut=1 suffix="-cut"
  [[ -f "$WORK/cad-dec2$suffix/manifest.json" ]] ||
    "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad-dec2$suffix" --count 180 \
      --seed 5501 --sampling vertices,uniform,scan --noise 0,0.5,1 --plane-cut "$cut" \
      --min-points 4000 --max-points 40000
  [[ -f "$WORK/cad-dec3$suffix/manifest.json" ]] ||
    "${NICE[@]}" "$GLINT" edges synth --kind cad -o "$WORK/cad-dec3$suffix" --count 160 \
      --seed 5601 --sampling vertices --noise 0,0,0,0.25 --outliers 0 --plane-cut "$cut" \
      --min-points 4000 --max-points 40000
done
/usr/bin/python3 "$(dirname "$0")/select-clean-vertex-gate.py" "$GLINT" "$WORK" models "$DATA"
