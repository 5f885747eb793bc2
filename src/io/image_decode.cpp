#include "io/image_decode.h"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/file_bytes.h"
#include "io/radiance_hdr.h"

namespace glint::io {
namespace {

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);

std::uint32_t big_endian_32(std::string_view bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) value = value << 8 | std::uint8_t(bytes[at + i]);
  return value;
}

std::int32_t little_endian_32(std::string_view bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 4; i-- > 0;) value = value << 8 | std::uint8_t(bytes[at + i]);
  return static_cast<std::int32_t>(value);
}

struct Size {
  std::int64_t width = 0, height = 0;
};

// JPEG: the first start-of-frame marker (SOF0-SOF15 but DHT C4, JPG C8, DAC CC) holds the size.
std::optional<Size> jpeg_size(std::string_view bytes) {
  std::size_t at = 2;
  while (at + 9 <= bytes.size()) {
    if (std::uint8_t(bytes[at]) != 0xFF) return std::nullopt;
    const std::uint8_t marker = std::uint8_t(bytes[at + 1]);
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    const std::size_t length = std::uint8_t(bytes[at + 2]) << 8 | std::uint8_t(bytes[at + 3]);
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
      return Size{std::uint8_t(bytes[at + 7]) << 8 | std::uint8_t(bytes[at + 8]),
                  std::uint8_t(bytes[at + 5]) << 8 | std::uint8_t(bytes[at + 6])};
    at += 2 + length;
  }
  return std::nullopt;
}

constexpr std::string_view kExrMagic("\x76\x2f\x31\x01", 4);
constexpr std::uint32_t kExrMultiPartFlag = 0x1000;  // in the version field

// OpenEXR: magic number, version, then a header of attributes "name\0type\0" + int32 size +
// value ended by a null byte (several headers ended by an empty one in a multi-part file).
// OpenEXR allocates and clears each attribute's declared size before reading it, so a garbled
// size costs gigabytes and seconds: every size must fit in the file. Returns each part's
// dataWindow size (box2i: xMin, yMin, xMax, yMax).
std::vector<Size> exr_part_sizes(const std::string& path, std::string_view bytes) {
  const auto fail = [&](const std::string& reason) {
    throw Error(path, "header", "not a readable OpenEXR file: " + reason);
  };
  if (bytes.size() < 8) fail("it ends inside its version field");
  const bool multi_part = (std::uint32_t(little_endian_32(bytes, 4)) & kExrMultiPartFlag) != 0;
  std::vector<Size> sizes;
  std::size_t at = 8;
  do {
    std::optional<Size> window;
    while (at < bytes.size() && bytes[at] != '\0') {
      const std::size_t name_end = bytes.find('\0', at);
      const std::size_t type_end =
          name_end == std::string_view::npos ? name_end : bytes.find('\0', name_end + 1);
      if (type_end == std::string_view::npos || type_end + 5 > bytes.size())
        fail("the header runs past the end of the file");
      const std::string_view name = bytes.substr(at, name_end - at);
      const std::int32_t size = little_endian_32(bytes, type_end + 1);
      const std::size_t value = type_end + 5;
      if (size < 0 || std::size_t(size) > bytes.size() - value)
        fail(fmt::format("the attribute at byte {} declares {} bytes, {} are left in the file", at,
                         size, bytes.size() - value));
      if (name == "dataWindow" && size == 16) {
        const std::int64_t x_min = little_endian_32(bytes, value),
                           y_min = little_endian_32(bytes, value + 4);
        const std::int64_t x_max = little_endian_32(bytes, value + 8),
                           y_max = little_endian_32(bytes, value + 12);
        window = Size{x_max - x_min + 1, y_max - y_min + 1};
      }
      at = value + std::size_t(size);
    }
    if (at >= bytes.size()) fail("the header runs past the end of the file");
    if (!window) fail("a header has no dataWindow");
    sizes.push_back(*window);
    ++at;  // the header's closing null byte
  } while (multi_part && at < bytes.size() && bytes[at] != '\0');
  return sizes;
}

// The formats OpenCV hands to GDAL ("NITF" at byte 0, "DTED" at byte 140) or to GDCM ("DICM" at
// byte 128; OpenCV's GdalDecoder / DICOMDecoder::checkSignature): GDAL tries every raster driver
// it has and prints their complaints on stderr, GDCM aborts the process on some malformed files
// (an assertion). glint reads photographs, depth and environment maps, never these.
std::optional<std::string_view> gis_or_medical_format(std::string_view bytes) {
  if (bytes.starts_with("NITF")) return "a NITF raster";
  if (bytes.size() > 144 && bytes.substr(140, 4) == "DTED") return "a DTED raster";
  if (bytes.size() >= 132 && bytes.substr(128, 4) == "DICM") return "a DICOM file";
  return std::nullopt;
}

