#include "io/pcd.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::fixture;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

TEST(Pcd, AsciiDropsNanPointsAndUnpacksFloatRgb) {
  const PointCloud cloud = read_pcd(fixture("organised.pcd"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0, 1}));
  EXPECT_EQ(cloud.z, (std::vector<float>{0, 3}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("label"), (std::vector<std::uint8_t>{1, 2}));
  const auto packed = std::bit_cast<std::uint32_t>(4.2108e+06f);
  EXPECT_EQ((*cloud.get<std::uint8_t>("red"))[0], (packed >> 16) & 0xff);
  EXPECT_EQ((*cloud.get<std::uint8_t>("green"))[0], (packed >> 8) & 0xff);
  EXPECT_EQ((*cloud.get<std::uint8_t>("blue"))[1], packed & 0xff);
}

TEST(Pcd, AsciiRgbWrittenAsAnInteger) {
  const std::string path = scratch("integer_rgb.pcd");
  write_text(path,
             "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\n"
             "DATA ascii\n1 2 3 16744455\n");  // 0xFF8007, no POINTS line: WIDTH × HEIGHT
  const PointCloud cloud = read_pcd(path);
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ((*cloud.get<std::uint8_t>("red"))[0], 255);
  EXPECT_EQ((*cloud.get<std::uint8_t>("green"))[0], 128);
  EXPECT_EQ((*cloud.get<std::uint8_t>("blue"))[0], 7);
}

TEST(Pcd, BinarySkipsMultiValueFields) {
  const PointCloud cloud = read_pcd(fixture("binary_rgb.pcd"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.x, (std::vector<float>{1, -1}));
  EXPECT_EQ(cloud.y, (std::vector<float>{2, -2}));
  EXPECT_EQ(cloud.z, (std::vector<float>{3, -3}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("red"), (std::vector<std::uint8_t>{255, 255}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("green"), (std::vector<std::uint8_t>{128, 128}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("blue"), (std::vector<std::uint8_t>{7, 7}));
  EXPECT_FALSE(cloud.has("normal"));
  EXPECT_EQ(cloud.attributes().size(), 3u);
}

TEST(Pcd, FieldTypesBecomeColumnTypes) {
  const std::string path = scratch("types.pcd");
  write_text(path,
             "FIELDS x y z a b c d\nSIZE 8 4 4 2 1 4 8\nTYPE F F F I U U I\nCOUNT 1 1 1 1 1 1 1\n"
             "POINTS 1\nDATA ascii\n0.5 0 0 -300 200 4000000000 -5\n");
  const PointCloud cloud = read_pcd(path);
  EXPECT_EQ(cloud.x[0], 0.5f);
  EXPECT_EQ(*cloud.get<std::int16_t>("a"), (std::vector<std::int16_t>{-300}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("b"), (std::vector<std::uint8_t>{200}));
  EXPECT_EQ(*cloud.get<std::uint32_t>("c"), (std::vector<std::uint32_t>{4000000000u}));
  EXPECT_EQ(*cloud.get<double>("d"), (std::vector<double>{-5}));  // 64-bit integers: double
}

const std::string kHeader = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 10\n";

void expect_pcd_error(const std::string& text, const std::string& element,
                      const std::string& reason) {
  const std::string path = scratch("bad.pcd");
  write_text(path, text);
  const Error e = error_of([&] { read_pcd(path); });
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.element(), element) << e.what();
  EXPECT_THAT(e.reason(), HasSubstr(reason));
}

TEST(Pcd, CompressedTruncatedAndMalformedFilesAreNamed) {
  expect_pcd_error(kHeader + "DATA binary_compressed\n", "DATA",
                   "binary_compressed PCD is not supported; re-save as binary or ascii");
  expect_pcd_error(kHeader + "DATA binary\n" + std::string(40, '\0'), "point 3",
                   "file truncated: expected 10 points of 12 bytes");
  expect_pcd_error(kHeader + "DATA ascii\n1 2 3\n4 5\n", "point 1", "file truncated");
  expect_pcd_error(kHeader + "DATA ascii\n1 2 z\n", "point 0", "not a number: 'z'");
  expect_pcd_error(kHeader + "DATA ascii\n1 2 inf\n", "point 0", "non-finite coordinate");
  expect_pcd_error("FIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nPOINTS 0\nDATA ascii\n", "FIELDS",
                   "no z field");
  expect_pcd_error("FIELDS x y z\n", "header", "no DATA line");
  expect_pcd_error("FIELDS x y z\nSIZE 4 4\n", "header line 2", "one entry per field");
  expect_pcd_error("FIELDS x y z\nSIZE 4 4 3\n", "header line 2", "1, 2, 4 or 8");
  expect_pcd_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\n", "header line 3", "I, U or F");
  expect_pcd_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n", "header",
                   "no POINTS line");
  expect_pcd_error("FIELDS x y z\nSIZE 4 4 4\nDATA ascii\n", "header", "no SIZE or no TYPE");
  expect_pcd_error("FIELDS x y z\nCOLOUR red\n", "header line 2", "unknown header keyword");
  expect_pcd_error("FIELDS x y z l\nSIZE 4 4 4 1\nTYPE F F F U\nPOINTS 1\nDATA ascii\n0 0 0 256\n",
                   "point 0", "256 does not fit field 'l'");
}

TEST(Pcd, HugeCountsFailBeforeAllocating) {
  expect_pcd_error("FIELDS x y z h\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 4611686018427387904\n",
                   "header line 4",
                   "COUNT: '4611686018427387904' is not a positive 32-bit integer");
  expect_pcd_error(
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 18446744073709551615\n"
      "DATA binary\n" +
          std::string(24, '\0'),
      "point 2", "file truncated");
}

}  // namespace
}  // namespace glint::io
