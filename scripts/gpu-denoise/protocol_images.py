# The protocol images as glint denoise eval --save writes them (8-bit PNG), as planar float32
# in [0, 1] (channels, rows, columns): glint's Image layout. Shared by prep.py and score.py.
import numpy as np
from PIL import Image


def load(path):
    a = np.asarray(Image.open(path), dtype=np.float32) / 255.0
    return a[None] if a.ndim == 2 else a.transpose(2, 0, 1)
