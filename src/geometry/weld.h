#pragma once
// Merging the copies of a vertex that separately triangulated patches (parametric grids' seams,
// a B-rep's faces) each hold, so that triangles share their corners.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

namespace glint::geometry {

// Vertices that round to the same cell of a grid of `quantum` (metres) become one; triangles
// left with two equal corners are dropped. Mesh: `vertices` (Eigen::Vector3d) and
// `triangles` (std::array<int, 3>). Order of first appearance is kept, so the result is
// deterministic.
template <class Mesh>
void weld_vertices(Mesh& mesh, double quantum) {
  struct KeyHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
      return std::hash<std::int64_t>()(k[0] * 73856093 ^ k[1] * 19349663 ^ k[2] * 83492791);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, int, KeyHash> index;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<int> remap(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d& v = mesh.vertices[i];
    const std::array<std::int64_t, 3> key{std::llround(v.x() / quantum),
                                          std::llround(v.y() / quantum),
                                          std::llround(v.z() / quantum)};
    const auto [it, inserted] = index.emplace(key, static_cast<int>(vertices.size()));
    if (inserted) vertices.push_back(v);
    remap[i] = it->second;
  }
  std::vector<std::array<int, 3>> triangles;
  for (auto t : mesh.triangles) {
    for (int& corner : t) corner = remap[corner];
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
  }
  mesh.vertices = std::move(vertices);
  mesh.triangles = std::move(triangles);
}

}  // namespace glint::geometry