// The image's size from a PNG or JPEG header.
std::optional<Size> header_size(std::string_view bytes) {
  if (bytes.starts_with(kPngSignature) && bytes.size() >= 24 && bytes.substr(12, 4) == "IHDR")
    return Size{big_endian_32(bytes, 16), big_endian_32(bytes, 20)};
  if (bytes.starts_with("\xff\xd8\xff")) return jpeg_size(bytes);
  return std::nullopt;
}

// ---- PNG through libpng with glint's own message handlers: libpng's default ones print to
// stderr ("libpng warning: iCCP: ...", "libpng error: ...") before glint's line, and OpenCV
// installs none. The transformations are those of OpenCV 4.6's PngDecoder, so the decoded
// samples are the same as cv::imdecode's.

struct PngSource {
  std::string_view bytes;
  std::size_t at = 0;
  std::string error;  // libpng's message when it gave up
  std::jmp_buf jump;
};

extern "C" void png_read_from_memory(png_structp png, png_bytep out, png_size_t size) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (size > source->bytes.size() - source->at) png_error(png, "the file ends early");
  std::memcpy(out, source->bytes.data() + source->at, size);
  source->at += size;
}

extern "C" void png_on_error(png_structp png, png_const_charp message) {
  auto* source = static_cast<PngSource*>(png_get_error_ptr(png));
  source->error = message;
  std::longjmp(source->jump, 1);
}

// A damaged ancillary chunk (a bad colour profile, text) does not stop the decode: its warning
// is dropped, as the chunk is.
extern "C" void png_on_warning(png_structp, png_const_charp) {}

struct PngStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngStructs() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

// The header's size and colour type; false with source.error set when libpng failed. Nothing
// with a destructor lives in these two frames between setjmp and libpng's longjmp.
bool read_png_header(PngSource& source, png_structp png, png_infop info, png_uint_32& width,
                     png_uint_32& height, int& bit_depth, int& colour_type) {
  if (setjmp(source.jump)) return false;
  png_read_info(png, info);
  png_get_IHDR(png, info, &width, &height, &bit_depth, &colour_type, nullptr, nullptr, nullptr);
  return true;
}

// Decodes into `image`, allocated with the type cv::imdecode would give (`rows` point at its
// rows), with OpenCV's PngDecoder::readData transformations.
bool read_png_rows(PngSource& source, png_structp png, png_infop info, int colour_type,
                   int bit_depth, cv::Mat& image, png_bytepp rows) {
  if (setjmp(source.jump)) return false;
  const bool colour = image.channels() > 1;
  if (image.depth() == CV_8U && bit_depth == 16)
    png_set_strip_16(png);
  else
    png_set_swap(png);  // 16-bit samples are big-endian in the file; the host is little-endian
  if (image.channels() < 4)
    png_set_strip_alpha(png);
  else
    png_set_tRNS_to_alpha(png);
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8)
    png_set_expand_gray_1_2_4_to_8(png);
  if ((colour_type & PNG_COLOR_MASK_COLOR) && colour)
    png_set_bgr(png);
  else if (colour)
    png_set_gray_to_rgb(png);
  else
    png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != image.cols * image.elemSize())
    png_error(png, "unexpected row size after conversion");
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

