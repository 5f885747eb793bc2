"""glint.edges against `glint edges classify|features` on the same cloud."""

import numpy as np
import pytest

import glint


def test_classify_equals_cli(cloud_file, cli, tmp_path):
    out = tmp_path / "cli.ply"
    cli("edges", "classify", cloud_file, "-o", out)
    _, cli_fields = glint.io.read_point_cloud(out)

    xyz, _ = glint.io.read_point_cloud(cloud_file)
    labels, probs = glint.edges.classify(xyz)
    assert labels.dtype == np.uint8 and labels.shape == (len(xyz),)
    assert probs.dtype == np.float32 and probs.shape == (len(xyz), 2)
    np.testing.assert_array_equal(labels, cli_fields["scalar_label"])
    np.testing.assert_array_equal(probs[:, 0], cli_fields["scalar_p_sharp"])
    np.testing.assert_array_equal(probs[:, 1], cli_fields["scalar_p_boundary"])


def test_classify_takes_float64_and_any_strides(cloud_file):
    xyz, _ = glint.io.read_point_cloud(cloud_file)
    labels, probs = glint.edges.classify(xyz)
    # float64 holding the same float32 values, and a Fortran-ordered copy: the same result.
    labels64, probs64 = glint.edges.classify(xyz.astype(np.float64))
    labels_f, _ = glint.edges.classify(np.asfortranarray(xyz))
    np.testing.assert_array_equal(labels, labels64)
    np.testing.assert_array_equal(probs, probs64)
    np.testing.assert_array_equal(labels, labels_f)


def test_classify_scales_and_model_options(cloud_file, cli, tmp_path):
    from conftest import REPO
    model = REPO / "models/bounded-2c.json"
    out = tmp_path / "cli.ply"
    cli("edges", "classify", cloud_file, "-o", out, "--scales", "64,32,16,8", "--model", model)
    _, cli_fields = glint.io.read_point_cloud(out)
    xyz, _ = glint.io.read_point_cloud(cloud_file)
    labels, probs = glint.edges.classify(xyz, model=model, scales=[64, 32, 16, 8])
    np.testing.assert_array_equal(labels, cli_fields["scalar_label"])
    np.testing.assert_array_equal(probs[:, 0], cli_fields["scalar_p_sharp"])
    assert not probs[:, 1].any()  # a 2-class model has no boundary class


def test_classify_takes_a_noise_gated_model(cli, tmp_path):
    import json
    from conftest import REPO
    # The shipped 3-class network without its sampling gate, and a second network that differs
    # from it: more weight on the boundary class.
    network = json.loads((REPO / "models/bounded-3c.json").read_text())
    network.pop("sampling_gate", None)
    shipped = tmp_path / "shipped.json"
    shipped.write_text(json.dumps(network))
    network["layers"][-1]["bias"][2] += 4.0
    low_noise = tmp_path / "low-noise.json"
    low_noise.write_text(json.dumps(network))
    gated = tmp_path / "gated.json"
    refused = cli("edges", "gate", shipped, REPO / "models/bounded-2c.json", "--threshold", "0.1",
                  "-o", gated, check=False)
    assert refused.returncode == 1 and "bounded-2c.json" in refused.stderr
    cli("edges", "gate", shipped, low_noise, "--threshold", "0.1", "-o", gated)

    # A clean plane: every point is quiet, so the low-noise network answers.
    x, y = np.meshgrid(np.arange(60, dtype=np.float32), np.arange(60, dtype=np.float32))
    plane = np.stack([x.ravel(), y.ravel(), np.zeros(x.size, np.float32)], axis=1)
    labels, probs = glint.edges.classify(plane, model=gated)
    expected_labels, expected_probs = glint.edges.classify(plane, model=low_noise)
    np.testing.assert_array_equal(labels, expected_labels)
    np.testing.assert_array_equal(probs, expected_probs)
    assert not np.array_equal(probs, glint.edges.classify(plane, model=shipped)[1])


def test_features_equal_cli(cloud_file, cli, tmp_path):
    out = tmp_path / "features.npy"
    cli("edges", "features", cloud_file, "-o", out, "--scales", "32,16")
    xyz, _ = glint.io.read_point_cloud(cloud_file)
    features = glint.edges.features(xyz, scales=[32, 16])
    assert features.shape == (len(xyz), 24) and features.dtype == np.float32
    np.testing.assert_array_equal(features, np.load(out))

    cli("edges", "features", cloud_file, "-o", out, "--scales", "32,16", "--angular-gap")
    with_gap = glint.edges.features(xyz, scales=[32, 16], angular_gap=True)
    assert with_gap.shape == (len(xyz), 26)
    np.testing.assert_array_equal(with_gap, np.load(out))
    # The thesis's twelve values per scale, then the gap, a fraction of the turn.
    np.testing.assert_array_equal(with_gap[:, [*range(12), *range(13, 25)]], features)
    assert ((with_gap[:, [12, 25]] >= 0) & (with_gap[:, [12, 25]] <= 1)).all()

    cli("edges", "features", cloud_file, "-o", out, "--scales", "32,16", "--area-weights")
    by_area = glint.edges.features(xyz, scales=[32, 16], area_weights=True)
    assert by_area.shape == features.shape and np.isfinite(by_area).all()
    np.testing.assert_array_equal(by_area, np.load(out))


def test_bad_inputs_raise_glint_error():
    with pytest.raises(glint.Error, match=r"xyz: must be an \(N, 3\) array of positions, got "
                                          r"shape \(5, 2\)"):
        glint.edges.classify(np.zeros((5, 2), np.float32))
    with pytest.raises(glint.Error, match="xyz: must be float32 or float64, got int64"):
        glint.edges.classify(np.zeros((5, 3), np.int64))
    with pytest.raises(glint.Error, match="expected a NumPy array, got list"):
        glint.edges.classify([[0, 0, 0]])
    bad = np.zeros((200, 3), np.float32)
    bad[17, 1] = np.nan
    with pytest.raises(glint.Error, match="xyz: row 17: non-finite coordinate") as caught:
        glint.edges.classify(bad)
    assert caught.value.file == "xyz" and caught.value.element == "row 17"
    assert caught.value.reason == "non-finite coordinate"
    assert isinstance(caught.value, RuntimeError)


def test_errors_carry_the_cli_message(cli, tmp_path):
    missing = tmp_path / "missing.json"
    xyz = np.random.default_rng(1).random((300, 3), np.float32)
    with pytest.raises(glint.Error) as caught:
        glint.edges.classify(xyz, model=missing)
    cloud = tmp_path / "c.xyz"
    glint.io.write_point_cloud(cloud, xyz)
    result = cli("edges", "classify", cloud, "-o", tmp_path / "o.ply", "--model", missing,
                 check=False)
    assert result.returncode == 1
    assert result.stderr.strip() == f"glint: error: {caught.value}"
