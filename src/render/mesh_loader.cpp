#include "render/mesh_loader.h"

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.h"
#include "core/limits.h"
#include "io/ply.h"

namespace glint::render {
namespace {

TriangleMesh read_obj_mesh(const std::string& path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.mtl_search_path = std::filesystem::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string reason = reader.Error();
    while (!reason.empty() && std::isspace(static_cast<unsigned char>(reason.back())))
      reason.pop_back();
    throw Error(path, "", reason.empty() ? "cannot read the OBJ file" : reason);
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  TriangleMesh mesh;
  mesh.vertices.reserve(attrib.vertices.size() / 3);
  for (std::size_t v = 0; v + 2 < attrib.vertices.size(); v += 3)
    mesh.vertices.emplace_back(attrib.vertices[v], attrib.vertices[v + 1], attrib.vertices[v + 2]);
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  const int uv_count = static_cast<int>(attrib.texcoords.size() / 2);
  bool all_corners_have_uvs = uv_count > 0;
  std::vector<Eigen::Vector2f> corner_uvs;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
    std::size_t first = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      if (corners == 3) {
        Eigen::Vector3i triangle;
        for (int c = 0; c < 3; ++c) {
          const tinyobj::index_t& index = indices[first + c];
          if (index.vertex_index < 0 || index.vertex_index >= vertex_count)
            throw Error(path, fmt::format("shape '{}'", shape.name), "vertex index out of range");
          triangle[c] = index.vertex_index;
          const bool has_uv = index.texcoord_index >= 0 && index.texcoord_index < uv_count;
          all_corners_have_uvs = all_corners_have_uvs && has_uv;
          if (has_uv)
            corner_uvs.emplace_back(attrib.texcoords[2 * index.texcoord_index],
                                    attrib.texcoords[2 * index.texcoord_index + 1]);
        }
        mesh.triangles.push_back(triangle);
      }
      first += corners;
    }
  }
  if (mesh.triangles.empty()) throw Error(path, "", "the mesh has no triangles");
  if (all_corners_have_uvs) mesh.corner_uvs = std::move(corner_uvs);
  return mesh;
}

TriangleMesh read_ply_mesh(const std::string& path) {
  io::PlyMesh ply = io::read_ply_mesh(path);
  TriangleMesh mesh;
  mesh.vertices.reserve(ply.vertices.size());
  for (std::size_t v = 0; v < ply.vertices.size(); ++v)
    mesh.vertices.push_back(
        (ply.vertices.origin + ply.vertices.point(v).cast<double>()).cast<float>());
  mesh.triangles = std::move(ply.triangles);
  return mesh;
}

}  // namespace

TriangleMesh load_mesh(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path, "", "no such mesh file");
  std::string extension = std::filesystem::path(path).extension().string();
  std::ranges::transform(extension, extension.begin(),
                         [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension != ".obj" && extension != ".ply")
    throw Error(path, "", "unknown mesh format (expected .obj or .ply)");
  TriangleMesh mesh = extension == ".obj" ? read_obj_mesh(path) : read_ply_mesh(path);
  // A NaN or huge vertex would reach the ray tracer's bounding boxes (and its assertions).
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    limits::check_position(mesh.vertices[v].cast<double>(), path, fmt::format("vertex {}", v));
  return mesh;
}

void normalise_mesh(TriangleMesh& mesh, double height_m) {
  Eigen::Vector3f lower = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f upper = -lower;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    lower = lower.cwiseMin(v);
    upper = upper.cwiseMax(v);
  }
  const float scale = static_cast<float>(height_m) / (upper.y() - lower.y());
  const Eigen::Vector3f anchor(0.5f * (lower.x() + upper.x()), lower.y(),
                               0.5f * (lower.z() + upper.z()));
  for (Eigen::Vector3f& v : mesh.vertices) v = (v - anchor) * scale;
}

std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> normals(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    // The cross product's length is twice the area: area weighting for free.
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (int c = 0; c < 3; ++c) normals[t[c]] += n;
  }
  for (Eigen::Vector3f& n : normals) {
    const float length = n.norm();
    if (length > 0) n /= length;
  }
  return normals;
}

}  // namespace glint::render
