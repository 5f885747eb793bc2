#include "fusion/marching_cubes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>

#include "core/error.h"
#include "core/parallel.h"
#include "fusion/marching_cubes_table.h"
#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

TEST(MarchingCubesTable, SingleCornerCasesAreOneOutwardTriangle) {
  const auto& cases = marching_cubes_cases();
  EXPECT_EQ(cases[0].triangle_count, 0);
  EXPECT_EQ(cases[255].triangle_count, 0);
  // Corner 0 inside: the triangle on edges x0, y0, z0 faces away from it, towards +(1,1,1).
  ASSERT_EQ(cases[1].triangle_count, 1);
  Eigen::Vector3d v[3];
  for (int k = 0; k < 3; ++k) {
    const CubeEdge& edge = kCubeEdges[cases[1].edges[k]];
    EXPECT_EQ(edge.corner, 0);
    v[k] = Eigen::Vector3d::Zero();
    v[k][edge.axis] = 0.5;
  }
  EXPECT_GT((v[1] - v[0]).cross(v[2] - v[0]).dot(Eigen::Vector3d(1, 1, 1)), 0);
  for (int c = 0; c < 8; ++c) EXPECT_EQ(cases[1 << c].triangle_count, 1);
}

TEST(MarchingCubes, SphereAreaAndVolumeWithinOnePercent) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 20000;
  TsdfVolume volume(params);
  const double radius = 0.3;
  const Eigen::Vector3d centre(0.013, -0.021, 0.007);
  test::fill_analytic(
      volume, [&](const Eigen::Vector3d& p) { return (p - centre).norm() - radius; }, 0.4, 0.04);
  const TriangleMesh mesh = extract_mesh(volume);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  const double area = 4 * std::numbers::pi * radius * radius;
  const double enclosed = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  EXPECT_NEAR(surface_area(mesh) / area, 1.0, 0.01);
  EXPECT_NEAR(enclosed_volume(mesh) / enclosed, 1.0, 0.01);
  for (const Eigen::Vector3f& v : mesh.vertices)
    ASSERT_NEAR((v.cast<double>() - centre).norm(), radius, 0.002);

  // Closed and manifold: every undirected edge is used by exactly two triangles, once in each
  // direction.
  std::map<std::pair<int, int>, int> directed;
  for (const Eigen::Vector3i& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1);
    ASSERT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
}

TEST(MarchingCubes, TheMeshIsTheSameWhateverTheThreadCount) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 20000;
  TsdfVolume volume(params);
  test::fill_analytic(
      volume, [](const Eigen::Vector3d& p) { return p.norm() - 0.25; }, 0.3, 0.04);
  const TriangleMesh parallel = extract_mesh(volume);
  TriangleMesh serial;
  {
    const auto one_thread = limit_threads(1);
    serial = extract_mesh(volume);
  }
  ASSERT_GT(parallel.vertices.size(), 1000u);
  EXPECT_EQ(parallel.vertices, serial.vertices);
  EXPECT_EQ(parallel.colours, serial.colours);
  EXPECT_EQ(parallel.triangles, serial.triangles);
}

TEST(MarchingCubes, TheMeshIsTheSameWhateverOrderTheBlocksWereAllocatedIn) {
  // Threads allocate a frame's blocks in no fixed order; the mesh follows block coordinates.
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 20000;
  const auto sphere = [](const Eigen::Vector3d& p) { return p.norm() - 0.25; };
  TsdfVolume forward(params), backward(params);
  test::fill_analytic(forward, sphere, 0.3, 0.04);
  // The same blocks allocated in the reverse order first.
  for (int b = int(forward.block_count()) - 1; b >= 0; --b)
    backward.allocate(forward.hash().block(b));
  test::fill_analytic(backward, sphere, 0.3, 0.04);
  ASSERT_EQ(backward.block_count(), forward.block_count());
  ASSERT_NE(backward.hash().block(0), forward.hash().block(0));
  const TriangleMesh a = extract_mesh(forward), b = extract_mesh(backward);
  ASSERT_GT(a.vertices.size(), 1000u);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
}

