#!/usr/bin/env bash
# The neural denoisers' full configuration on a GPU machine that has PyTorch (CUDA) but none of
# glint's Debian packages (OpenCV, Embree, ...), a lent device machine for example:
# builds glint's neural denoisers (src/denoise, the code `glint denoise run` loads as its
# plugin) against PyTorch's libtorch with a small driver (driver.cpp), runs DIP and guided DIP
# (3,000 steps) on each protocol image and S2S / guided S2S for a timing (1,000 of the 150,000
# steps, 100 predictions) on the first, and scores them: PSNR over the whole crop, its clean
# and its noisy part (as glint's metrics), SSIM as skimage computes it (borders left out).
# INPUTS comes from glint on any machine:
#   glint denoise eval --set kodak --count 6 --crop 256 --methods none --save INPUTS
# Where glint itself builds against a CUDA libtorch, `glint denoise eval --config full
# --device cuda` is the way; this is for machines where it cannot.
#   scripts/gpu-denoise/run.sh INPUTS OUT [TIME_LIMIT_S]
set -euo pipefail
INPUTS=${1:?usage: run.sh INPUTS OUT [TIME_LIMIT_S]}
OUT=${2:?usage: run.sh INPUTS OUT [TIME_LIMIT_S]}
LIMIT=${3:-600}  # no job starts after this many seconds
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$HERE/../..
WORK=$(mktemp -d)
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader
TORCH=$(python3 -c 'import torch, os; print(os.path.dirname(torch.__file__))')
ABI=$(python3 -c 'import torch; print(int(torch._C._GLIBCXX_USE_CXX11_ABI))')
python3 -c 'import torch; print("torch", torch.__version__, torch.cuda.get_device_name(0))'
compile() {  # compile SOURCE: one object in WORK, built in the background
  g++ -O2 -std=c++20 -w -D_GLIBCXX_USE_CXX11_ABI="$ABI" -I"$ROOT/src" -I"$TORCH/include" \
    -I"$TORCH/include/torch/csrc/api/include" -c "$1" -o "$WORK/$(basename "$1" .cpp).o" &
}
for name in unet dip self2self torch_support denoise_neural neural; do
  compile "$ROOT/src/denoise/$name.cpp"
done
compile "$ROOT/src/core/error.cpp"
compile "$ROOT/src/core/progress.cpp"
compile "$HERE/driver.cpp"
wait
# --no-as-needed: nothing references libtorch_cuda directly, but loading it registers CUDA.
g++ "$WORK"/*.o -o "$WORK/denoise" -L"$TORCH/lib" -Wl,--no-as-needed -ltorch_cuda -lc10_cuda \
  -Wl,--as-needed -ltorch -ltorch_cpu -lc10 -Wl,-rpath,"$TORCH/lib"
python3 "$HERE/prep.py" "$INPUTS" "$WORK"
"$WORK/denoise" "$WORK/jobs.txt" "$LIMIT" | tee "$OUT/driver.log"
python3 "$HERE/score.py" "$INPUTS" "$OUT/driver.log" "$OUT/gpu-denoise.json" | tee "$OUT/score.txt"
