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

// Throws glint::Error(path, "header", ...) when a PNG, JPEG or OpenEXR header declares a size
// beyond core/limits.h's pixel budget, or when an OpenEXR header is cut short, lacks its
// dataWindow or declares an attribute larger than the rest of the file (which OpenEXR would
// allocate). Radiance HDR headers are checked by io/radiance_hdr.h before any pixel; other
// formats are not checked here.
void require_image_size_allowed(const std::string& path, std::string_view bytes);

// Reads and decodes the image file with cv::imdecode `flags`; throws glint::Error naming it
// when it is missing, empty, truncated, larger than the pixel budget (checked on the header,
// before decoding), a GIS raster or DICOM file (which OpenCV would pass to GDAL or GDCM) or not
// decodable. PNG goes through libpng with glint's own message handlers (libpng's messages become
// part of the one error line, never a line of their own); Radiance HDR is decoded by
// io/radiance_hdr.h.
cv::Mat decode_image_file(const std::string& path, int flags);

}  // namespace glint::io
