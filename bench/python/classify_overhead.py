#!/usr/bin/env python3
"""The Python module's overhead: BoundED classification of one cloud from NumPy arrays
(glint.edges.classify) against `glint edges classify` on the same cloud as a PLY file.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python/classify_overhead.py \
        [--points 1000000] [--repeats 3] [--glint build/release/apps/glint/glint] [--json out]

The cloud: points on a box with an open top (sharp edges and a boundary), seed 1, written once
as a binary PLY. Timed, each --repeats times (median, min, max of wall-clock seconds):
  cli        the glint process: start, read the PLY, classify, write the labelled PLY;
  python     glint.edges.classify(xyz) on the arrays already in memory;
  python_io  read_point_cloud + classify + write_point_cloud (the CLI's work, from Python).
Prints the machine, the figures and the ratios; --json writes them.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import glint


def box_cloud(points, seed):
    rng = np.random.default_rng(seed)
    face = rng.integers(0, 5, points)
    u, v = rng.random(points), rng.random(points)
    zero, one = np.zeros(points), np.ones(points)
    xyz = np.select([face[:, None] == f for f in range(5)], [
        np.stack([u, v, zero], 1), np.stack([u, zero, v], 1), np.stack([u, one, v], 1),
        np.stack([zero, u, v], 1), np.stack([one, u, v], 1)])
    return (xyz + rng.normal(0, 0.0005, xyz.shape)).astype(np.float32)


def timed(function, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return {"median_s": statistics.median(times), "min_s": min(times), "max_s": max(times),
            "runs_s": times}


def cpu_model():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--glint", default="build/release/apps/glint/glint")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()

    xyz = box_cloud(args.points, args.seed)
    with tempfile.TemporaryDirectory() as folder:
        cloud = Path(folder) / "cloud.ply"
        glint.io.write_point_cloud(cloud, xyz)
        out_cli, out_py = Path(folder) / "cli.ply", Path(folder) / "py.ply"

        def run_cli():
            subprocess.run([args.glint, "--quiet", "edges", "classify", str(cloud), "-o",
                            str(out_cli)], check=True, capture_output=True)

        def run_python_io():
            points, _ = glint.io.read_point_cloud(cloud)
            labels, probs = glint.edges.classify(points)
            glint.io.write_point_cloud(out_py, points, labels=labels, probs=probs)

        # Interleaved order is not needed: each variant's runs are back to back, CLI first.
        result = {"cli": timed(run_cli, args.repeats),
                  "python": timed(lambda: glint.edges.classify(xyz), args.repeats),
                  "python_io": timed(run_python_io, args.repeats)}
        _, cli_fields = glint.io.read_point_cloud(out_cli)
        labels, _ = glint.edges.classify(xyz)
        result["labels_equal"] = bool(np.array_equal(labels, cli_fields["scalar_label"]))
    result.update({
        "points": args.points, "seed": args.seed, "repeats": args.repeats,
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count()},
        "ratio_python_to_cli": result["python"]["median_s"] / result["cli"]["median_s"],
        "ratio_python_io_to_cli": result["python_io"]["median_s"] / result["cli"]["median_s"],
    })
    print(f"{args.points} points, seed {args.seed}, {args.repeats} runs each, "
          f"{result['machine']['cpu']} ({result['machine']['cores']} cores)")
    for name in ("cli", "python", "python_io"):
        r = result[name]
        print(f"  {name:10s} median {r['median_s']:.3f} s (min {r['min_s']:.3f}, "
              f"max {r['max_s']:.3f})")
    print(f"  python / cli {result['ratio_python_to_cli']:.3f}, python_io / cli "
          f"{result['ratio_python_io_to_cli']:.3f}; labels equal: {result['labels_equal']}")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
