"""glint.Reconstruction against `glint reconstruct` on a small rendered sequence."""

import json

import numpy as np
import pytest

import glint


@pytest.fixture(scope="module")
def sequence(tmp_path_factory, cli):
    """A 256x212 `cubes` sequence of 12 frames and `glint reconstruct`'s output on it (true
    lights, poses and segments; the shipped HemiCNN)."""
    folder = tmp_path_factory.mktemp("reconstruct")
    cli("synth", "cubes", "--frames", "12", "--width", "256", "--no-shadows", "-o",
        folder / "seq")
    cli("reconstruct", folder / "seq", "--gt-lights", "--gt-poses", "--gt-segmentation",
        "--eval-every", "0", "--obs-spacing", "0", "-o", folder / "cli", "--report",
        folder / "cli-report.json")
    return folder


def run_python(folder, **options):
    seq = glint.io.open_rgbd_sequence(folder / "seq")
    reconstruction = glint.Reconstruction(seq.intrinsics, folder / "cli/lights.json",
                                          gt_poses=True, exposure=seq.exposure, obs_spacing=0,
                                          **options)
    stats = [reconstruction.add_frame(f["rgb"], f["depth"], f["pose"], f["segments"])
             for f in seq]
    return seq, reconstruction, stats


def test_materials_and_outputs_equal_cli(sequence, tmp_path):
    seq, reconstruction, stats = run_python(sequence)
    assert [s["frame"] for s in stats] == list(range(len(seq)))
    assert all(s["integrated"] for s in stats) and stats[-1]["segments"] > 0
    np.testing.assert_array_equal(stats[3]["pose"], seq[3]["pose"])

    cli_materials = json.loads((sequence / "cli/materials.json").read_text())
    assert reconstruction.materials() == cli_materials
    assert cli_materials["segments"] and cli_materials["segments"][0]["estimates"] > 0
    # The gathered light's scale and the stages timed, as the CLI's report; rendered with direct
    # light only, the voxels no light reaches are black and the gathered light is scaled away.
    report = json.loads((sequence / "cli-report.json").read_text())
    assert reconstruction.indirect_scale == pytest.approx(report["indirect_scale"])
    assert reconstruction.indirect_scale < 0.1
    assert set(reconstruction.timings()) == set(report["timings_ms"]) >= {"shadows", "indirect"}

    reconstruction.export(tmp_path / "py")
    for name in ("mesh.ply", "materials.json"):
        assert (tmp_path / "py" / name).read_bytes() == (sequence / "cli" / name).read_bytes()
    assert json.loads((tmp_path / "py/lights.json").read_text())["lights"] == \
        json.loads((sequence / "cli/lights.json").read_text())["lights"]

    mesh = reconstruction.mesh()
    assert mesh["vertices"].shape[1] == 3 and mesh["faces"].dtype == np.int32
    assert mesh["faces"].max() < len(mesh["vertices"])
    assert mesh["kd"].shape == mesh["colours"].shape and mesh["segment"].max() > 0

    # The re-rendering from the last pose, its ray cast started from the frame's depth, is what
    # the CLI wrote (as 8-bit sRGB) for that frame.
    image = reconstruction.render(seq[-1]["pose"], depth=seq[-1]["depth"])
    k = seq.intrinsics
    assert image.shape == (k["height"], k["width"], 3) and image.dtype == np.float32
    written = glint.io.read_image(sequence / f"cli/frames/{len(seq) - 1:06d}-render.png")
    srgb = np.where(image <= 0.0031308, 12.92 * image, 1.055 * np.power(image, 1 / 2.4) - 0.055)
    np.testing.assert_allclose(np.round(srgb * 255) / 255, written, atol=1 / 255 + 1e-6)
    maps = reconstruction.render_maps(seq[-1]["pose"])
    assert maps["segment"].dtype == np.int32 and maps["alpha"].shape == image.shape[:2]


def test_light_transport_options_equal_cli(sequence, tmp_path, cli):
    """Shadows, the shadow test, the unscaled gather mirrored by the lobe and the unseen light as
    `--shadows on --shadow-test on --shadow-test-sigmas 1 --indirect on --indirect-scale off
    --indirect-specular mirror --unseen-light on --albedo-shrinkage off` give the CLI's
    materials."""
    cli("reconstruct", sequence / "seq", "--gt-lights", "--gt-poses", "--gt-segmentation",
        "--eval-every", "0", "--obs-spacing", "0", "--no-glb", "--shadows", "on", "--shadow-test",
        "on", "--shadow-test-sigmas", "1", "--indirect", "on", "--indirect-scale", "off",
        "--indirect-specular", "mirror", "--unseen-light", "on", "--albedo-shrinkage", "off",
        "-o", tmp_path / "cli")
    _, reconstruction, _ = run_python(sequence, shadows=True, shadow_test=True,
                                      shadow_test_sigmas=1.0, indirect=True,
                                      indirect_scale=False, indirect_specular="mirror",
                                      unseen_light=True, albedo_shrinkage=False)
    cli_materials = json.loads((tmp_path / "cli/materials.json").read_text())
    assert reconstruction.materials() == cli_materials
    assert all("unseen_irradiance" in s for s in cli_materials["segments"])
    assert reconstruction.indirect_scale == 1


def test_bad_inputs(sequence):
    seq = glint.io.open_rgbd_sequence(sequence / "seq")
    lights = sequence / "cli/lights.json"
    with pytest.raises(glint.Error, match="intrinsics: fx: missing"):
        glint.Reconstruction({"width": 4, "height": 4}, lights)
    with pytest.raises(glint.Error, match="obs_voxel: must be more than 0, got -1"):
        glint.Reconstruction(seq.intrinsics, lights, obs_voxel=-1)
    with pytest.raises(glint.Error, match="indirect_rays: must be in \\[1, 65535\\], got 0"):
        glint.Reconstruction(seq.intrinsics, lights, indirect_rays=0)
    with pytest.raises(glint.Error, match="albedo_shrinkage: 'yes': wrong type for this option"):
        glint.Reconstruction(seq.intrinsics, lights, albedo_shrinkage="yes")
    with pytest.raises(glint.Error, match="albedo_normal_error: must be finite and >= 0"):
        glint.Reconstruction(seq.intrinsics, lights, albedo_normal_error=-1)
    with pytest.raises(glint.Error, match="shadow_test_sigmas: must be finite and >= 0"):
        glint.Reconstruction(seq.intrinsics, lights, shadow_test_sigmas=-1)
    with pytest.raises(glint.Error, match="specular: phong: must be hemicnn or hemicnn\\+fit"):
        glint.Reconstruction(seq.intrinsics, lights, specular="phong")
    with pytest.raises(glint.Error, match="lights: light 0: needs position and intensity"):
        glint.Reconstruction(seq.intrinsics, [{"position": [0, 1, 0]}])
    reconstruction = glint.Reconstruction(seq.intrinsics, [
        {"position": [0, 2, 0], "intensity": [1, 1, 1]}], gt_poses=True)
    frame = seq[0]
    with pytest.raises(glint.Error, match="rgb: must have 3 channels"):
        reconstruction.add_frame(frame["depth"], frame["depth"], frame["pose"])
    with pytest.raises(glint.Error, match="pose: must be a 4x4 array"):
        reconstruction.add_frame(frame["rgb"], frame["depth"], np.eye(3))
    with pytest.raises(glint.Error):
        reconstruction.add_frame(frame["rgb"][:10], frame["depth"][:10], frame["pose"])
    with pytest.raises(glint.Error, match="exists and is not a glint reconstruction"):
        reconstruction.export(lights)
