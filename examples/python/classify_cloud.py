#!/usr/bin/env python3
"""Label a point cloud's sharp edges and boundaries with BoundED and show them.

    python3 classify_cloud.py [CLOUD] [-o labelled.ply] [--png picture.png]

CLOUD: any .ply/.xyz/.pts/.pcd; without one, a 40k-point box with a hole is made with NumPy.
Shows the cloud in a matplotlib window (red = sharp edge, green = boundary); where there is no
display, it writes the picture to a PNG instead (--png, default classify_cloud.png).
"""

import argparse
import os

import matplotlib
import numpy as np

import glint


def box_with_hole(points=40000, seed=1):
    """Points on five faces of a unit box (the top is open: its rim is a boundary) with a
    little noise."""
    rng = np.random.default_rng(seed)
    face = rng.integers(0, 5, points)
    u, v = rng.random(points), rng.random(points)
    zero, one = np.zeros(points), np.ones(points)
    xyz = np.select([face[:, None] == f for f in range(5)], [
        np.stack([u, v, zero], 1), np.stack([u, zero, v], 1), np.stack([u, one, v], 1),
        np.stack([zero, u, v], 1), np.stack([one, u, v], 1)])
    return xyz + rng.normal(0, 0.001, xyz.shape)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cloud", nargs="?", help="input point cloud (default: a synthetic box)")
    parser.add_argument("-o", "--output", help="also write the labelled cloud (.ply)")
    parser.add_argument("--png", default="classify_cloud.png",
                        help="picture to write when there is no display")
    args = parser.parse_args()

    xyz = glint.io.read_point_cloud(args.cloud)[0] if args.cloud else box_with_hole()
    labels, probs = glint.edges.classify(xyz)  # the shipped 3-class model
    counts = np.bincount(labels, minlength=3)
    print(f"{len(xyz)} points: {counts[0]} non-edge, {counts[1]} sharp, {counts[2]} boundary")
    if args.output:
        glint.io.write_point_cloud(args.output, xyz, labels=labels, probs=probs)
        print(f"labelled cloud -> {args.output}")

    headless = not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")
    if headless:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = np.array([[0.75, 0.75, 0.75], [0.9, 0.1, 0.1], [0.1, 0.75, 0.2]])[labels]
    figure = plt.figure(figsize=(7, 7))
    axes = figure.add_subplot(projection="3d")
    order = np.argsort(labels, kind="stable")  # edges drawn last, on top
    axes.scatter(*xyz[order].T, c=colours[order], s=0.5, depthshade=False)
    axes.set_title("BoundED: red = sharp edge, green = boundary")
    axes.set_box_aspect(np.ptp(xyz, axis=0))
    if headless:
        figure.savefig(args.png, dpi=120)
        print(f"picture -> {args.png}")
    else:
        plt.show()


if __name__ == "__main__":
    main()
