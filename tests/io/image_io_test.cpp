#include "io/image_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::read_text;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

ImageF random_image(int width, int height, int channels, float low = 0.f, float high = 1.f) {
  ImageF image(width, height, channels);
  std::mt19937_64 random(static_cast<std::uint64_t>(channels));
  std::uniform_real_distribution<float> uniform(low, high);
  for (float& v : image.values()) v = uniform(random);
  return image;
}

float largest_difference(const ImageF& a, const ImageF& b) {
  float largest = 0;
  for (std::size_t i = 0; i < a.values().size(); ++i) {
    largest = std::max(largest, std::abs(a.values()[i] - b.values()[i]));
  }
  return largest;
}

void expect_same_shape(const ImageF& a, const ImageF& b) {
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  ASSERT_EQ(a.channels(), b.channels());
}

TEST(ImageIo, PngRoundTripsWithinHalfAStep) {
  for (const int channels : {1, 3, 4}) {
    SCOPED_TRACE(channels);
    const ImageF image = random_image(13, 7, channels);
    const std::string path = scratch("image.png");
    write_image(path, image);
    const ImageF eight = read_image(path);
    expect_same_shape(eight, image);
    EXPECT_LE(largest_difference(eight, image), 0.5f / 255 + 1e-6f);
    write_image(path, image, PngDepth::sixteen);
    const ImageF sixteen = read_image(path);
    expect_same_shape(sixteen, image);
    EXPECT_LE(largest_difference(sixteen, image), 0.5f / 65535 + 1e-7f);
  }
}

TEST(ImageIo, ExrRoundTripsExactly) {
  for (const int channels : {1, 3, 4}) {
    SCOPED_TRACE(channels);
    const ImageF image = random_image(9, 11, channels, -2.f, 40.f);  // HDR values stay as they are
    const std::string path = scratch("image.exr");
    write_image(path, image);
    const ImageF back = read_image(path);
    expect_same_shape(back, image);
    EXPECT_EQ(back.values(), image.values());
  }
}

TEST(ImageIo, PngClampsAndKeepsTheRgbOrderOnDisk) {
  ImageF image(2, 1, 3);
  image.at(0, 0, 0) = 1.5f;   // red, clamped to 1
  image.at(0, 0, 2) = -0.5f;  // blue, clamped to 0
  image.at(1, 0, 2) = 1.f;
  const std::string path = scratch("order.png");
  write_image(path, image);
  const cv::Mat bgr = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(255, 0, 0));
  const ImageF back = read_image(path);
  EXPECT_EQ(back.at(0, 0, 0), 1.f);
  EXPECT_EQ(back.at(0, 0, 2), 0.f);
}

TEST(ImageIo, WritingLeavesNoTemporaryBehind) {
  const std::string path = scratch("only.png");
  write_image(path, random_image(4, 4, 3));
  write_image(path, random_image(4, 4, 1));  // replaces the old image
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(test::scratch_folder())) {
    names.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(names, std::vector<std::string>{"only.png"});
  EXPECT_EQ(read_image(path).channels(), 1);
}

TEST(ImageIo, UnreadableFilesAreErrorsNamingTheFile) {
  const std::string missing = scratch("missing.png");
  Error e = error_of([&] { read_image(missing); });
  EXPECT_EQ(e.file(), missing);
  EXPECT_THAT(e.reason(), HasSubstr("cannot open the file"));

  const std::string text = scratch("text.png");
  write_text(text, "this is not an image\n");
  e = error_of([&] { read_image(text); });
  EXPECT_EQ(e.file(), text);
  EXPECT_THAT(e.reason(), HasSubstr("not a readable image"));

  const std::string truncated = scratch("truncated.png");
  write_image(truncated, random_image(64, 64, 3));
  const std::string bytes = read_text(truncated);
  write_text(truncated, bytes.substr(0, bytes.size() / 2));
  e = error_of([&] { read_image(truncated); });
  EXPECT_EQ(e.file(), truncated);
  EXPECT_THAT(e.reason(), HasSubstr("truncated PNG"));

  // A PNG whose header says 0 pixels wide (crafted: no encoder writes one).
  const std::string zero_width = test::fixture("zero_width.png");
  e = error_of([&] { read_image(zero_width); });
  EXPECT_EQ(e.file(), zero_width);
  EXPECT_THAT(e.reason(), HasSubstr("outside the allowed image size"));

  const std::string empty = scratch("empty.exr");
  write_text(empty, "");
  EXPECT_THAT(error_of([&] { read_image(empty); }).reason(), HasSubstr("empty"));
}

// libjpeg decodes a JPEG cut short without an error (grey where the data ends), so a truncated
// one is caught before decoding; bytes appended after a complete one are no reason to refuse it.
TEST(ImageIo, TruncatedJpegIsAnErrorButTrailingBytesAreNot) {
  cv::Mat colour(48, 64, CV_8UC3);
  cv::randu(colour, 0, 255);
  std::vector<unsigned char> encoded;
  ASSERT_TRUE(cv::imencode(".jpg", colour, encoded));
  const std::string jpeg(encoded.begin(), encoded.end());

  const std::string whole = scratch("whole.jpg");
  write_text(whole, jpeg + std::string(16, '\0') + "appended");
  const ImageF image = read_image(whole);
  EXPECT_EQ(image.width(), 64);
  EXPECT_EQ(image.height(), 48);

  const std::string truncated = scratch("truncated.jpg");
  write_text(truncated, jpeg.substr(0, jpeg.size() * 3 / 4));
  const Error e = error_of([&] { read_image(truncated); });
  EXPECT_EQ(e.file(), truncated);
  EXPECT_THAT(e.reason(), HasSubstr("truncated JPEG"));
}

TEST(ImageIo, UnwritableImagesAreErrorsNamingTheFile) {
  const ImageF image = random_image(4, 4, 3);
  for (const std::string name : {"image.bmp", "image"}) {
    const std::string path = scratch(name);
    const Error e = error_of([&] { write_image(path, image); });
    EXPECT_EQ(e.file(), path);
    EXPECT_THAT(e.reason(), HasSubstr("unknown image extension"));
  }
  const std::string path = scratch("image.png");
  EXPECT_THAT(error_of([&] { write_image(path, ImageF()); }).reason(), HasSubstr("no pixels"));
  EXPECT_THAT(error_of([&] { write_image(path, random_image(4, 4, 2)); }).reason(),
              HasSubstr("cannot write 2 channels"));
  ImageF with_nan = image;
  with_nan.at(1, 2, 1) = NAN;
  const Error e = error_of([&] { write_image(path, with_nan); });
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.element(), "pixel (1, 2), channel 1");
  EXPECT_FALSE(std::filesystem::exists(path));
  test::write_text(scratch("plain"), "a file, not a folder");
  EXPECT_EQ(error_of([&] { write_image(scratch("plain/image.exr"), image); }).file(),
            scratch("plain/image.exr"));
}

}  // namespace
}  // namespace glint::io
