// Text clouds, PCD, format dispatch, labels, atomic writes and JSON files.
#include <gtest/gtest.h>

#include <bit>
#include <filesystem>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/json_report.h"
#include "io/pcd.h"
#include "io/point_cloud_io.h"
#include "io/text_cloud.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::fixture;
using test::scratch;
using test::write_text;

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(TextCloud, HeaderNamesColumnsAndCommentsAreSkipped) {
  const PointCloud cloud = read_point_cloud(fixture("labelled.xyz"));
  ASSERT_EQ(cloud.size(), 4u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0, 1, 0, 0}));
  EXPECT_EQ(*read_labels(cloud), (std::vector<std::uint8_t>{0, 1, 2, 1}));
}

TEST(TextCloud, PtsCountLineIsCheckedAndExtraColumnsKept) {
  const PointCloud cloud = read_point_cloud(fixture("count_first.pts"));
  ASSERT_EQ(cloud.size(), 3u);
  // Without a header the one integer extra column is taken for labels.
  EXPECT_EQ(*cloud.get<float>("label"), (std::vector<float>{10, 20, 30}));
  const std::string path = scratch("wrong_count.pts");
  write_text(path, "5\n0 0 0\n1 1 1\n");
  EXPECT_NE(error_of([&] { read_point_cloud(path); }).find("announces 5 points"), std::string::npos);
}

TEST(TextCloud, RaggedRowsAndBadNumbersNameTheLine) {
  const std::string path = scratch("ragged.xyz");
  write_text(path, "0 0 0\n1 1 1\n2 2\n");
  EXPECT_NE(error_of([&] { read_point_cloud(path); }).find("line 3"), std::string::npos);
  write_text(path, "0 0 0\n1 x 1\n");
  EXPECT_NE(error_of([&] { read_point_cloud(path); }).find("line 2"), std::string::npos);
  write_text(path, "0 0 0\n1 inf 1\n");
  EXPECT_NE(error_of([&] { read_point_cloud(path); }).find("non-finite"), std::string::npos);
  write_text(path, "# only a comment\n");
  EXPECT_NE(error_of([&] { read_point_cloud(path); }).find("no points"), std::string::npos);
}

TEST(TextCloud, RoundTripKeepsValues) {
  PointCloud cloud;
  cloud.push_back(0.1f, 0.2f, 0.3f);
  cloud.push_back(-1e-5f, 1e5f, 3.3333333f);
  cloud.set("label", std::vector<std::uint8_t>{1, 2});
  const std::string path = scratch("round_trip.xyz");
  write_point_cloud(path, cloud);
  const PointCloud back = read_point_cloud(path);
  EXPECT_EQ(back.x, cloud.x);
  EXPECT_EQ(back.z, cloud.z);
  EXPECT_EQ(*read_labels(back), (std::vector<std::uint8_t>{1, 2}));
}

TEST(Pcd, AsciiDropsNanPointsAndUnpacksRgb) {
  const PointCloud cloud = read_pcd(fixture("organised.pcd"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.z, (std::vector<float>{0, 3}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("label"), (std::vector<std::uint8_t>{1, 2}));
  const auto packed = std::bit_cast<std::uint32_t>(4.2108e+06f);
  EXPECT_EQ((*cloud.get<std::uint8_t>("red"))[0], (packed >> 16) & 0xff);
  EXPECT_EQ((*cloud.get<std::uint8_t>("blue"))[1], packed & 0xff);
}

TEST(Pcd, BinarySkipsMultiValueFields) {
  const PointCloud cloud = read_point_cloud(fixture("binary_rgb.pcd"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.x, (std::vector<float>{1, -1}));
  EXPECT_EQ(cloud.z, (std::vector<float>{3, -3}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("red"), (std::vector<std::uint8_t>{255, 255}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("green"), (std::vector<std::uint8_t>{128, 128}));
  EXPECT_EQ(*cloud.get<std::uint8_t>("blue"), (std::vector<std::uint8_t>{7, 7}));
  EXPECT_FALSE(cloud.has("normal"));
}

TEST(Pcd, CompressedTruncatedAndMalformed) {
  const std::string header = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 10\n";
  const std::string path = scratch("bad.pcd");
  write_text(path, header + "DATA binary_compressed\n");
  EXPECT_NE(error_of([&] { read_pcd(path); }).find("binary_compressed"), std::string::npos);
  write_text(path, header + "DATA binary\n" + std::string(40, '\0'));
  EXPECT_NE(error_of([&] { read_pcd(path); }).find("truncated"), std::string::npos);
  write_text(path, "FIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nPOINTS 0\nDATA ascii\n");
  EXPECT_NE(error_of([&] { read_pcd(path); }).find("no z field"), std::string::npos);
  write_text(path, "FIELDS x y z\n");
  EXPECT_NE(error_of([&] { read_pcd(path); }).find("no DATA line"), std::string::npos);
}

TEST(PointCloudIo, UnknownExtensionsAreRejected) {
  EXPECT_NE(error_of([] { read_point_cloud("scan.las"); }).find("unknown point-cloud format"),
            std::string::npos);
  EXPECT_THROW(write_point_cloud(scratch("out.pcd"), PointCloud{}), Error);
}

TEST(PointCloudIo, LabelsMustBeWholeNumbersInRange) {
  PointCloud cloud;
  cloud.push_back(0, 0, 0);
  cloud.push_back(1, 0, 0);
  EXPECT_FALSE(read_labels(cloud).has_value());
  cloud.set("scalar_label", std::vector<float>{1, 2});
  EXPECT_EQ(*read_labels(cloud), (std::vector<std::uint8_t>{1, 2}));
  cloud.set("scalar_label", std::vector<float>{1, 2.5f});
  EXPECT_NE(error_of([&] { read_labels(cloud); }).find("vertex 1"), std::string::npos);
  cloud.set("scalar_label", std::vector<std::int32_t>{-1, 0});
  EXPECT_THROW(read_labels(cloud), Error);
}

TEST(AtomicFile, UncommittedWritesLeaveTheTargetUntouched) {
  const std::string path = scratch("atomic.txt");
  write_text(path, "old");
  {
    AtomicFile file(path, false);
    file.stream() << "new but abandoned";
  }
  EXPECT_EQ(test::read_text(path), "old");
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
    EXPECT_EQ(entry.path().string().find("atomic.txt.tmp"), std::string::npos);
  {
    AtomicFile file(path, false);
    file.stream() << "new";
    file.commit();
  }
  EXPECT_EQ(test::read_text(path), "new");
}

TEST(Json, WriteReadAndParseErrors) {
  const std::string path = scratch("report.json");
  write_json(path, {{"points", 3}, {"name", "cube"}});
  EXPECT_EQ(read_json(path)["points"], 3);
  write_text(path, "{\"points\": 3,");
  EXPECT_NE(error_of([&] { read_json(path); }).find("not valid JSON"), std::string::npos);
}

}  // namespace
}  // namespace glint::io
