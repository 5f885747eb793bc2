#!/usr/bin/env python3
"""Reconstruct geometry, lights' shading and per-object materials from an RGB-D sequence,
frame by frame from NumPy arrays.

    python3 reconstruct_sequence.py [SEQUENCE] --lights LIGHTS [-o OUT] [--frames N]

SEQUENCE: an RGB-D folder (default ../shared/data/rgbd/7scenes-50, beside the repository, with
the assumed lights of docs/reflectance/7scenes-assumed-lights.json; or make one with
`glint synth bunnies -o seq`). LIGHTS: its lights.json or light-capture folder (`glint synth
lights --scene bunnies -o cap` renders one); default: a synthetic sequence's true lights (its
scene.json), else a single light guessed at the first camera position. Each frame is read into arrays and handed to glint.Reconstruction, as a
live camera's frames would be; the per-frame statistics are printed, and at the end the
materials, a re-rendering of the last view (OUT/render.png) and the model (OUT/mesh.ply,
materials.json, lights.json) are written.
"""

import argparse
import json
from pathlib import Path

import numpy as np

import glint

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "../shared/data/rgbd"


def default_lights(folder, sequence):
    """A synthetic sequence's true point lights (its scene.json); for a real one without a
    light capture, one light at the first camera position (a head-lamp guess: the materials
    then say little, but the geometry and segments do)."""
    if Path(folder).resolve() == (DATA / "7scenes-50").resolve():
        return str(REPO / "docs/reflectance/7scenes-assumed-lights.json")
    scene = Path(folder) / "scene.json"
    if scene.exists():
        return [{"position": light["position"], "intensity": light["intensity"]}
                for light in json.loads(scene.read_text())["lights"]]
    pose = sequence[0]["pose"]
    position = pose[:3, 3] if pose is not None else np.zeros(3)
    print(f"no lights given: guessing one at {np.round(position, 2)}")
    return [{"position": position, "intensity": [1, 1, 1]}]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sequence", nargs="?", default=str(DATA / "7scenes-50"))
    parser.add_argument("--lights", help="lights.json or light-capture folder")
    parser.add_argument("-o", "--output", default="reconstruction")
    parser.add_argument("--frames", type=int, default=0, help="first N frames (0 = all)")
    parser.add_argument("--track", action="store_true",
                        help="track the camera instead of using the sequence's poses (real "
                             "data without ground truth is tracked anyway)")
    args = parser.parse_args()

    sequence = glint.io.open_rgbd_sequence(args.sequence)
    lights = args.lights or default_lights(args.sequence, sequence)
    track = args.track or sequence[0]["pose"] is None
    reconstruction = glint.Reconstruction(sequence.intrinsics, lights, gt_poses=not track,
                                          exposure=sequence.exposure)
    count = min(args.frames or len(sequence), len(sequence))
    for i in range(count):
        frame = sequence[i]  # rgb (H, W, 3) linear float32, depth (H, W) metres, pose (4, 4)
        rgb, depth = frame["rgb"], frame["depth"]
        stats = reconstruction.add_frame(rgb, depth, pose=None if track else frame["pose"])
        print(f"frame {i:4d}: {'fused' if stats['integrated'] else 'lost '}, "
              f"{stats['observed_voxels']:6d} voxels observed, {stats['segments']:3d} segments")
    last_pose = stats["pose"]

    for segment in reconstruction.materials()["segments"]:
        kd, ks = np.round(segment["kd"], 3), np.round(segment["ks"], 3)
        print(f"segment {segment['id']:3d}: kd {kd}, ks {ks}, alpha {segment['alpha']:.3f} "
              f"({segment['estimates']} estimates)")
    out = Path(args.output)
    reconstruction.export(out)
    image = reconstruction.render(last_pose)  # linear RGB
    srgb = np.where(image <= 0.0031308, 12.92 * image, 1.055 * image ** (1 / 2.4) - 0.055)
    glint.io.write_image(out / "render.png", srgb)
    print(f"median per-frame ms: {reconstruction.timings()}")
    print(f"-> {out}/mesh.ply, materials.json, lights.json, render.png")


if __name__ == "__main__":
    main()
