#include "io/point_cloud_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::fixture;
using test::scratch;
using ::testing::HasSubstr;

PointCloud labelled_cloud() {
  PointCloud cloud;
  cloud.push_back(0, 0, 0);
  cloud.push_back(1, 0.5f, -2);
  cloud.set("scalar_label", std::vector<std::uint8_t>{2, 1});
  return cloud;
}

TEST(PointCloudIo, DispatchesOnTheExtensionWhateverItsCase) {
  EXPECT_EQ(read_point_cloud(fixture("ascii_faces.ply")).size(), 3u);
  EXPECT_EQ(read_point_cloud(fixture("organised.pcd")).size(), 2u);
  EXPECT_EQ(read_point_cloud(fixture("count_first.pts")).size(), 3u);
  EXPECT_EQ(read_point_cloud(fixture("labelled.xyz")).size(), 4u);
  for (const char* name : {"cloud.PLY", "cloud.xyz", "cloud.TXT", "cloud.pts"}) {
    const std::string path = scratch(name);
    write_point_cloud(path, labelled_cloud());
    const PointCloud back = read_point_cloud(path);
    EXPECT_EQ(back.y, labelled_cloud().y) << name;
    EXPECT_EQ(*read_labels(back), (std::vector<std::uint8_t>{2, 1})) << name;
  }
  const std::string csv = scratch("cloud.csv");
  test::write_text(csv, "x,y,z\n1,2,3\n");
  EXPECT_EQ(read_point_cloud(csv).z, (std::vector<float>{3}));
}

TEST(PointCloudIo, PlyIsWrittenAsBinaryLittleEndian) {
  const std::string path = scratch("cloud.ply");
  write_point_cloud(path, labelled_cloud());
  EXPECT_THAT(test::read_text(path), HasSubstr("format binary_little_endian 1.0\n"));
}

TEST(PointCloudIo, UnknownExtensionsListTheSupportedOnes) {
  const Error e = error_of([] { read_point_cloud("scan.las"); });
  EXPECT_EQ(e.file(), "scan.las");
  EXPECT_EQ(e.reason(),
            "unknown point-cloud format '.las' (supported: .ply, .xyz, .txt, .pts, .csv, .pcd)");
  EXPECT_THAT(error_of([] { read_point_cloud("no_extension"); }).reason(),
              HasSubstr("unknown point-cloud format ''"));
  const std::string pcd = scratch("out.pcd");
  EXPECT_THAT(error_of([&] { write_point_cloud(pcd, labelled_cloud()); }).reason(),
              HasSubstr("supported: .ply, .xyz, .txt, .pts"));
  EXPECT_FALSE(std::filesystem::exists(pcd));
}

TEST(PointCloudIo, MissingFilesAreNamed) {
  const std::string path = scratch("missing.ply");
  EXPECT_EQ(error_of([&] { read_point_cloud(path); }).file(), path);
}

TEST(Labels, TheFirstPresentNameIsUsed) {
  PointCloud cloud = labelled_cloud();
  EXPECT_EQ(*read_labels(cloud), (std::vector<std::uint8_t>{2, 1}));
  cloud.set("label", std::vector<double>{0, 255});
  EXPECT_EQ(*read_labels(cloud), (std::vector<std::uint8_t>{0, 255}));
  // A classified cloud keeps the input's "label": its prediction is "scalar_label".
  EXPECT_EQ(*read_labels(cloud, LabelSource::prediction), (std::vector<std::uint8_t>{2, 1}));
  cloud.remove("label");
  cloud.remove("scalar_label");
  cloud.set("scalar_class", std::vector<std::int32_t>{3, 4});
  EXPECT_EQ(*read_labels(cloud), (std::vector<std::uint8_t>{3, 4}));
  cloud.remove("scalar_class");
  EXPECT_FALSE(read_labels(cloud).has_value());
}

TEST(Labels, ValuesMustBeWholeNumbersFrom0To255) {
  PointCloud cloud;
  for (int i = 0; i < 13; ++i) cloud.push_back(0, 0, 0);
  std::vector<float> values(13, 1);
  values[12] = 3.5f;
  cloud.set("label", values);
  const Error e = error_of([&] { read_labels(cloud); });
  EXPECT_EQ(e.file(), "");
  EXPECT_EQ(e.element(), "label");
  EXPECT_EQ(e.reason(), "value 3.5 at vertex 12 is not a class label (whole number 0..255)");
  for (const float bad : {-1.f, 256.f, std::nanf("")}) {
    values[12] = bad;
    cloud.set("label", values);
    EXPECT_THROW(read_labels(cloud), Error) << bad;
  }
  cloud.set("label", std::vector<std::int16_t>(13, -1));
  EXPECT_THROW(read_labels(cloud), Error);
}

}  // namespace
}  // namespace glint::io
