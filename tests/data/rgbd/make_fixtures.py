#!/usr/bin/env python3
"""Writes the tiny RGB-D fixtures of tests/io/rgbd_*_test.cpp (run from this folder):
one 16x12 camera (fx = fy = 20, cx = 7.5, cy = 5.5) looking down +z at a wall whose depth is
1.0 m + 0.01 m * x (pixel column) + 0.002 m * frame, in each dataset layout glint reads.
Colour: red = 16 * x, green = 16 * y, blue = 40 * frame (8-bit sRGB). Poses: camera i at
(0.01 i, 0, 0), identity rotation. Pure Python (zlib), no imaging library needed."""
import json
import os
import struct
import zlib

W, H, FRAMES = 16, 12, 3


def png(path, width, height, rows, bit_depth, colour_type):
    raw = b"".join(b"\x00" + row for row in rows)
    chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data +
                                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) +
                chunk(b"IEND", b""))


def depth_png(path, frame, units_per_metre):
    rows = []
    for y in range(H):
        values = []
        for x in range(W):
            metres = 1.0 + 0.01 * x + 0.002 * frame
            values.append(0 if (x, y) == (0, 0) else round(metres * units_per_metre))
        rows.append(struct.pack(">%dH" % W, *values))
    png(path, W, H, rows, 16, 0)


def colour_png(path, frame):
    rows = [bytes(v for x in range(W) for v in (16 * x, 16 * y, 40 * frame)) for y in range(H)]
    png(path, W, H, rows, 8, 2)


def tum_line(t, i):
    return "%.6f %.6f 0 0 0 0 0 1\n" % (t, 0.01 * i)


def intrinsics(folder, extra=None):
    value = {"width": W, "height": H, "fx": 20.0, "fy": 20.0, "cx": 7.5, "cy": 5.5}
    value.update(extra or {})
    with open(os.path.join(folder, "intrinsics.json"), "w") as f:
        json.dump(value, f, indent=2)


def glint_sequence(folder):
    os.makedirs(folder, exist_ok=True)
    intrinsics(folder, {"depth_scale": 1000})
    with open(os.path.join(folder, "associations.txt"), "w") as assoc, \
            open(os.path.join(folder, "groundtruth.txt"), "w") as gt:
        gt.write("# timestamp tx ty tz qx qy qz qw\n")
        for i in range(FRAMES):
            t = i / 30
            name = "%06d.png" % i
            colour_png(os.path.join(folder, "rgb", name), i)
            depth_png(os.path.join(folder, "depth", name), i, 1000)
            assoc.write("%.6f rgb/%s %.6f depth/%s\n" % (t, name, t, name))
            gt.write(tum_line(t, i))


def tum_sequence(folder):
    """rgb.txt + depth.txt; the last depth image has no colour within 0.02 s (skipped)."""
    os.makedirs(folder, exist_ok=True)
    intrinsics(folder)
    with open(os.path.join(folder, "rgb.txt"), "w") as rgb, \
            open(os.path.join(folder, "depth.txt"), "w") as depth, \
            open(os.path.join(folder, "groundtruth.txt"), "w") as gt:
        for f in (rgb, depth, gt):
            f.write("# fixture\n")
        for i in range(FRAMES):
            t = 100 + i / 30
            colour_png(os.path.join(folder, "rgb", "%.6f.png" % (t + 0.005)), i)
            rgb.write("%.6f rgb/%.6f.png\n" % (t + 0.005, t + 0.005))
            depth_png(os.path.join(folder, "depth", "%.6f.png" % t), i, 5000)
            depth.write("%.6f depth/%.6f.png\n" % (t, t))
            gt.write(tum_line(t - 0.01, i))
        t = 100 + FRAMES / 30 + 1
        depth_png(os.path.join(folder, "depth", "%.6f.png" % t), FRAMES, 5000)
        depth.write("%.6f depth/%.6f.png\n" % (t, t))


def seven_scenes_sequence(folder):
    frames = os.path.join(folder, "rgbd-frames")
    os.makedirs(frames, exist_ok=True)
    with open(os.path.join(folder, "camera-intrinsics.txt"), "w") as f:
        f.write("20 0 7.5\n0 20 5.5\n0 0 1\n")
    for i in range(FRAMES):
        stem = os.path.join(frames, "frame-%06d" % (150 + i))
        colour_png(stem + ".color.png", i)
        depth_png(stem + ".depth.png", i, 1000)
        with open(stem + ".pose.txt", "w") as f:
            f.write("1 0 0 %g\n0 1 0 0\n0 0 1 0\n0 0 0 1\n" % (0.01 * i))


def redwood_sequence(folder):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "camera_primesense.json"), "w") as f:
        json.dump({"width": W, "height": H, "intrinsic_matrix": [20, 0, 0, 0, 20, 0, 7.5, 5.5, 1]}, f)
    with open(os.path.join(folder, "trajectory.log"), "w") as log:
        for i in range(FRAMES):
            colour_png(os.path.join(folder, "color", "%05d.png" % i), i)
            depth_png(os.path.join(folder, "depth", "%05d.png" % i), i, 1000)
            log.write("%d %d %d\n1 0 0 %g\n0 1 0 0\n0 0 1 0\n0 0 0 1\n" % (i, i, i + 1, 0.01 * i))


if __name__ == "__main__":
    glint_sequence("glint")
    tum_sequence("tum")
    seven_scenes_sequence("7scenes")
    redwood_sequence("redwood")
