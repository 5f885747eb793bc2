# prep.py INPUTS WORK: the protocol images (glint denoise eval --save) as raw planar float32
# for the driver, and its job list: DIP and guided DIP on every image, S2S and guided S2S (a
# timing: 1,000 steps) on the first.
import sys, os, numpy as np
from protocol_images import load
src, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
names = sorted(f[:-len("-noisy.png")] for f in os.listdir(src) if f.endswith("-noisy.png"))
shapes = {}
for n in names:
    noisy = load(f"{src}/{n}-noisy.png")
    shapes[n] = noisy.shape
    noisy.astype(np.float32).tofile(f"{work}/{n}-noisy.f32")
    load(f"{src}/{n}-guidance-svd.png").astype(np.float32).tofile(f"{work}/{n}-guidance.f32")
jobs = []
def job(method, n, it=0, pred=0):
    g = f"{work}/{n}-guidance.f32" if method.startswith("guided") else "-"
    c, h, w = shapes[n]
    jobs.append(f"{method} full {work}/{n}-noisy.f32 {g} {w} {h} {c} {work}/{n}-{method}.f32 {it} {pred}")
job("dip", names[0]); job("guided-dip", names[0])
job("s2s", names[0], 1000, 100); job("guided-s2s", names[0], 1000, 100)
for n in names[1:]:
    job("dip", n); job("guided-dip", n)
open(f"{work}/jobs.txt", "w").write("\n".join(jobs) + "\n")
