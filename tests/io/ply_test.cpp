#include "io/ply.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/point_cloud_io.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::fixture;
using test::scratch;

// One attribute of every PLY scalar type, with extreme values.
PointCloud every_type_cloud() {
  PointCloud cloud;
  cloud.push_back(0.1f, -2.5f, 1e-7f);
  cloud.push_back(3.4028235e38f, -0.f, 12345.678f);
  cloud.push_back(-1.f, 1.f, 0.33333334f);
  cloud.set("i8", std::vector<std::int8_t>{-128, 0, 127});
  cloud.set("u8", std::vector<std::uint8_t>{0, 1, 255});
  cloud.set("i16", std::vector<std::int16_t>{-32768, 5, 32767});
  cloud.set("u16", std::vector<std::uint16_t>{0, 7, 65535});
  cloud.set("i32", std::vector<std::int32_t>{-2147483647 - 1, 9, 2147483647});
  cloud.set("u32", std::vector<std::uint32_t>{0, 11, 4294967295u});
  cloud.set("f32", std::vector<float>{1.1f, -0.f, 1e-38f});
  cloud.set("f64", std::vector<double>{0.1, -1e300, 2.0 / 3.0});
  return cloud;
}

void expect_same(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
  ASSERT_EQ(a.attributes().size(), b.attributes().size());
  for (std::size_t i = 0; i < a.attributes().size(); ++i) {
    EXPECT_EQ(a.attributes()[i].name, b.attributes()[i].name);
    EXPECT_EQ(a.attributes()[i].values, b.attributes()[i].values) << a.attributes()[i].name;
  }
}

class PlyRoundTrip : public ::testing::TestWithParam<PlyFormat> {};

TEST_P(PlyRoundTrip, EveryTypeIsPreservedExactly) {
  const PointCloud cloud = every_type_cloud();
  const std::string path = scratch("round_trip.ply");
  write_ply(path, cloud, GetParam());
  expect_same(cloud, read_ply(path));
}

INSTANTIATE_TEST_SUITE_P(Encodings, PlyRoundTrip,
                         ::testing::Values(PlyFormat::ascii, PlyFormat::binary_little_endian,
                                           PlyFormat::binary_big_endian));

TEST(Ply, AsciiSkipsOtherElementsAndLists) {
  const PointCloud cloud = read_ply(fixture("ascii_faces.ply"));
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0, 1.5f, 0}));
  EXPECT_EQ(cloud.z, (std::vector<float>{0, 0, -1}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("label"), (std::vector<std::uint8_t>{0, 1, 2}));
  EXPECT_EQ(*cloud.get<std::int16_t>("temperature"), (std::vector<std::int16_t>{-5, 300, 7}));
}

TEST(Ply, BigEndianDoublesWithCrlfHeader) {
  const PointCloud cloud = read_ply(fixture("big_endian_double.ply"));
  ASSERT_EQ(cloud.size(), 4u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0.125f, 1, -4, 7}));
  EXPECT_EQ(cloud.z, (std::vector<float>{1000, 3, -6, 9}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("label"), (std::vector<std::uint8_t>{0, 1, 2, 1}));
  EXPECT_EQ(*cloud.get<float>("intensity"), (std::vector<float>{0.5f, -1.25f, 3, 0}));
}

TEST(Ply, EmptyCloudRoundTrips) {
  const std::string path = scratch("empty.ply");
  write_ply(path, PointCloud{});
  EXPECT_EQ(read_ply(path).size(), 0u);
}

// Reading `text` as a PLY file throws a glint::Error whose message contains `expected`.
void expect_ply_error(const std::string& text, const std::string& expected) {
  const std::string path = scratch("bad.ply");
  test::write_text(path, text);
  try {
    read_ply(path);
    ADD_FAILURE() << "no error for: " << expected;
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(Ply, MalformedHeadersAreNamed) {
  expect_ply_error("PLY?\n", "not a PLY file");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "no end_header");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n",
                   "unknown property type 'quaternion'");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "end_header\n1 2\n",
                   "no z property");
  expect_ply_error("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n"
                   "3 0 1 2\n",
                   "no vertex element");
  expect_ply_error("ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown format");
  expect_ply_error("ply\nformat ascii 1.0\nelement vertex many\nend_header\n",
                   "expected 'element <name> <count>'");
}

TEST(Ply, TruncatedAndMalformedBodies) {
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 1000\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n";
  expect_ply_error(header + std::string(12 * 999 + 5, '\0'), "file truncated");
  // A count that no file could hold fails before any allocation.
  expect_ply_error("ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n"
                   "property float x\nproperty float y\nproperty float z\nend_header\n",
                   "file truncated");
  const std::string ascii = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                            "property float y\nproperty float z\nproperty uchar label\nend_header\n";
  expect_ply_error(ascii + "0 0 0 1\n1 1\n", "vertex 1");
  expect_ply_error(ascii + "0 0 0 1\n1 one 1 0\n", "not a number");
  expect_ply_error(ascii + "0 0 0 1\n1 1 1 300\n", "does not fit");
  expect_ply_error(ascii + "0 0 0 1\n1 nan 1 0\n", "non-finite coordinate");
}

TEST(Ply, NonFiniteBinaryCoordinateNamesTheVertex) {
  PointCloud cloud;
  cloud.push_back(0, 0, 0);
  cloud.push_back(1, std::nanf(""), 0);
  const std::string path = scratch("nan.ply");
  write_ply(path, cloud);
  try {
    read_ply(path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.element(), "vertex 1");
  }
}

TEST(Ply, MissingFileAndFolder) {
  EXPECT_THROW(read_ply(scratch("does_not_exist.ply")), Error);
  EXPECT_THROW(read_ply(std::filesystem::temp_directory_path().string()), Error);
}

TEST(Ply, WriteIntoMissingFolderFailsCleanly) {
  const std::string path = scratch("no_such_folder/out.ply");
  EXPECT_THROW(write_ply(path, every_type_cloud()), Error);
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(path).parent_path()));
}

}  // namespace
}  // namespace glint::io
