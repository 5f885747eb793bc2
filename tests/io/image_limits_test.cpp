// Image decoding: the size in a file's header is checked against the pixel budget before any
// pixel is decoded, and an OpenEXR header's attribute sizes against the file; libpng's messages
// become part of glint's one error line (nothing of their own on stderr), with the samples
// cv::imdecode gives; GIS and DICOM files are refused before OpenCV hands them to GDAL or GDCM;
// a failed Radiance HDR read leaves no temporary copy of the input behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "io/image_decode.h"
#include "io/image_io.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::read_text;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

std::string big_endian(std::uint32_t value) {
  return {char(value >> 24), char(value >> 16), char(value >> 8), char(value)};
}

// A PNG whose header declares width x height (no pixel data; CRCs are not checked first).
std::string png_declaring(std::uint32_t width, std::uint32_t height) {
  return std::string("\x89PNG\r\n\x1a\n", 8) + big_endian(13) + "IHDR" + big_endian(width) +
         big_endian(height) + std::string("\x08\x02\x00\x00\x00", 5) + big_endian(0) +
         big_endian(0) + "IEND" + big_endian(0xAE426082);
}

TEST(ImageLimits, HeaderBeyondThePixelBudgetIsRefusedBeforeDecoding) {
  const std::string png = scratch("huge.png");
  write_text(png, png_declaring(20000, 20000));
  const Error error = error_of([&] { read_image(png); });
  EXPECT_EQ(error.file(), png);
  EXPECT_EQ(error.element(), "header");
  EXPECT_EQ(error.reason(),
            "20000x20000 pixels is outside the allowed image size (each side 1 to 65535, at "
            "most 134217728 pixels in all)");
  // A JPEG's start-of-frame marker is read the same way.
  const std::string jpeg = scratch("huge.jpg");
  write_text(jpeg, std::string("\xff\xd8\xff\xc0\x00\x11\x08\x4e\x20\x9c\x40\x03", 12) +
                       std::string(9, '\x01') + std::string("\xff\xda\x00\x02\xff\xd9", 6));
  EXPECT_THAT(error_of([&] { read_image(jpeg); }).reason(), HasSubstr("40000x20000 pixels"));
}

// OpenEXR allocates an attribute's declared size before reading it: a garbled size is refused
// on the header walk, before OpenEXR sees the file.
TEST(ImageLimits, ExrAttributeLargerThanTheFileIsRefusedBeforeDecoding) {
  const std::string path = scratch("garbled.exr");
  write_image(path, ImageF(8, 4, 3, 0.5f));
  std::string bytes = read_text(path);
  ASSERT_EQ(read_image(path).width(), 8);
  const std::size_t size_field = bytes.find("chlist") + 7;  // the channels attribute's size
  const std::string intact = bytes;
  bytes.replace(size_field, 4, "\xff\xff\xff\x7f");
  write_text(path, bytes);
  const Error error = error_of([&] { read_image(path); });
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.element(), "header");
  EXPECT_THAT(error.reason(), ::testing::MatchesRegex("not a readable OpenEXR file: the "
                                                      "attribute at byte 8 declares 2147483647 "
                                                      "bytes, [0-9]+ are left in the file"));
  write_text(path, intact.substr(0, 20));  // cut inside the first attribute's name and type
  EXPECT_EQ(error_of([&] { read_image(path); }).reason(),
            "not a readable OpenEXR file: the header runs past the end of the file");
}

std::string little_endian(std::int32_t value) {
  const auto bits = std::uint32_t(value);
  return {char(bits), char(bits >> 8), char(bits >> 16), char(bits >> 24)};
}

// One OpenEXR header holding only a dataWindow of width x height, with its closing null byte.
std::string exr_header(std::int32_t width, std::int32_t height) {
  return std::string("dataWindow\0box2i\0", 17) + little_endian(16) + little_endian(0) +
         little_endian(0) + little_endian(width - 1) + little_endian(height - 1) + '\0';
}

