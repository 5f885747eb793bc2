// Mesh files: OBJ with UVs, PLY with polygons, normalisation, bad inputs.
#include "render/mesh_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "scene_fixtures.h"
#include "support/error_of.h"

namespace glint::render {
namespace {

const std::string kData = std::string(GLINT_TEST_DATA_DIR) + "/render/";

TEST(MeshLoader, ReadsObjTrianglesWithCornerUvs) {
  const TriangleMesh mesh = load_mesh(kData + "pyramid.obj");
  ASSERT_EQ(mesh.vertices.size(), 5u);
  ASSERT_EQ(mesh.triangles.size(), 4u);
  ASSERT_EQ(mesh.corner_uvs.size(), 12u);
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(1, 2, 4));
  EXPECT_EQ(mesh.corner_uvs[2], Eigen::Vector2f(0.5f, 1.0f));
}

TEST(MeshLoader, ReadsPlyPolygonsFanTriangulated) {
  const TriangleMesh mesh = load_mesh(kData + "quad_and_triangle.ply");
  ASSERT_EQ(mesh.vertices.size(), 5u);
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], Eigen::Vector3i(3, 2, 4));
  EXPECT_EQ(mesh.vertices[4], Eigen::Vector3f(0.5f, 2, 0));
  EXPECT_TRUE(mesh.corner_uvs.empty());
}

TEST(MeshLoader, ReadsBinaryBigEndianPly) {
  test::TemporaryFolder folder;
  const std::string path = folder.path("tri.ply");
  std::ofstream stream(path, std::ios::binary);
  stream << "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
            "property double y\nproperty double z\nelement face 1\n"
            "property list uchar uint vertex_indices\nend_header\n";
  const auto put = [&](auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    std::reverse(bytes, bytes + sizeof(value));  // this machine is little endian
    stream.write(bytes, sizeof(value));
  };
  for (double v : {0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0, 0.5}) put(v);
  put(std::uint8_t(3));
  for (std::uint32_t i : {0u, 1u, 2u}) put(i);
  stream.close();
  const TriangleMesh mesh = load_mesh(path);
  ASSERT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(0, 3, 0.5f));
}

TEST(MeshLoader, NormalisesToHeightCentredAndOnTheFloor) {
  TriangleMesh mesh = load_mesh(kData + "pyramid.obj");
  for (Eigen::Vector3f& v : mesh.vertices) v = 3.0f * v + Eigen::Vector3f(5, -2, 1);
  normalise_mesh(mesh, 1.5);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v);
  EXPECT_NEAR(box.min().y(), 0.0f, 1e-6f);
  EXPECT_NEAR(box.max().y(), 1.5f, 1e-6f);
  EXPECT_NEAR(box.center().x(), 0.0f, 1e-6f);
  EXPECT_NEAR(box.center().z(), 0.0f, 1e-6f);
  EXPECT_NEAR(box.sizes().x(), 1.5f, 1e-6f);  // uniform scale: the base was as wide as high
}

TEST(MeshLoader, VertexNormalsOfAFlatQuadPointAlongItsNormal) {
  const std::vector<Eigen::Vector3f> normals =
      vertex_normals(load_mesh(kData + "quad_and_triangle.ply"));
  for (const Eigen::Vector3f& n : normals) EXPECT_NEAR(n.z(), 1.0f, 1e-6f);
}

TEST(MeshLoader, BadFilesNameThemselves) {
  test::TemporaryFolder folder;
  const std::string missing = folder.path("missing.obj");
  EXPECT_EQ(glint::test::error_of([&] { load_mesh(missing); }).file(), missing);
  const std::string unknown = folder.path("mesh.stl");
  std::ofstream(unknown) << "solid x\n";
  EXPECT_EQ(glint::test::error_of([&] { load_mesh(unknown); }).file(), unknown);
  const std::string out_of_range = folder.path("bad.ply");
  std::ofstream(out_of_range) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 1\n"
                                 "property list uchar int vertex_indices\nend_header\n"
                                 "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  const Error error = glint::test::error_of([&] { load_mesh(out_of_range); });
  EXPECT_EQ(error.file(), out_of_range);
  EXPECT_NE(error.reason().find("out of range"), std::string::npos);
  const std::string no_faces = folder.path("empty.obj");
  std::ofstream(no_faces) << "v 0 0 0\nv 1 0 0\n";
  EXPECT_EQ(glint::test::error_of([&] { load_mesh(no_faces); }).file(), no_faces);
}

}  // namespace
}  // namespace glint::render
