"""glint.denoise against `glint denoise noise-map|run` on the same image."""

import json

import numpy as np
import pytest

import glint


def test_noise_map_equals_cli(noisy_png, cli, tmp_path):
    cli("denoise", "noise-map", noisy_png, "-o", tmp_path / "m.exr", "--raw",
        tmp_path / "n.exr", "--report", tmp_path / "r.json", "--method", "svd", "--patch", "5")
    image = glint.io.read_image(noisy_png)
    guidance, noise, info = glint.denoise.noise_map(image, method="svd", patch=5)
    assert guidance.shape == image.shape[:2] and noise.shape == image.shape[:2]
    np.testing.assert_array_equal(noise, glint.io.read_image(tmp_path / "n.exr"))
    np.testing.assert_array_equal(guidance, glint.io.read_image(tmp_path / "m.exr"))
    report = json.loads((tmp_path / "r.json").read_text())
    assert info == {"n_peak": report["n_peak"], "lower": report["lower"],
                    "upper": report["upper"]}


def test_noise_map_takes_uint8_like_the_file_reader(noisy_png):
    image = glint.io.read_image(noisy_png)
    as_uint8 = np.round(image * 255).astype(np.uint8)
    np.testing.assert_array_equal(glint.denoise.noise_map(as_uint8)[1],
                                  glint.denoise.noise_map(image)[1])


def test_nlm_equals_cli(noisy_png, cli, tmp_path):
    cli("denoise", "run", noisy_png, "-o", tmp_path / "nlm.exr", "--method", "nlm", "--nlm-h",
        "12")
    result = glint.denoise.run(glint.io.read_image(noisy_png), method="nlm", nlm_h=12)
    np.testing.assert_array_equal(result, glint.io.read_image(tmp_path / "nlm.exr"))


def test_guided_s2s_through_the_plugin_equals_cli(noisy_png, cli, tmp_path):
    options = dict(iterations=3, predictions=2, levels=1, channels=4, device="cpu", seed=5)
    cli("--threads", "1", "denoise", "run", noisy_png, "-o", tmp_path / "s2s.exr",
        "--iterations", "3", "--predictions", "2", "--levels", "1", "--channels", "4",
        "--device", "cpu", "--seed", "5")
    glint.set_threads(1)  # libtorch's threads follow glint's; one thread sums in one order
    try:
        result = glint.denoise.run(glint.io.read_image(noisy_png), **options)
    finally:
        glint.set_threads(0)
    np.testing.assert_array_equal(result, glint.io.read_image(tmp_path / "s2s.exr"))


def test_denoise_errors(noisy_png):
    image = glint.io.read_image(noisy_png)
    with pytest.raises(glint.Error, match="method: median: unknown method"):
        glint.denoise.run(image, method="median")
    with pytest.raises(glint.Error, match="guidance: guidance map is 5x5 but the image is 48x40"):
        glint.denoise.run(image, guidance=np.ones((5, 5), np.float32))
    with pytest.raises(glint.Error, match="colour: unknown option of glint.denoise.run"):
        glint.denoise.run(image, method="nlm", colour=1)
    with pytest.raises(glint.Error, match="nlm_h: 'strong': wrong type for this option"):
        glint.denoise.run(image, method="nlm", nlm_h="strong")
    with pytest.raises(glint.Error, match="patch"):
        glint.denoise.noise_map(image, patch=4)
