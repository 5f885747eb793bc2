"""glint's readers and writers with NumPy arrays: point clouds (PLY, XYZ/PTS/TXT, PCD), images
(PNG, EXR, NPY) and RGB-D sequences (glint synthetic, TUM, 7-Scenes, Redwood)."""

from ._glint.io import (RgbdSequence, open_rgbd_sequence, read_image, read_point_cloud,
                        write_image, write_point_cloud)

__all__ = ["RgbdSequence", "open_rgbd_sequence", "read_image", "read_point_cloud", "write_image",
           "write_point_cloud"]
