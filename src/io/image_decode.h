#pragma once
// Decoding of image files (PNG, JPEG, EXR and whatever else OpenCV reads) with one clear error
// naming the file. A truncated PNG or JPEG is rejected before decoding: libjpeg decodes a
// JPEG cut short without an error, filling its missing rows with grey (a silently corrupted
// frame), and libpng prints its own line on stderr before failing.
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>

namespace glint::io {

// Throws glint::Error(path, ...) when `bytes` (a whole file) is a PNG without its closing IEND
// chunk, or a JPEG without an end-of-image marker after its last scan. Bytes after a complete
// image (padding, appended data) are allowed; other formats are not checked.
void require_complete_image(const std::string& path, std::string_view bytes);

// Reads and decodes the image file with cv::imdecode `flags`; throws glint::Error naming it
// when it is missing, empty, truncated or not decodable.
cv::Mat decode_image_file(const std::string& path, int flags);

}  // namespace glint::io