TEST(ImageLimits, EveryPartOfAMultiPartExrIsChecked) {
  const std::string magic("\x76\x2f\x31\x01", 4);
  const std::string multi_part = magic + little_endian(2 | 0x1000);
  EXPECT_NO_THROW(require_image_size_allowed(
      "two.exr", multi_part + exr_header(8, 4) + exr_header(16, 2) + '\0' + "offsets"));
  const Error error = error_of([&] {
    require_image_size_allowed(
        "two.exr", multi_part + exr_header(8, 4) + exr_header(20000, 20000) + '\0' + "offsets");
  });
  EXPECT_THAT(error.reason(), HasSubstr("20000x20000 pixels"));
  // A single-part file ends its header list after one header, whatever follows.
  EXPECT_NO_THROW(require_image_size_allowed(
      "one.exr", magic + little_endian(2) + exr_header(8, 4) + "\xff\xff\xff\x7f offsets"));
  EXPECT_THAT(error_of([&] {
                require_image_size_allowed("none.exr", magic + little_endian(2) + '\0');
              }).reason(),
              HasSubstr("a header has no dataWindow"));
}

// OpenCV would pass these to GDAL, which tries all of its drivers and prints on stderr, and to
// GDCM, which aborts on some malformed DICOM files (an assertion; such a file is
// fuzz/corpus/image/regression-dicom-gdcm-assertion).
TEST(ImageLimits, GisAndMedicalFormatsAreRefusedWithOneLine) {
  const std::string nitf = scratch("map.ntf");
  write_text(nitf, "NITF02.10" + std::string(400, '0'));
  const std::string dicom = scratch("scan.dcm");
  write_text(dicom, std::string(128, '\x10') + "DICM" + std::string(64, '\x10'));
  for (const auto& [file, format] : {std::pair{nitf, "a NITF raster"}, {dicom, "a DICOM file"}}) {
    const std::string& path = file;  // clang 14 cannot capture a structured binding
    ::testing::internal::CaptureStderr();
    const Error error = error_of([&] { read_image(path); });
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    EXPECT_EQ(error.file(), path);
    EXPECT_EQ(error.reason(),
              std::string(format) + ", which glint does not read (convert it to PNG, TIFF or EXR)");
  }
}

TEST(ImageLimits, CorruptPngIsOneErrorWithLibpngsReasonAndNothingOnStderr) {
  const std::string path = scratch("corrupt.png");
  write_image(path, ImageF(32, 32, 3, 0.25f));
  std::string bytes = read_text(path);
  const std::size_t data = bytes.find("IDAT") + 8;
  bytes[data] = char(bytes[data] ^ 0x55);  // damaged compressed data
  write_text(path, bytes);
  ::testing::internal::CaptureStderr();
  const Error error = error_of([&] { read_image(path); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(error.file(), path);
  // zlib meets the damage before the chunk's CRC is checked: libpng's reason, whichever it is.
  EXPECT_THAT(error.reason(), ::testing::StartsWith("not a readable PNG: IDAT: "));
}

TEST(ImageLimits, PngSamplesAreThoseOfOpenCv) {
  cv::RNG random(7);
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    cv::Mat image(9, 13, type);
    random.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_8U ? 256 : 65536);
    std::vector<std::uint8_t> encoded;
    ASSERT_TRUE(cv::imencode(".png", image, encoded));
    const std::string path = scratch("samples.png");
    write_text(path, std::string(encoded.begin(), encoded.end()));
    for (const int flags : {cv::IMREAD_UNCHANGED, cv::IMREAD_ANYDEPTH, cv::IMREAD_COLOR}) {
      const cv::Mat ours = decode_image_file(path, flags);
      const cv::Mat opencv = cv::imdecode(encoded, flags);
      ASSERT_EQ(ours.type(), opencv.type()) << type << " " << flags;
      EXPECT_EQ(cv::norm(ours, opencv, cv::NORM_INF), 0) << type << " " << flags;
    }
  }
}

TEST(ImageLimits, FailedHdrReadLeavesNoTemporaryFile) {
  const std::filesystem::path temporaries = test::scratch_folder() / "opencv-temporaries";
  std::filesystem::create_directories(temporaries);
  ::setenv("OPENCV_TEMP_PATH", temporaries.c_str(), 1);
  const std::string path = scratch("broken.hdr");
  write_text(path, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 4\n\x02\x02");
  ::testing::internal::CaptureStderr();
  const Error error = error_of([&] { read_image(path); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.reason(), "not a readable Radiance HDR file: the file ends in scanline 0");
  ::unsetenv("OPENCV_TEMP_PATH");
  EXPECT_TRUE(std::filesystem::is_empty(temporaries));
}

}  // namespace
}  // namespace glint::io
