#!/usr/bin/env bash
# Runs the CUDA integration checks gathered by pack.sh on a GPU machine: the CUDA integrator's
# tests (GPU against CPU fusion), and the fusion kernel benchmark (CPU with all cores and with
# 2, GPU integration alone and with the per-frame download), 5 repetitions each, and the tests
# under compute-sanitizer; results in OUT.
#   run.sh DIR OUT
set -euo pipefail
DIR=$(cd "${1:?usage: run.sh DIR OUT}" && pwd)
OUT=${2:?usage: run.sh DIR OUT}
mkdir -p "$OUT"
export LD_LIBRARY_PATH=$DIR${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader
echo "CPU cores: $(nproc)"
status=0  # a failing test fails the script, after the benchmarks have run
"$DIR/glint_fusion_cuda_tests" 2>&1 | tee "$OUT/cuda-tests.txt" || status=1
bench() {  # bench NAME [taskset CPUS]: the benchmark's JSON in OUT/NAME.json
  local name=$1
  shift
  "$@" "$DIR/fusion_kernels" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
    --benchmark_out="$OUT/$name.json" --benchmark_out_format=json
}
bench fusion-kernels-all-cores
bench fusion-kernels-2-cores taskset -c 0,1
# The tests again under compute-sanitizer's memcheck, where the machine has it.
if command -v compute-sanitizer >/dev/null; then
  compute-sanitizer --tool memcheck --error-exitcode 1 "$DIR/glint_fusion_cuda_tests" \
    --gtest_brief=1 >"$OUT/memcheck.txt" 2>&1 || status=1
  tail -5 "$OUT/memcheck.txt"
fi
exit $status
