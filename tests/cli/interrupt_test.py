#!/usr/bin/python3
"""SIGINT / SIGTERM in the middle of a long glint command: the command exits 130 (SIGINT) or
143 (SIGTERM) with one line, and leaves neither its output nor any partial or temporary file.

Usage: interrupt_test.py GLINT_BINARY [CASE ...]   (cases: render, render-sigterm, reconstruct,
classify, classify-tiled (LAS in tiles, its temporary tile folder), denoise (SIGTERM inside the
libtorch module's loop); default all). Not timing-dependent: each signal is sent once the
command's staging folder (classify: its first log line; denoise: the module mapped) exists, and
each run is made long enough to be still working then; a command that ends before the signal
fails the test instead of passing.
"""
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

GLINT = sys.argv[1]
CASES = sys.argv[2:] or ["render", "render-sigterm", "reconstruct", "classify", "classify-tiled",
                         "denoise"]
WORK = tempfile.mkdtemp(prefix="glint_interrupt_test_")
failures = []


def run(arguments):
    result = subprocess.run([GLINT, "--quiet"] + arguments, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"glint {' '.join(arguments)} failed: {result.stderr}")


def wait_until(process, ready, what):
    """Polls `ready` until it holds; the command must still be running then."""
    deadline = time.monotonic() + 600
    while not ready():
        if process.poll() is not None:
            raise RuntimeError(f"the command ended (status {process.returncode}) before {what}")
        if time.monotonic() > deadline:
            process.kill()
            raise RuntimeError(f"no {what} after 600 s")
        time.sleep(0.01)


def leftovers(output):
    """Anything named after the output: itself, OUT.partial-PID, OUT.tmp-PID, OUT.png ..."""
    folder, name = os.path.split(output)
    return sorted(entry for entry in os.listdir(folder) if entry.startswith(name))


def interrupt(case, arguments, output, ready, what, sent=signal.SIGINT, stderr_ready=None,
              on_start=None):
    """Runs glint ARGUMENTS, sends `sent` once `ready` holds, checks the status and that no
    file whose name starts with `output` is left."""
    process = subprocess.Popen([GLINT] + arguments, stderr=subprocess.PIPE, text=True)
    if on_start is not None:
        on_start(process)
    try:
        if stderr_ready is None:
            wait_until(process, ready, what)
        else:  # read stderr until the line that says the long part began
            for line in process.stderr:
                if stderr_ready in line:
                    break
            else:
                raise RuntimeError(f"the command ended before printing '{stderr_ready}'")
        process.send_signal(sent)
        _, error_text = process.communicate(timeout=600)
    except Exception as error:  # noqa: BLE001 - reported as this case's failure
        process.kill()
        process.wait()
        failures.append(f"{case}: {error}")
        return
    expected = 128 + sent
    left = leftovers(output)
    last_line = error_text.strip().splitlines()[-1] if error_text.strip() else ""
    print(f"{case}: exit status {process.returncode} (expected {expected}); "
          f"left behind: {left or 'nothing'}; last line: {last_line!r}")
    if process.returncode != expected:
        failures.append(f"{case}: exit status {process.returncode}, expected {expected}: "
                        f"{error_text}")
    if left:
        failures.append(f"{case}: left {left}")


def staging_has(output, relative):
    """True once OUT.partial-PID/relative exists."""
    folder, name = os.path.split(output)
    return lambda: any(
        entry.startswith(name + ".partial-") and
        os.path.exists(os.path.join(folder, entry, relative)) for entry in os.listdir(folder))


def write_cloud(path, points, seed):
    """A binary PLY of `points` points on the faces of a unit cube."""
    values = cube_points(points, seed)
    with open(path, "wb") as file:
        file.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {points}\n"
                    "property float x\nproperty float y\nproperty float z\nend_header\n").encode())
        file.write(struct.pack(f"<{len(values)}f", *values))


def cube_points(points, seed):
    """`points` points on the faces of a unit cube (sharp edges, no boundary)."""
    generator = random.Random(seed)
    values = []
    for _ in range(points):
        axis, side = generator.randrange(3), float(generator.randrange(2))
        point = [generator.random(), generator.random(), generator.random()]
        point[axis] = side
        values.extend(point)
    return values


