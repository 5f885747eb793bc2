"""glint.io: round trips through glint's readers and writers, and what they keep."""

import numpy as np
import pytest

import glint


def test_point_cloud_round_trip_with_labels_and_fields(tmp_path):
    rng = np.random.default_rng(2)
    xyz = rng.random((500, 3)).astype(np.float32)
    labels = rng.integers(0, 3, 500).astype(np.uint8)
    probs = rng.random((500, 2)).astype(np.float32)
    intensity = rng.random(500)
    path = tmp_path / "out.ply"
    glint.io.write_point_cloud(path, xyz, labels=labels, probs=probs,
                               fields={"intensity": intensity})
    read, fields = glint.io.read_point_cloud(path)
    np.testing.assert_array_equal(read, xyz)
    np.testing.assert_array_equal(fields["scalar_label"], labels)
    np.testing.assert_array_equal(fields["scalar_p_sharp"], probs[:, 0])
    np.testing.assert_array_equal(fields["scalar_p_boundary"], probs[:, 1])
    np.testing.assert_array_equal(fields["intensity"], intensity)
    # Red marks sharp points, as `glint edges classify` writes them.
    assert (fields["red"][labels == 1] == 230).all()


def test_image_round_trip_and_layout(tmp_path):
    image = np.random.default_rng(4).random((30, 20, 3)).astype(np.float32)
    glint.io.write_image(tmp_path / "a.exr", image)
    read = glint.io.read_image(tmp_path / "a.exr")
    assert read.shape == (30, 20, 3) and read.dtype == np.float32
    np.testing.assert_array_equal(read, image)
    # The result is a view of glint's planar image: channel-major strides, no copy.
    assert read.strides == (20 * 4, 4, 30 * 20 * 4)
    glint.io.write_image(tmp_path / "a.png", image, depth=16)
    np.testing.assert_allclose(glint.io.read_image(tmp_path / "a.png"), image, atol=1 / 65535)


def test_io_errors(tmp_path):
    with pytest.raises(glint.Error, match="missing.ply"):
        glint.io.read_point_cloud(tmp_path / "missing.ply")
    with pytest.raises(glint.Error, match="cannot write point-cloud format '.las'"):
        glint.io.write_point_cloud(tmp_path / "x.las", np.zeros((3, 3)))
    with pytest.raises(glint.Error, match="labels: must be a 1-D array of 3 values"):
        glint.io.write_point_cloud(tmp_path / "x.ply", np.zeros((3, 3)),
                                   labels=np.zeros(2, np.uint8))
    with pytest.raises(glint.Error, match=r"image: must be an \(H, W\) or \(H, W, C\) image"):
        glint.io.write_image(tmp_path / "x.png", np.zeros(5, np.float32))
    with pytest.raises(glint.Error, match="must be float32, float64, uint8 or uint16, got bool"):
        glint.io.write_image(tmp_path / "x.png", np.zeros((4, 4), bool))
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_rgbd_sequence_fixture(request):
    from conftest import REPO
    seq = glint.io.open_rgbd_sequence(REPO / "tests/data/rgbd/glint")
    assert len(seq) == 3 and seq.format == "glint"
    frame = seq[-1]
    k = seq.intrinsics
    assert frame["rgb"].shape == (k["height"], k["width"], 3)
    assert frame["depth"].shape == (k["height"], k["width"])
    assert frame["pose"].shape == (4, 4) and frame["index"] == 2
    with pytest.raises(IndexError):
        seq[3]
    assert len(list(seq)) == 3
