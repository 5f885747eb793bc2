// Radiance HDR decoding: the samples cv::imread gives (run-length and flat scanlines, float and
// 8-bit), and bad files as one line each without a file descriptor left open (OpenCV's decoder
// kept one per failed read).
#include "io/radiance_hdr.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "io/image_decode.h"
#include "io/image_io.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::scratch;
using test::write_text;

std::size_t open_descriptors() {
  const std::filesystem::directory_iterator entries("/proc/self/fd");
  return std::size_t(std::distance(begin(entries), end(entries)));
}

TEST(RadianceHdr, SamplesAreThoseOfOpenCv) {
  cv::RNG random(11);
  // Width 13 is written in run-length scanlines, width 5 flat.
  for (const cv::Size size : {cv::Size(13, 9), cv::Size(5, 3)}) {
    cv::Mat image(size, CV_32FC3);
    random.fill(image, cv::RNG::UNIFORM, 0.0, 40.0);
    image(cv::Rect(0, 0, size.width, 1)).setTo(cv::Scalar(0.5, 0.25, 2.0));  // a run
    const std::string path = scratch("samples.hdr");
    ASSERT_TRUE(cv::imwrite(path, image));
    for (const int flags : {int(cv::IMREAD_UNCHANGED), cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR,
                            int(cv::IMREAD_COLOR)}) {
      const cv::Mat ours = decode_image_file(path, flags);
      const cv::Mat opencv = cv::imread(path, flags);
      ASSERT_EQ(ours.type(), opencv.type()) << size << " " << flags;
      EXPECT_EQ(cv::norm(ours, opencv, cv::NORM_INF), 0) << size << " " << flags;
    }
  }
}

TEST(RadianceHdr, BadFilesAreOneLineAndLeaveNoDescriptorOpen) {
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
  const std::string run_start("\x02\x02\x00\x08", 4);
  const std::pair<std::string, std::string> cases[] = {
      {"#?RADIANCE\nEXPOSURE=1\n\n-Y 1 +X 1\n\x80\x80\x80\x80",
       "the header has no FORMAT=32-bit_rle_rgbe line"},
      {"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n",
       "pixel format '32-bit_rle_xyze' is not supported (32-bit_rle_rgbe)"},
      {header + "+Y 4 +X 4\n", "resolution line '+Y 4 +X 4' is not '-Y height +X width'"},
      {header + "-Y 3 +X\xff\xff", "the file ends inside the resolution line"},
      {header + "-Y 3 +X\x01z\n", "resolution line '-Y 3 +X?z' is not '-Y height +X width'"},
      {header + "-Y 1 +X 8\n" + run_start + "\x09", "scanline 0 has a run past its end"},
      {header + "-Y 1 +X 8\n" + std::string("\x02\x02\x00\x09", 4),
       "scanline 0 declares a width other than the image's"},
      {header + "-Y 2 +X 8\n" + run_start + "\x88\x01\x88\x02\x88\x03\x88\x04",
       "the file ends in scanline 1"},
  };
  const std::string path = scratch("bad.hdr");
  const std::size_t before = open_descriptors();
  for (const auto& [bytes, reason] : cases) {
    write_text(path, bytes);
    for (int i = 0; i < 20; ++i)
      EXPECT_EQ(error_of([&] { read_image(path); }).reason(),
                "not a readable Radiance HDR file: " + reason);
  }
  EXPECT_EQ(open_descriptors(), before);
  write_text(path, header + "-Y 40000 +X 40000\n");
  EXPECT_THAT(error_of([&] { read_image(path); }).reason(),
              ::testing::HasSubstr("40000x40000 pixels is outside the allowed image size"));
}

}  // namespace
}  // namespace glint::io
