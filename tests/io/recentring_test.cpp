// Positions are read in double and re-centred before they become float (core/point_cloud.h,
// set_positions): a cloud far from 0 gets the floats of the same cloud at 0, writers give its
// coordinates back, and a coordinate no origin can bring within float's reach is an error.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/pcd.h"
#include "io/ply.h"
#include "io/text_cloud.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::scratch;

// 200 points on a 1/64 m grid (exact in double at any offset below 2^46) within [-0.5, 0.5].
std::vector<Eigen::Vector3d> grid_points() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i)
    points.emplace_back((i % 7 - 3) / 64.0, (i % 11 - 5) / 64.0, (i % 13 - 6) / 64.0 + i / 512.0);
  return points;
}

// An ascii PLY with double positions shifted by `offset`.
std::string ply_text(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& offset) {
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n",
      points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p + offset;
    text += fmt::format("{:.17g} {:.17g} {:.17g}\n", q.x(), q.y(), q.z());
  }
  return text;
}

TEST(Recentring, FarCloudGetsTheFloatsOfTheSameCloudAtZero) {
  const std::vector<Eigen::Vector3d> points = grid_points();
  const Eigen::Vector3d offset(1e7, -3e7, 250);
  const std::string near_path = scratch("near.ply"), far_path = scratch("far.ply");
  test::write_text(near_path, ply_text(points, Eigen::Vector3d::Zero()));
  test::write_text(far_path, ply_text(points, offset));
  const PointCloud near = read_ply(near_path);
  const PointCloud far = read_ply(far_path);
  EXPECT_EQ(near.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(far.origin, offset);  // the rounded centre of the bounding box
  ASSERT_EQ(far.size(), near.size());
  for (std::size_t i = 0; i < far.size(); ++i) {
    EXPECT_EQ(far.x[i], near.x[i]);
    EXPECT_EQ(far.y[i], near.y[i]);
    EXPECT_EQ(far.z[i], near.z[i]);
  }
  // In float the same file loses everything below 1 m.
  EXPECT_NE(float(points[1].x() + offset.x()) - float(offset.x()), float(points[1].x()));
}

TEST(Recentring, FarPcdCloudIsRecentredAndItsNanPointsDropped) {
  const std::vector<Eigen::Vector3d> points = grid_points();
  const Eigen::Vector3d offset(-2e6, 7e6, 3e5);
  std::string text = fmt::format(
      "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {}\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA ascii\nnan nan nan\n",
      points.size() + 1, points.size() + 1);
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p + offset;
    text += fmt::format("{:.17g} {:.17g} {:.17g}\n", q.x(), q.y(), q.z());
  }
  const std::string far_path = scratch("far.pcd"), near_path = scratch("near.ply");
  test::write_text(far_path, text);
  test::write_text(near_path, ply_text(points, Eigen::Vector3d::Zero()));
  const PointCloud far = read_pcd(far_path);
  const PointCloud near = read_ply(near_path);
  EXPECT_EQ(far.origin, offset);
  EXPECT_EQ(far.x, near.x);
  EXPECT_EQ(far.y, near.y);
  EXPECT_EQ(far.z, near.z);
}

TEST(Recentring, WritersGiveTheOriginalCoordinatesBack) {
  const std::vector<Eigen::Vector3d> points = grid_points();
  const Eigen::Vector3d offset(4e6, 5e6, 1e3);
  const std::string far_path = scratch("far.ply");
  test::write_text(far_path, ply_text(points, offset));
  const PointCloud cloud = read_ply(far_path);
  for (const PlyFormat format : {PlyFormat::ascii, PlyFormat::binary_big_endian}) {
    const std::string copy_path = scratch("copy.ply");
    write_ply(copy_path, cloud, format);
    const PointCloud copy = read_ply(copy_path);
    EXPECT_EQ(copy.origin, cloud.origin);
    EXPECT_EQ(copy.x, cloud.x);
    EXPECT_EQ(copy.z, cloud.z);
  }
  const std::string text_path = scratch("copy.xyz");
  write_text_cloud(text_path, cloud);
  const PointCloud text = read_text_cloud(text_path);
  EXPECT_EQ(text.origin, cloud.origin);
  EXPECT_EQ(text.y, cloud.y);
  for (std::size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(text.origin.x() + double(text.x[i]), points[i].x() + offset.x());
}

TEST(Recentring, CloudsNearZeroKeepTheirCoordinates) {
  // Small clouds and clouds within 1e4 of 0 are read as they are (origin 0).
  const std::string path = scratch("near.xyz");
  test::write_text(path, "5000 5000 5000\n5001 5000 5000\n");
  const PointCloud cloud = read_text_cloud(path);
  EXPECT_EQ(cloud.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(cloud.x[1], 5001.0f);
}

TEST(Recentring, CoordinateBeyondFloatFromTheRestIsAnError) {
  std::vector<Eigen::Vector3d> points = grid_points();
  points[17].z() = 1e39;
  const std::string path = scratch("outlier.ply");
  test::write_text(path, ply_text(points, Eigen::Vector3d::Zero()));
  const Error error = error_of([&] { read_ply(path); });
  EXPECT_EQ(error.file(), path);
  EXPECT_EQ(error.element(), "vertex 17");
  EXPECT_NE(error.reason().find("outside the float range"), std::string::npos) << error.what();
}

}  // namespace
}  // namespace glint::io
