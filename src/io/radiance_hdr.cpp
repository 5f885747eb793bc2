#include "io/radiance_hdr.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.h"
#include "core/limits.h"

namespace glint::io {
namespace {

using Rgbe = std::array<std::uint8_t, 4>;

// The bytes of one file, consumed from the front; every read names what ran short.
class Reader {
 public:
  Reader(const std::string& path, std::string_view bytes) : path_(path), bytes_(bytes) {}

  // The next line without its '\n'; throws when no '\n' is left.
  std::string_view line(const char* what) {
    const std::size_t end = bytes_.find('\n');
    if (end == std::string_view::npos) fail(fmt::format("the file ends inside {}", what));
    const std::string_view text = bytes_.substr(0, end);
    bytes_.remove_prefix(end + 1);
    return text;
  }

  std::uint8_t byte(int row) {
    if (bytes_.empty()) fail(fmt::format("the file ends in scanline {}", row));
    const auto value = std::uint8_t(bytes_.front());
    bytes_.remove_prefix(1);
    return value;
  }

  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(path_, "", "not a readable Radiance HDR file: " + reason);
  }

 private:
  const std::string& path_;
  std::string_view bytes_;
};

// Header text for an error message: at most 40 bytes, anything but printable ASCII as '?'.
std::string quoted(std::string_view text) {
  std::string shown(text.substr(0, 40));
  for (char& c : shown)
    if (c < 0x20 || c > 0x7e) c = '?';
  return "'" + shown + "'";
}

// The header: the magic line, variable lines ("FORMAT=32-bit_rle_rgbe" among them) up to a
// blank line, then the resolution line. Only the standard orientation (rows top to bottom,
// columns left to right) is read.
cv::Size read_header(Reader& reader, const std::string& path) {
  reader.line("the header");
  bool rgbe_format = false;
  for (std::string_view text = reader.line("the header"); !text.empty();
       text = reader.line("the header")) {
    if (text.starts_with("FORMAT=")) {
      if (text != "FORMAT=32-bit_rle_rgbe")
        reader.fail(fmt::format("pixel format {} is not supported (32-bit_rle_rgbe)",
                                quoted(text.substr(7))));
      rgbe_format = true;
    }
  }
  if (!rgbe_format) reader.fail("the header has no FORMAT=32-bit_rle_rgbe line");
  std::string_view line = reader.line("the resolution line");
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
  const std::string resolution(line.substr(0, 80));
  long long height = 0, width = 0;
  int used = 0;
  if (std::sscanf(resolution.c_str(), "-Y %lld +X %lld%n", &height, &width, &used) != 2 ||
      used != int(resolution.size()))
    reader.fail(fmt::format("resolution line {} is not '-Y height +X width'", quoted(line)));
  limits::check_image_size(width, height, path, "header");
  return {int(width), int(height)};
}

// One scanline in the adaptive run-length form: each of the four components in turn as runs
// (count > 128: the next byte count - 128 times) and literals (count bytes).
void read_rle_scanline(Reader& reader, int row, std::vector<Rgbe>& scanline) {
  const int width = int(scanline.size());
  for (int component = 0; component < 4; ++component) {
    for (int x = 0; x < width;) {
      int count = reader.byte(row);
      const bool run = count > 128;
      if (run) count -= 128;
      if (count == 0 || count > width - x)
        reader.fail(fmt::format("scanline {} has a run past its end", row));
      if (run) {
        const std::uint8_t value = reader.byte(row);
        for (int i = 0; i < count; ++i) scanline[x++][component] = value;
      } else {
        for (int i = 0; i < count; ++i) scanline[x++][component] = reader.byte(row);
      }
    }
  }
}

// Ward's RGBE: each component × 2^(exponent − 136); exponent 0 is black.
cv::Vec3f to_bgr(const Rgbe& rgbe) {
  if (rgbe[3] == 0) return {0, 0, 0};
  const float scale = std::ldexp(1.0f, int(rgbe[3]) - (128 + 8));
  return {rgbe[2] * scale, rgbe[1] * scale, rgbe[0] * scale};
}

}  // namespace

bool is_radiance_hdr(std::string_view bytes) {
  return bytes.starts_with("#?RADIANCE") || bytes.starts_with("#?RGBE");
}

cv::Mat decode_radiance_hdr(const std::string& path, std::string_view bytes, int flags) {
  Reader reader(path, bytes);
  const cv::Size size = read_header(reader, path);
  cv::Mat image(size, CV_32FC3);
  std::vector<Rgbe> scanline(std::size_t(size.width));
  // A run-length scanline starts 2, 2, width / 256, width % 256 (widths 8 to 32767). Any other
  // start is a flat pixel, and the rest of the file is flat too (as Radiance's own reader).
  bool flat = size.width < 8 || size.width >= 32768;
  for (int row = 0; row < size.height; ++row) {
    for (int x = 0; x < size.width; ++x) {
      Rgbe& pixel = scanline[std::size_t(x)];
      for (std::uint8_t& component : pixel) component = reader.byte(row);
      if (x > 0 || flat) continue;
      if (pixel[0] == 2 && pixel[1] == 2 && pixel[2] < 128) {
        if ((pixel[2] << 8 | pixel[3]) != size.width)
          reader.fail(fmt::format("scanline {} declares a width other than the image's", row));
        read_rle_scanline(reader, row, scanline);
        break;
      }
      flat = true;
    }
    auto* out = image.ptr<cv::Vec3f>(row);
    for (int x = 0; x < size.width; ++x) out[x] = to_bgr(scanline[std::size_t(x)]);
  }
  // What cv::imread gives for the other flags: 8-bit scaled by 255, or grey.
  if (flags == cv::IMREAD_UNCHANGED) return image;
  if ((flags & cv::IMREAD_ANYDEPTH) == 0) image.convertTo(image, CV_8U, 255.0);
  if ((flags & (cv::IMREAD_COLOR | cv::IMREAD_ANYCOLOR)) == 0)
    cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  return image;
}

}  // namespace glint::io