TEST(MarchingCubes, UnobservedVoxelsEmitNothing) {
  TsdfVolume volume;
  EXPECT_TRUE(extract_mesh(volume).triangles.empty());
  const int block = volume.allocate({0, 0, 0});
  EXPECT_TRUE(extract_mesh(volume).vertices.empty()) << "a new block is unobserved";
  // Observed: +1 cm everywhere but -1 cm at voxel 0, whose cubes then cross the surface.
  std::fill_n(volume.sdf_m(block), kVoxelsPerBlock, 0.01f);
  std::fill_n(volume.weight(block), kVoxelsPerBlock, std::uint8_t{1});
  volume.sdf_m(block)[0] = -0.01f;
  EXPECT_FALSE(extract_mesh(volume).vertices.empty());
  volume.sdf_m(block)[0] = kUnobservedSdf;
  volume.weight(block)[0] = 0;
  EXPECT_TRUE(extract_mesh(volume).vertices.empty())
      << "the only crossing cubes had voxel 0 as a corner";
}

TEST(MarchingCubes, PlyOutputHasHeaderCountsAndColours) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 1, 2}};
  const std::string path = ::testing::TempDir() + "/triangle.ply";
  write_mesh_ply(path, mesh);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("element vertex 3"), std::string::npos);
  EXPECT_NE(text.find("element face 1"), std::string::npos);
  EXPECT_NE(text.find("property uchar red"), std::string::npos);
  const std::size_t body = text.find("end_header\n") + 11;
  EXPECT_EQ(text.size() - body, 3 * 15 + 13u);
  EXPECT_EQ(linear_to_srgb8(1.0f), 255);
  EXPECT_EQ(linear_to_srgb8(0.2158605f), 128);
}

TEST(MarchingCubes, PlyRecordsPastTheFirstWriteChunkKeepTheirOrder) {
  // More vertices and faces than one packing chunk (2^16 records).
  TriangleMesh mesh;
  const int n = 70000;
  for (int i = 0; i < n; ++i) mesh.vertices.emplace_back(float(i), float(-i), 0.5f * float(i));
  mesh.vertex_properties.emplace_back("index", std::vector<float>(std::size_t(n)));
  for (int i = 0; i < n; ++i) mesh.vertex_properties[0].second[std::size_t(i)] = float(i);
  for (int i = 0; i + 2 < n; ++i) mesh.triangles.emplace_back(i, i + 1, i + 2);
  const std::string path = ::testing::TempDir() + "/chunked.ply";
  write_mesh_ply(path, mesh);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t body = text.find("end_header\n") + 11;
  ASSERT_EQ(text.size() - body, std::size_t(n) * 16 + std::size_t(n - 2) * 13);
  for (const int i : {0, 65535, 65536, n - 1}) {
    float record[4];
    std::memcpy(record, text.data() + body + std::size_t(i) * 16, sizeof(record));
    EXPECT_EQ(record[0], float(i));
    EXPECT_EQ(record[1], float(-i));
    EXPECT_EQ(record[3], float(i));
  }
  for (const int t : {0, 65536, n - 3}) {
    const char* face = text.data() + body + std::size_t(n) * 16 + std::size_t(t) * 13;
    int indices[3];
    std::memcpy(indices, face + 1, sizeof(indices));
    EXPECT_EQ(face[0], 3);
    EXPECT_EQ(indices[0], t);
    EXPECT_EQ(indices[2], t + 2);
  }
}

TEST(MarchingCubes, PlyHeaderCarriesTheCommentsAndRefusesAMultiLineOne) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  mesh.comments = {"red green blue: refined diffuse albedo"};
  const std::string path = ::testing::TempDir() + "/commented.ply";
  write_mesh_ply(path, mesh);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t comment = text.find("comment red green blue: refined diffuse albedo\n");
  ASSERT_NE(comment, std::string::npos);
  EXPECT_LT(comment, text.find("element vertex 3"));

  const std::string refused = ::testing::TempDir() + "/two-line-comment.ply";
  mesh.comments = {"first line\nend_header"};
  EXPECT_THROW(write_mesh_ply(refused, mesh), Error);
  EXPECT_FALSE(std::filesystem::exists(refused));
}

}  // namespace
}  // namespace glint::fusion
