#pragma once
// Radiance HDR (RGBE) images, decoded by glint rather than OpenCV: OpenCV's decoder keeps its file
// open after any failure (one descriptor lost per bad file) and, reading from memory, leaves a
// temporary copy behind. Header and resolution line as Ward's "picture format" note, pixels flat
// or in the adaptive run-length scanlines every current writer uses.
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>

namespace glint::io {

// True when `bytes` starts with a Radiance header's magic ("#?RADIANCE" or "#?RGBE").
bool is_radiance_hdr(std::string_view bytes);

// Decodes the file's `bytes` into the image cv::imread would give for `flags` (32-bit float BGR
// for IMREAD_UNCHANGED); throws glint::Error(path, ...) naming what is wrong: a missing FORMAT
// line, a resolution line other than "-Y height +X width", a size beyond core/limits.h's pixel
// budget, a damaged run or a file that ends early.
cv::Mat decode_radiance_hdr(const std::string& path, std::string_view bytes, int flags);

}  // namespace glint::io
