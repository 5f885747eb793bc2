"""BoundED: per-point non-edge (0) / sharp-edge (1) / boundary (2) labels of a point cloud,
from multi-scale neighbourhood statistics and a small network (thesis ch. 5)."""

from ._glint.edges import classify, features

__all__ = ["classify", "features"]
