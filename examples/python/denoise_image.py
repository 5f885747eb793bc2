#!/usr/bin/env python3
"""Denoise an image with locally-guided Self2Self (or another method), from NumPy arrays.

    python3 denoise_image.py [IMAGE] [-o denoised.png] [--method guided-s2s] [--iterations N]

IMAGE: PNG/EXR/...; without one, a 96x96 test picture is made and noise added to its right
half, where the guidance map should mark pixels noisy. Writes the denoised image, the guidance
map next to it (*-guidance.png) and prints how much the noisy half changed.
"""

import argparse
from pathlib import Path

import numpy as np

import glint


def test_picture(size=96, sigma=0.08, seed=2):
    y, x = np.mgrid[0:size, 0:size] / size
    clean = np.stack([x, y, 0.4 + 0.4 * ((x - 0.5) ** 2 + (y - 0.5) ** 2 < 0.08)], axis=-1)
    noisy = clean.copy()
    noisy[:, size // 2:] += np.random.default_rng(seed).normal(0, sigma, (size, size // 2, 3))
    return np.clip(noisy, 0, 1).astype(np.float32), clean.astype(np.float32)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image", nargs="?", help="noisy image (default: a made-up one)")
    parser.add_argument("-o", "--output", default="denoised.png")
    parser.add_argument("--method", default="guided-s2s",
                        help="guided-s2s, s2s, guided-dip, dip or nlm")
    parser.add_argument("--iterations", type=int, help="optimisation steps (default: preset's)")
    args = parser.parse_args()

    if args.image:
        noisy, clean = glint.io.read_image(args.image), None
    else:
        noisy, clean = test_picture()
    guidance, noise, info = glint.denoise.noise_map(noisy)  # SVD noise level, patch 7
    print(f"noise map: n_peak {info['n_peak']:.3g}; {np.mean(guidance < 0.5):.0%} of the "
          "pixels marked noisy (m < 0.5)")
    denoised = glint.denoise.run(noisy, method=args.method, guidance=guidance,
                                 iterations=args.iterations)
    glint.io.write_image(args.output, denoised)
    stem = Path(args.output)
    glint.io.write_image(stem.with_name(stem.stem + "-guidance.png"), guidance)
    print(f"{args.method} -> {args.output}")
    if clean is not None:
        half = slice(noisy.shape[1] // 2, None)
        for name, image in (("noisy", noisy), ("denoised", denoised)):
            rmse = np.sqrt(np.mean((image[:, half] - clean[:, half]) ** 2))
            print(f"  RMSE of the noisy half, {name}: {rmse:.4f}")


if __name__ == "__main__":
    main()
