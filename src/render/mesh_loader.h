#pragma once
// Triangle meshes from OBJ (tinyobjloader; polygons are triangulated) and PLY (ASCII or binary
// little/big endian "vertex" x/y/z and "face" vertex_indices lists, polygons fan-triangulated),
// and the normalisation scene.h defines for ShapeKind::mesh.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace glint::render {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;  // indices into vertices, counter-clockwise
  // Texture coordinates per triangle corner (3 per triangle, OBJ convention: v points up), or
  // empty when the file has none.
  std::vector<Eigen::Vector2f> corner_uvs;
};

// Reads by extension (.obj / .ply, case-insensitive). Throws glint::Error naming the file for
// a missing or unreadable file, an unknown extension, an index out of range or a mesh without
// triangles.
TriangleMesh load_mesh(const std::string& path);

// Uniformly scales and translates the mesh so its bounding box is `height_m` high, centred on
// x = z = 0, and rests on y = 0. Precondition: the mesh has a non-zero height.
void normalise_mesh(TriangleMesh& mesh, double height_m);

// Area-weighted vertex normals (unit length; zero for vertices of degenerate faces only).
std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh);

}  // namespace glint::render
