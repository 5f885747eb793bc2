#include "mesh_distance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "core/error.h"
#include "core/parallel.h"
#include "geometry/kdtree.h"

namespace glint::bench {
namespace {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
Eigen::Vector3f closest_on_triangle(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                                    const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denominator = 1.0f / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

std::vector<Eigen::Vector3f> sample_surface(const fusion::TriangleMesh& mesh, std::size_t count,
                                            std::uint32_t seed) {
  std::vector<double> cumulative_area;
  double area = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    area += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                      .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                      .norm();
    cumulative_area.push_back(area);
  }
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i = 0; i < count; ++i) {
    const auto t =
        std::lower_bound(cumulative_area.begin(), cumulative_area.end(), uniform(random) * area) -
        cumulative_area.begin();
    const Eigen::Vector3i& triangle =
        mesh.triangles[std::min<std::size_t>(t, mesh.triangles.size() - 1)];
    float r1 = float(uniform(random)), r2 = float(uniform(random));
    if (r1 + r2 > 1) {
      r1 = 1 - r1;
      r2 = 1 - r2;
    }
    const Eigen::Vector3f a = mesh.vertices[triangle[0]];
    points.push_back(a + r1 * (mesh.vertices[triangle[1]] - a) +
                     r2 * (mesh.vertices[triangle[2]] - a));
  }
  return points;
}

}  // namespace

DistanceSummary surface_distance(const fusion::TriangleMesh& from, const fusion::TriangleMesh& to,
                                 std::size_t samples, std::uint32_t seed) {
  if (from.triangles.empty() || to.triangles.empty())
    throw Error("mesh distance", "", "both meshes need triangles");
  PointCloud vertices;
  for (const Eigen::Vector3f& v : to.vertices) vertices.push_back(v.x(), v.y(), v.z());
  const geometry::KdTree tree(vertices);
  std::vector<std::vector<int>> triangles_of_vertex(to.vertices.size());
  for (std::size_t t = 0; t < to.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) triangles_of_vertex[to.triangles[t][k]].push_back(int(t));

  const std::vector<Eigen::Vector3f> points = sample_surface(from, samples, seed);
  std::vector<double> distances(points.size());
  constexpr int kNeighbours = 8;
  parallel_for(points.size(), [&](std::size_t i) {
    std::uint32_t indices[kNeighbours];
    float squared[kNeighbours];
    const int found = tree.knn(points[i].data(), kNeighbours, indices, squared);
    float best = std::sqrt(squared[0]);
    for (int n = 0; n < found; ++n) {
      for (int t : triangles_of_vertex[indices[n]]) {
        const Eigen::Vector3i& tri = to.triangles[t];
        best = std::min(best,
                        (points[i] - closest_on_triangle(points[i], to.vertices[tri[0]],
                                                         to.vertices[tri[1]], to.vertices[tri[2]]))
                            .norm());
      }
    }
    distances[i] = best;
  });
  DistanceSummary summary;
  summary.samples = distances.size();
  for (double d : distances) summary.mean_m += d / double(distances.size());
  std::sort(distances.begin(), distances.end());
  summary.median_m = distances[distances.size() / 2];
  summary.p90_m = distances[std::min(distances.size() - 1, distances.size() * 9 / 10)];
  return summary;
}

}  // namespace glint::bench
