"""glint: practical real-time reflectance estimation, from Python.

The C++ toolkit's three systems over NumPy arrays, computing exactly what the `glint`
command line computes:

* :mod:`glint.edges` -- BoundED point-cloud edge and boundary detection
  (``classify``, ``features``);
* :mod:`glint.denoise` -- locally-guided image denoising (``noise_map``, ``run``);
* :class:`glint.Reconstruction` -- the online reflectance pipeline, one RGB-D frame at a time;
* :mod:`glint.io` -- point clouds, images and RGB-D sequences through glint's readers and writers.

Errors raise :class:`glint.Error` with the one-line message the CLI prints. The GIL is released
while glint works. See docs/python.md.
"""

from ._glint import (Error, Reconstruction, __version__, cuda, set_log_level, set_quiet,
                     set_threads)
from . import denoise, edges, io

__all__ = ["Error", "Reconstruction", "__version__", "cuda", "denoise", "edges", "io",
           "set_log_level", "set_quiet", "set_threads"]
