#pragma once
// Raster images on disk: PNG (8/16-bit) and OpenEXR (32-bit float) through OpenCV's codecs,
// and NumPy .npy float arrays (height, width[, channels]) for any number of channels.
// In memory every image is an ImageF with values as stored: no sRGB decoding on reading, no
// encoding on writing (material maps are data, not pictures).
#include <string>

#include "core/image.h"

namespace glint::io {

enum class PngDepth { eight, sixteen };

// Reads .npy (float32/64, (H, W) or (H, W, C)), PNG (8/16-bit, grey/RGB/RGBA), EXR (float) and
// anything else OpenCV's imread reads.
// Integer samples are normalised to [0,1] (8-bit / 255, 16-bit / 65535), floats kept as they
// are; channels in R, G, B(, A) order. Throws glint::Error(path, "", reason) for a missing or
// unreadable file, an unknown, corrupt or truncated image and an image without pixels.
ImageF read_image(const std::string& path);

// Writes by extension: .png (values clamped to [0,1] and rounded to 8 or 16 bits; NaN is an
// error) or .exr (32-bit float, written as is), 1, 3 or 4 channels (grey, RGB, RGBA); or .npy
// (float32, any channel count). The file
// is encoded in memory, written to a temporary next to `path` and renamed into place, so a
// failure never leaves a half-written image. Throws glint::Error naming `path`.
void write_image(const std::string& path, const ImageF& image, PngDepth depth = PngDepth::eight);

}  // namespace glint::io
