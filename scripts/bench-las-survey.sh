#!/usr/bin/env bash
# Out-of-core and MPI benchmark of `glint edges classify` on synthetic LAS surveys
# (docs/benchmarks.md, "BoundED at survey scale"). Needs the release build (glint, survey_las)
# and, for the MPI part, an MPI build in build/mpi (cmake -B build/mpi -DGLINT_WITH_MPI=ON).
#   scripts/bench-las-survey.sh WORK_FOLDER [POINTS_BIG] [POINTS_SMALL]
set -euo pipefail
work=${1:?work folder}
big=${2:-100000000}
small=${3:-10000000}
root=$(cd "$(dirname "$0")/.." && pwd)
glint=$root/build/release/apps/glint/glint
glint_mpi=$root/build/mpi/apps/glint/glint
survey=$root/build/release/bench/edges/survey_las
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
run() {  # name, command...: wall time, peak RSS and the command's own summary
  local name=$1; shift
  /usr/bin/time -f "$name: wall %e s, peak RSS %M KiB, user %U s, sys %S s" -a -o "$work/times.txt" \
    nice -n 10 "$@" 2>&1 | grep -v '^\s*$' | tail -4
}

[ -f "$work/small.las" ] || nice -n 10 "$survey" --points "$small" --seed 2 -o "$work/small.las"
run small-in-memory "$glint" --quiet edges classify "$work/small.las" -o "$work/small-memory.las" \
  --report "$work/small-memory.json"
run small-out-of-core "$glint" --quiet edges classify "$work/small.las" -o "$work/small-tiled.las" \
  --memory-limit 2G --report "$work/small-tiled.json"
cmp "$work/small-memory.las" "$work/small-tiled.las" && echo "small: in-memory and out-of-core outputs identical"
md5sum "$work/small-memory.las" "$work/small-tiled.las" | tee -a "$work/checksums.txt"

if [ -x "$glint_mpi" ]; then
  for ranks in 1 2 3; do
    run "small-mpi-$ranks" mpirun --oversubscribe -n "$ranks" "$glint_mpi" --quiet --threads 1 \
      edges classify "$work/small.las" -o "$work/small-mpi$ranks.las" --memory-limit 2G \
      --report "$work/small-mpi$ranks.json"
    md5sum "$work/small-mpi$ranks.las" | tee -a "$work/checksums.txt"
    rm -f "$work/small-mpi$ranks.las"
  done
fi
rm -f "$work/small-tiled.las"

if [ "$big" -gt 0 ]; then
  [ -f "$work/big.las" ] || run big-generate "$survey" --points "$big" --seed 1 -o "$work/big.las"
  run big-out-of-core "$glint" --quiet edges classify "$work/big.las" -o "$work/big-out.las" \
    --memory-limit 2G --report "$work/big.json"
  md5sum "$work/big-out.las" | tee -a "$work/checksums.txt"
fi
cat "$work/times.txt"
