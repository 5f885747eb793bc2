#include "io/image_decode.h"

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/file_bytes.h"

namespace glint::io {

void require_complete_image(const std::string& path, std::string_view bytes) {
  constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
  if (bytes.starts_with(kPngSignature)) {
    // The IEND chunk: length 0, type, 4 CRC bytes; nothing of the image follows it.
    const std::size_t end = bytes.rfind("IEND");
    if (end == std::string_view::npos || end + 8 > bytes.size())
      throw Error(path, "", "truncated PNG: it ends before its IEND chunk");
    return;
  }
  if (bytes.starts_with("\xff\xd8\xff")) {
    // Scan data escapes 0xFF bytes, so FF DA (start of scan) and FF D9 (end of image) occur
    // only as markers; a thumbnail's markers come before the main image's scans.
    const std::size_t last_scan = bytes.rfind("\xff\xda");
    if (last_scan == std::string_view::npos ||
        bytes.find("\xff\xd9", last_scan) == std::string_view::npos)
      throw Error(path, "", "truncated JPEG: no end-of-image marker after its last scan");
  }
}

cv::Mat decode_image_file(const std::string& path, int flags) {
  const std::string bytes = read_file_bytes(path);
  if (bytes.empty()) throw Error(path, "", "the file is empty");
  require_complete_image(path, bytes);
  cv::Mat image;
  try {
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U,
                         const_cast<char*>(bytes.data()));  // imdecode only reads it
    image = cv::imdecode(buffer, flags);
  } catch (const cv::Exception& e) {
    throw Error(path, "", "cannot decode the image: " + e.err);
  }
  if (image.empty())
    throw Error(path, "", "not a readable image (unknown format, corrupt or truncated)");
  return image;
}

}  // namespace glint::io
