#!/usr/bin/env bash
# BoundED on real CAD meshes that no one here made: the figures of docs/benchmarks.md ("BoundED on
# real CAD meshes").
#   scripts/eval-bounded-meshes.sh [GLINT] [DATA] [WORK]
# Labels come from each mesh's own edges (`glint edges label MESH.obj`, sharp from a 25-degree
# turn of the neighbouring triangles' normals, bands of 0.3 / 0.6 local spacings).
# - Sharp edges: fandisk (a CAD part; its dihedral angles are bimodal, 728 edges of 25 degrees or
#   more against 18,691 below and 28 between 25 and 60), sampled at its mesh vertices (as ABC's
#   clouds are) and at 30,000 uniform points, noise 0 / 0.25 / 0.5 / 1 median spacings along the
#   normal, five noise seeds each; the clean clouds again with a 40-degree sharp angle.
# - Boundaries: fandisk and rocker-arm (its smooth tessellation has no such gap, so it is not
#   scored for sharp edges), each cut open by the eight planes below (unit normals and offsets in
#   box diagonals, drawn once from a seeded generator), at mesh vertices and uniformly, clean and
#   at noise 0.5; at clean mesh vertices also with the crossed triangles dropped (--cut-mode
#   drop) instead of clipped.
# The shipped models are scored beside CA and the angle-gap criterion (its default, and 4
# spacings with k = 64 on the uniform clouds). Nothing here chose a model or a setting.
set -euo pipefail
GLINT=${1:-build/release/apps/glint/glint}
DATA=${2:-${GLINT_DATA:-../shared/data}}
WORK=${3:-build/eval-meshes}
MESHES="$DATA/meshes"
PLANES=(0.364,0.864,0.348,0.135 0.792,0.390,-0.470,-0.027 0.777,0.627,0.061,0.011
  -0.823,-0.182,-0.539,-0.014 0.048,-0.350,-0.936,-0.071 0.006,-0.208,0.978,0.144
  -0.819,-0.571,-0.053,-0.067 0.100,0.102,0.990,0.037)
MODELS=(--model models/bounded-3c.json --model models/bounded-2c.json)
mkdir -p "$WORK"

label() {  # mesh output args...
  local mesh=$1 output=$2
  shift 2
  [[ -f "$output" ]] || "$GLINT" --quiet edges label "$MESHES/$mesh.obj" -o "$output" "$@"
}
evaluate() {  # folder task report args...
  local folder=$1 task=$2 report=$3
  shift 3
  [[ -f "$report" ]] ||
    "$GLINT" --quiet edges eval "$folder" --task "$task" --report "$report" "$@" > "${report%.json}.txt"
}

for sampling in vertices uniform; do
  points=()
  [[ $sampling == uniform ]] && points=(--points 30000)
  for noise in 0 0.25 0.5 1; do
    set_dir="$WORK/sharp-$sampling-noise$noise"
    mkdir -p "$set_dir"
    for seed in 1 2 3 4 5; do
      label fandisk "$set_dir/fandisk-seed$seed.ply" --sampling "$sampling" "${points[@]}" \
        --noise "$noise" --seed "$seed"
    done
    evaluate "$set_dir" sharp "$WORK/sharp-$sampling-noise$noise.json" "${MODELS[@]}"
  done
  set_dir="$WORK/sharp40-$sampling-noise0"
  mkdir -p "$set_dir"
  label fandisk "$set_dir/fandisk.ply" --sampling "$sampling" "${points[@]}" --sharp-angle 40
  evaluate "$set_dir" sharp "$WORK/sharp40-$sampling-noise0.json" "${MODELS[@]}"

  wide=()
  [[ $sampling == uniform ]] && wide=(--ag-radius-spacings 4 --ag-k 64)
  for noise in 0 0.5; do
    set_dir="$WORK/boundary-$sampling-noise$noise"
    mkdir -p "$set_dir"
    for mesh in fandisk rocker-arm; do
      for k in "${!PLANES[@]}"; do
        label "$mesh" "$set_dir/$mesh-cut$k.ply" --sampling "$sampling" "${points[@]}" \
          --noise "$noise" --cut-plane "${PLANES[$k]}"
      done
    done
    evaluate "$set_dir" boundary "$WORK/boundary-$sampling-noise$noise.json" \
      --model models/bounded-3c.json
    if ((${#wide[@]})); then
      evaluate "$set_dir" boundary "$WORK/boundary-$sampling-noise$noise-wide.json" \
        --model models/bounded-3c.json "${wide[@]}"
    fi
  done
done

# The same cuts with the crossed triangles dropped (a jagged border), clean mesh vertices.
set_dir="$WORK/boundary-drop-vertices-noise0"
mkdir -p "$set_dir"
for mesh in fandisk rocker-arm; do
  for k in "${!PLANES[@]}"; do
    label "$mesh" "$set_dir/$mesh-cut$k.ply" --sampling vertices --cut-plane "${PLANES[$k]}" \
      --cut-mode drop
  done
done
evaluate "$set_dir" boundary "$WORK/boundary-drop-vertices-noise0.json" \
  --model models/bounded-3c.json

# One row per set and method: median MCC over the files (range).
/usr/bin/python3 - "$WORK" <<'EOF'
import glob, json, os, sys
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    report = json.load(open(path))
    for method, summary in report["summary"].items():
        scores = sorted(f["scores"][method]["mcc"] for f in report["files"])
        print(f"{os.path.basename(path)[:-5]:32} {method:26} median MCC "
              f"{summary['median']['mcc']:.3f} ({scores[0]:.3f}-{scores[-1]:.3f}), n = {len(scores)}")
EOF
