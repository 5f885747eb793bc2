# score.py INPUTS LOG OUTJSON: PSNR (whole / clean part / noisy part, peak 1, as glint's
# denoise/metrics.h) and SSIM (skimage: Gaussian window sigma 1.5, borders left out) of each
# result the driver's LOG names, against the protocol's clean crop and true noisy mask.
import sys, os, json, numpy as np
from protocol_images import load
from skimage.metrics import structural_similarity
src, log, out = sys.argv[1:4]
def psnr(a, b, m=None):
    d = (a - b) ** 2
    mse = d.mean() if m is None else d[:, m].mean()
    return float("inf") if mse == 0 else 10 * np.log10(1.0 / mse)
rows = []
for line in open(log):
    if not line.startswith("RESULT"): continue
    t = line.split()
    method, path = t[1], t[3]
    n = os.path.basename(path)[: -len(f"-{method}.f32")]
    clean = load(f"{src}/{n}-clean.png"); noisy = load(f"{src}/{n}-noisy.png")
    mask = load(f"{src}/{n}-mask.png")[0] > 0.5
    res = np.fromfile(path, dtype=np.float32).reshape(clean.shape).clip(0, 1)
    ssim = structural_similarity(clean.transpose(1, 2, 0), res.transpose(1, 2, 0), channel_axis=2,
                                 data_range=1.0, gaussian_weights=True, sigma=1.5,
                                 use_sample_covariance=False)
    rows.append(dict(image=n, method=method, iterations=int(t[5]), predictions=int(t[7]),
                     seconds=float(t[9]), device=t[11], psnr=float(psnr(clean, res)),
                     psnr_clean=float(psnr(clean, res, ~mask)), psnr_noisy=float(psnr(clean, res, mask)),
                     ssim=float(ssim), input_psnr=float(psnr(clean, noisy))))
    r = rows[-1]
    print(f"{n} {method:11s} it {r['iterations']:6d} {r['seconds']:7.1f} s  PSNR {r['psnr']:.2f} clean {r['psnr_clean']:.2f} noisy {r['psnr_noisy']:.2f} SSIM {r['ssim']:.3f} (input {r['input_psnr']:.2f})")
json.dump(rows, open(out, "w"), indent=1)