cv::Mat decode_png(const std::string& path, std::string_view bytes, int flags) {
  PngSource source;
  source.bytes = bytes;
  PngStructs structs;
  structs.png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, png_on_error, png_on_warning);
  if (structs.png) structs.info = png_create_info_struct(structs.png);
  if (!structs.png || !structs.info) limits::throw_out_of_memory("the PNG decoder's state", 0);
  png_set_read_fn(structs.png, &source, png_read_from_memory);
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  if (!read_png_header(source, structs.png, structs.info, width, height, bit_depth, colour_type))
    throw Error(path, "", "not a readable PNG: " + source.error);
  // The type cv::imdecode gives for these flags (OpenCV's PngDecoder::readHeader, calcType).
  int channels = 1;
  if (colour_type == PNG_COLOR_TYPE_RGB || colour_type == PNG_COLOR_TYPE_PALETTE) {
    png_bytep alpha = nullptr;
    int alpha_count = 0;
    png_color_16p alpha_values = nullptr;
    png_get_tRNS(structs.png, structs.info, &alpha, &alpha_count, &alpha_values);
    channels = alpha_count > 0 ? 4 : 3;
  } else if (colour_type == PNG_COLOR_TYPE_GRAY_ALPHA || colour_type == PNG_COLOR_TYPE_RGB_ALPHA) {
    channels = 4;
  }
  int depth = bit_depth == 16 ? CV_16U : CV_8U;
  if (flags != cv::IMREAD_UNCHANGED) {
    if ((flags & cv::IMREAD_ANYDEPTH) == 0) depth = CV_8U;
    if ((flags & cv::IMREAD_ANYCOLOR) == 0) channels = (flags & cv::IMREAD_COLOR) ? 3 : 1;
  }
  cv::Mat image;
  try {
    image.create(static_cast<int>(height), static_cast<int>(width), CV_MAKETYPE(depth, channels));
  } catch (const cv::Exception&) {
    limits::throw_out_of_memory(
        fmt::format("a {}x{} image of {} channels", width, height, channels),
        double(width) * height * channels * (depth == CV_8U ? 1 : 2));
  }
  std::vector<png_bytep> rows(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = image.ptr(static_cast<int>(y));
  if (!read_png_rows(source, structs.png, structs.info, colour_type, bit_depth, image, rows.data()))
    throw Error(path, "", "not a readable PNG: " + source.error);
  return image;
}

// OpenCV prints "imread_(...): can't read data: <reason>" on std::cerr when a decoder throws,
// and returns an empty image. While one lives, std::cerr writes into text() instead, so the
// reason becomes part of glint's line. One at a time (std::cerr is global); PNG, the format of
// every RGB-D frame, does not come here.
class OpenCvMessages {
 public:
  OpenCvMessages() : lock_(mutex()), previous_(std::cerr.rdbuf(captured_.rdbuf())) {}
  ~OpenCvMessages() { std::cerr.rdbuf(previous_); }
  OpenCvMessages(const OpenCvMessages&) = delete;
  OpenCvMessages& operator=(const OpenCvMessages&) = delete;

  // The reason OpenCV gave, one line, or "" when it printed nothing.
  std::string reason() const {
    std::string text = captured_.str();
    const std::size_t colon = text.find("can't read data: ");
    if (colon != std::string::npos) text = text.substr(colon + 17);
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    std::replace(text.begin(), text.end(), '\n', ' ');
    return text;
  }

 private:
  static std::mutex& mutex() {
    static std::mutex instance;
    return instance;
  }
  std::lock_guard<std::mutex> lock_;
  std::ostringstream captured_;
  std::streambuf* previous_;
};

}  // namespace

void require_complete_image(const std::string& path, std::string_view bytes) {
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

void require_image_size_allowed(const std::string& path, std::string_view bytes) {
  if (bytes.starts_with(kExrMagic)) {
    for (const Size& size : exr_part_sizes(path, bytes))
      limits::check_image_size(size.width, size.height, path, "header");
    return;
  }
  if (const std::optional<Size> size = header_size(bytes))
    limits::check_image_size(size->width, size->height, path, "header");
}

cv::Mat decode_image_file(const std::string& path, int flags) {
  // OpenCV's own bound for the formats whose header glint does not read (read once, on first use).
  static const bool bounded = [] {
    return ::setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(limits::kMaxImagePixels).c_str(),
                    0) == 0;
  }();
  (void)bounded;
  const std::string bytes = read_file_bytes(path);
  if (bytes.empty()) throw Error(path, "", "the file is empty");
  require_image_size_allowed(path, bytes);
  require_complete_image(path, bytes);
  if (std::string_view(bytes).starts_with(kPngSignature)) return decode_png(path, bytes, flags);
  if (const auto format = gis_or_medical_format(bytes))
    throw Error(
        path, "",
        fmt::format("{}, which glint does not read (convert it to PNG, TIFF or EXR)", *format));
  if (is_radiance_hdr(bytes)) return decode_radiance_hdr(path, bytes, flags);
  cv::Mat image;
  OpenCvMessages messages;
  try {
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U,
                         const_cast<char*>(bytes.data()));  // imdecode only reads it
    image = cv::imdecode(buffer, flags);
  } catch (const cv::Exception& e) {
    throw Error(path, "", "cannot decode the image: " + e.err);
  }
  if (image.empty()) {
    const std::string reason = messages.reason();
    throw Error(path, "",
                reason.empty() ? "not a readable image (unknown format, corrupt or truncated)"
                               : "not a readable image: " + reason);
  }
  return image;
}

}  // namespace glint::io