def write_las(path, points, seed):
    """A LAS 1.2 file, point format 0, millimetre units, of `points` cube points."""
    values = cube_points(points, seed)
    header = bytearray(227)
    struct.pack_into("<4s", header, 0, b"LASF")
    struct.pack_into("<BB", header, 24, 1, 2)  # version 1.2
    struct.pack_into("<HHI", header, 94, 227, 227, 0)  # header size, point offset, no VLRs
    struct.pack_into("<BHI", header, 104, 0, 20, points)  # format 0, 20-byte records
    struct.pack_into("<I", header, 111, points)  # points by return: all first returns
    struct.pack_into("<3d", header, 131, 0.001, 0.001, 0.001)  # scale
    struct.pack_into("<3d", header, 155, 0.0, 0.0, 0.0)  # offset
    struct.pack_into("<6d", header, 179, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0)  # max/min x, y, z
    records = bytearray()
    for i in range(points):
        x, y, z = (round(v * 1000) for v in values[3 * i:3 * i + 3])
        records += struct.pack("<3iHBBbBH", x, y, z, 0, 1, 0, 0, 0, 0)
    with open(path, "wb") as file:
        file.write(header + records)


def write_noise_png(path, side, seed):
    """An 8-bit grey PNG of uniform noise, side x side."""
    generator = random.Random(seed)
    rows = b"".join(b"\0" + bytes(generator.randrange(256) for _ in range(side))
                    for _ in range(side))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    with open(path, "wb") as file:
        file.write(b"\x89PNG\r\n\x1a\n" +
                   chunk(b"IHDR", struct.pack(">IIBBBBB", side, side, 8, 0, 0, 0, 0)) +
                   chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


try:
    scene = os.path.join(WORK, "scene")
    if {"render", "render-sigterm", "reconstruct"} & set(CASES):
        # A small sequence: its scene.json drives render, its frames drive reconstruct.
        run(["synth", "cubes", "--frames", "12", "--width", "160", "--no-shadows", "-o", scene])
    for sent, case in ((signal.SIGINT, "render"), (signal.SIGTERM, "render-sigterm")):
        if case in CASES:
            output = os.path.join(WORK, case)
            interrupt(case, ["render", os.path.join(scene, "scene.json"), "-o", output,
                             "--width", "320"],
                      output, staging_has(output, "rgb/000000.png"), "a first rendered frame",
                      sent)
    if "reconstruct" in CASES:
        output = os.path.join(WORK, "reconstruction")
        interrupt("reconstruct", ["reconstruct", scene, "--gt-poses", "--gt-lights", "-o", output],
                  output, staging_has(output, "frames"), "the staging folder")
    if "classify" in CASES:
        cloud = os.path.join(WORK, "cube.ply")
        write_cloud(cloud, 400000, seed=1)
        output = os.path.join(WORK, "cube_edges.ply")
        interrupt("classify", ["edges", "classify", cloud, "-o", output, "--png",
                               os.path.join(WORK, "cube_edges.png")],
                  os.path.join(WORK, "cube_edges"), None, None, stderr_ready="points; model")
    if "classify-tiled" in CASES:
        survey = os.path.join(WORK, "survey.las")
        write_las(survey, 300000, seed=2)
        output = os.path.join(WORK, "survey_edges.las")
        interrupt("classify-tiled", ["edges", "classify", survey, "-o", output,
                                     "--tile-points", "40000"],
                  output, lambda: any(entry.startswith("survey_edges.las.tiles-")
                                      for entry in os.listdir(WORK)),
                  "the temporary tile folder")
    if "denoise" in CASES:
        # The signal arrives inside the libtorch module, which has its own copy of glint_core
        # and must poll the host's flag; sent once the module is mapped into the process. With
        # no snapshots nothing on the host side polls until the million steps are done.
        noisy = os.path.join(WORK, "noisy.png")
        write_noise_png(noisy, 64, seed=3)
        output = os.path.join(WORK, "denoised.png")
        process_maps = []

        def module_loaded():
            with open(process_maps[0]) as maps:
                return "denoise-nets.so" in maps.read()

        interrupt("denoise", ["denoise", "run", noisy, "-o", output, "--method", "dip",
                              "--iterations", "1000000"],
                  output, module_loaded, "the denoiser module", signal.SIGTERM,
                  on_start=lambda process: process_maps.append(f"/proc/{process.pid}/maps"))
finally:
    shutil.rmtree(WORK, ignore_errors=True)

for failure in failures:
    print("FAILED", failure)
sys.exit(1 if failures else 0)
