#!/usr/bin/python3
"""Renders a reconstruction's scene.glb in headless Chromium (the three.js viewer of `glint view`)
from the poses of input frames and compares each screenshot with glint's own re-rendering of the
same pose and with the input frame: PSNR over the object pixels (8-bit sRGB).

  /usr/bin/python3 scripts/compare-viewer.py --sequence SEQ --lights CAPTURE --work DIR \
      [--glint build/release/apps/glint/glint] [--frames 10,30,50,70,90] [--figure out.png]

Runs `glint reconstruct SEQ --lights CAPTURE --gt-poses --views DIR/views.txt -o DIR/out` (skipped
when DIR/out/scene.glb exists, --reuse), `glint view DIR/out --write-html DIR/site`, then
web/tests/render-viewer.mjs once per frame. Object pixels: the input frame has depth there and
the viewer drew the model there (the viewer renders on a magenta background for this). Writes
DIR/compare.json and, with --figure, input | glint | viewer (| Blender, with --blender) for the
middle frame, halved.
Needs numpy and Pillow (Debian's python3-numpy, python3-pil), node, web/node_modules, chromium.
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys
import time

import numpy as np
from PIL import Image

ROOT = pathlib.Path(__file__).resolve().parent.parent
BACKGROUND = (255, 0, 255)


def read_rgb(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64)


def psnr(a, b, mask):
    mse = np.mean((a[mask] - b[mask]) ** 2)
    return math.inf if mse == 0 else 10 * math.log10(255.0**2 / mse)


def quaternion_matrix(qx, qy, qz, qw):
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    x, y, z, w = qx / n, qy / n, qz / n, qw / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def frame_poses(sequence):
    """Per frame (associations.txt order): rgb path, depth path, TUM pose line, camera-to-world."""
    poses = {}
    for line in (sequence / "groundtruth.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        values = line.split()
        poses[values[0]] = values
    frames = []
    for line in (sequence / "associations.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        stamp, rgb, _, depth = line.split()[:4]
        values = poses[stamp]
        t = np.array([float(v) for v in values[1:4]])
        camera_to_world = np.eye(4)
        camera_to_world[:3, :3] = quaternion_matrix(*[float(v) for v in values[4:8]])
        camera_to_world[:3, 3] = t
        frames.append((sequence / rgb, sequence / depth, " ".join(values), camera_to_world))
    return frames


def run(command, **kwargs):
    print("+", " ".join(str(c) for c in command), file=sys.stderr, flush=True)
    return subprocess.run([str(c) for c in command], check=True, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sequence", required=True, type=pathlib.Path)
    parser.add_argument("--lights", required=True, help="light capture folder or lights.json")
    parser.add_argument("--work", required=True, type=pathlib.Path)
    parser.add_argument("--glint", default=ROOT / "build/release/apps/glint/glint")
    parser.add_argument("--frames", default="10,30,50,70,90",
                        help="frame indices (associations.txt order) to compare")
    parser.add_argument("--figure", type=pathlib.Path, help="PNG: input | glint | viewer | Blender")
    parser.add_argument("--reuse", action="store_true", help="keep an existing WORK/out")
    parser.add_argument("--blender", help="also render the middle frame with this Blender "
                        "(scripts/blender-render-glb.py, Cycles, shadows off as glint)")
    parser.add_argument("--blender-samples", type=int, default=32)
    args = parser.parse_args()

    frames = frame_poses(args.sequence)
    chosen = [int(k) for k in args.frames.split(",")]
    intrinsics = json.loads((args.sequence / "intrinsics.json").read_text())
    args.work.mkdir(parents=True, exist_ok=True)
    out = args.work / "out"
    timings = {}
    if not (args.reuse and (out / "scene.glb").exists()):
        (args.work / "views.txt").write_text(
            "# timestamp tx ty tz qx qy qz qw\n" + "".join(frames[k][2] + "\n" for k in chosen))
        start = time.perf_counter()
        run([args.glint, "--quiet", "reconstruct", args.sequence, "--lights", args.lights,
             "--gt-poses", "--views", args.work / "views.txt", "-o", out,
             "--report", args.work / "report.json"])
        timings["reconstruct_s"] = time.perf_counter() - start
    report = json.loads((args.work / "report.json").read_text())
    exposure = report.get("parameters", {}).get("exposure", 1.0)
    run([args.glint, "--quiet", "view", out, "--write-html", args.work / "site"])

    rows = []
    size = f"{intrinsics['fx']},{intrinsics['fy']},{intrinsics['cx']},{intrinsics['cy']}," \
           f"{intrinsics['width']},{intrinsics['height']}"
    for view, k in enumerate(chosen):
        rgb, depth, _, camera_to_world = frames[k]
        world_to_camera = np.linalg.inv(camera_to_world)
        shot = args.work / f"viewer-{k:06d}.png"
        start = time.perf_counter()
        run(["node", ROOT / "web/tests/render-viewer.mjs", "--dir", args.work / "site",
             "--check", "--out", shot, "--exposure", str(exposure), "--intrinsics", size,
             "--world-to-camera", ",".join(f"{v:.9g}" for v in world_to_camera.reshape(-1)),
             "--background", "".join(f"{c:02x}" for c in BACKGROUND)], stdout=subprocess.DEVNULL)
        browser_s = time.perf_counter() - start
        viewer = read_rgb(shot)
        glint = read_rgb(out / "views" / f"{view:06d}-render.png")
        source = read_rgb(rgb)
        has_depth = np.asarray(Image.open(depth)) > 0
        drawn = np.any(viewer != np.array(BACKGROUND), axis=2)
        mask = has_depth & drawn
        rows.append({
            "frame": k,
            "object_pixels": int(mask.sum()),
            "depth_pixels_drawn_by_viewer": float(mask.sum() / max(1, has_depth.sum())),
            "psnr_viewer_vs_glint_db": psnr(viewer, glint, mask),
            "psnr_viewer_vs_input_db": psnr(viewer, source, mask),
            "psnr_glint_vs_input_db": psnr(glint, source, mask),
            "browser_s": browser_s,
        })
        panels = [source, glint, viewer.copy()]
        panels[2][~drawn] = 0  # the background as glint's (black)
        if args.blender and view == len(chosen) // 2:
            rendered = args.work / f"blender-{k:06d}.png"
            start = time.perf_counter()
            run([args.blender, "-b", "--python", ROOT / "scripts/blender-render-glb.py", "--",
                 out / "scene.glb", rendered, "--samples", args.blender_samples, "--no-shadows",
                 "--exposure", exposure, "--intrinsics", size, "--world-to-camera",
                 ",".join(f"{v:.9g}" for v in world_to_camera.reshape(-1))],
                stdout=subprocess.DEVNULL)
            blender = read_rgb(rendered)
            rows[-1]["blender_s"] = time.perf_counter() - start
            rows[-1]["psnr_blender_vs_glint_db"] = psnr(blender, glint, mask)
            rows[-1]["psnr_blender_vs_viewer_db"] = psnr(blender, viewer, mask)
            rows[-1]["psnr_blender_vs_input_db"] = psnr(blender, source, mask)
            panels.append(blender)
        print(json.dumps(rows[-1]), flush=True)
        if args.figure and view == len(chosen) // 2:
            strip = np.concatenate(panels, axis=1).astype(np.uint8)
            picture = Image.fromarray(strip)
            picture = picture.resize((picture.width // 2, picture.height // 2), Image.LANCZOS)
            args.figure.parent.mkdir(parents=True, exist_ok=True)
            picture.save(args.figure, optimize=True)

    def median(key):
        return float(np.median([row[key] for row in rows]))

    summary = {
        "sequence": str(args.sequence),
        "lights": str(args.lights),
        "frames": rows,
        "median": {key: median(key) for key in
                   ("psnr_viewer_vs_glint_db", "psnr_viewer_vs_input_db", "psnr_glint_vs_input_db")},
        "timings": timings,
        "glb_bytes": (out / "scene.glb").stat().st_size,
    }
    (args.work / "compare.json").write_text(json.dumps(summary, indent=2))
    print(json.dumps(summary["median"]))


if __name__ == "__main__":
    main()
