"""Shared fixtures: the glint executable the module is compared with, and small inputs made in
the test (no data folder needed)."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import glint

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def glint_binary():
    """The built `glint` (GLINT_BINARY, set by ctest), else build/release/apps/glint/glint."""
    path = Path(os.environ.get("GLINT_BINARY", REPO / "build/release/apps/glint/glint"))
    if not path.exists():
        pytest.skip(f"no glint executable at {path}")
    return path


@pytest.fixture(scope="session")
def cli(glint_binary):
    """Runs `glint ARGS...`; returns the completed process (check=True unless told)."""
    def run(*args, check=True):
        result = subprocess.run([str(glint_binary), "--quiet", *map(str, args)],
                                capture_output=True, text=True)
        if check and result.returncode != 0:
            raise AssertionError(f"glint {' '.join(map(str, args))} failed:\n{result.stderr}")
        return result
    return run


@pytest.fixture(scope="session")
def cloud_file(tmp_path_factory, cli):
    """A procedural labelled cloud from `glint edges synth` (a box, about 3,000 points)."""
    folder = tmp_path_factory.mktemp("clouds")
    cli("edges", "synth", "-o", folder, "--count", "1", "--seed", "7", "--min-points", "2500",
        "--max-points", "3500", "--shapes", "box")
    return next(folder.glob("*.ply"))


@pytest.fixture(scope="session")
def noisy_png(tmp_path_factory):
    """A 48x40 RGB PNG: smooth gradients, an edge, and Gaussian noise in one half."""
    rng = np.random.default_rng(3)
    y, x = np.mgrid[0:40, 0:48] / 48.0
    image = np.stack([x, y, 0.5 + 0.3 * (x > 0.5)], axis=-1)
    image[:, 24:] += rng.normal(0, 0.08, (40, 24, 3))
    path = tmp_path_factory.mktemp("images") / "noisy.png"
    glint.io.write_image(path, np.clip(image, 0, 1))
    return path
