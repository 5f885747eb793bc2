#include "cad/surface_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "cad/sample.h"
#include "core/error.h"

namespace glint::cad {
namespace {

using Vec = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

}  // namespace

Vec triangle_normal(const SurfaceMesh& mesh, const std::array<int, 3>& t) {
  const Vec& a = mesh.vertices[t[0]];
  const Vec n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
  const double length = n.norm();
  return length > 0 ? Vec(n / length) : Vec(0, 0, 1);
}

double triangle_area(const SurfaceMesh& mesh, const std::array<int, 3>& t) {
  const Vec& a = mesh.vertices[t[0]];
  return 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
}

EdgeClasses classify_mesh_edges(const SurfaceMesh& mesh, double sharp_angle_deg) {
  // Every triangle's three sides, sorted so that the sides of one edge are adjacent.
  struct Side {
    std::uint64_t edge;
    int triangle;
    bool forward;  // the triangle runs the edge from its lower to its higher vertex
  };
  std::vector<Side> sides;
  sides.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = mesh.triangles[t][c], b = mesh.triangles[t][(c + 1) % 3];
      sides.push_back({edge_key(a, b), int(t), a < b});
    }
  std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
    return x.edge != y.edge ? x.edge < y.edge : x.triangle < y.triangle;
  });
  std::vector<char> degenerate(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    degenerate[t] = !(triangle_area(mesh, mesh.triangles[t]) > 0);

  const double cos_sharp = std::cos(sharp_angle_deg * kPi / 180.0);
  EdgeClasses classes;
  for (std::size_t first = 0, last = 0; first < sides.size(); first = last) {
    while (last < sides.size() && sides[last].edge == sides[first].edge) ++last;
    const auto begin = sides.begin() + std::ptrdiff_t(first);
    const auto end = sides.begin() + std::ptrdiff_t(last);
    if (std::any_of(begin, end, [&](const Side& side) { return degenerate[side.triangle]; }))
      continue;
    std::uint8_t label = 0;
    if (last - first == 1) {
      label = edges::kLabelBoundary;
    } else if (last - first > 2) {
      label = edges::kLabelSharp;
    } else {
      const Vec n0 = triangle_normal(mesh, mesh.triangles[begin[0].triangle]);
      Vec n1 = triangle_normal(mesh, mesh.triangles[begin[1].triangle]);
      if (begin[0].forward == begin[1].forward) n1 = -n1;
      if (n0.dot(n1) <= cos_sharp) label = edges::kLabelSharp;
    }
    const Vec& a = mesh.vertices[sides[first].edge >> 32];
    const Vec& b = mesh.vertices[sides[first].edge & 0xffffffffu];
    classes.count(label, (b - a).norm());
    if (label) classes.segments.push_back({a, b, label});
  }
  return classes;
}

SurfaceMesh cut_mesh(const SurfaceMesh& mesh, const Vec& point, const Vec& normal, CutMode mode) {
  if (!(normal.norm() > 0)) throw Error("--cut-plane", "normal", "is zero");
  const Vec n = normal.normalized();
  std::vector<double> height(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    height[i] = n.dot(mesh.vertices[i] - point);

  SurfaceMesh cut;
  std::vector<int> kept(mesh.vertices.size(), -1);
  auto keep = [&](int v) {
    if (kept[v] < 0) {
      kept[v] = int(cut.vertices.size());
      cut.vertices.push_back(mesh.vertices[v]);
    }
    return kept[v];
  };
  // One vertex where the plane crosses an edge, shared by the triangles on both sides of it.
  std::unordered_map<std::uint64_t, int> crossings;
  auto crossing = [&](int a, int b) {
    const auto [it, inserted] = crossings.emplace(edge_key(a, b), int(cut.vertices.size()));
    if (inserted) {
      const int low = std::min(a, b), high = std::max(a, b);
      const double t = height[low] / (height[low] - height[high]);
      cut.vertices.push_back(mesh.vertices[low] + t * (mesh.vertices[high] - mesh.vertices[low]));
    }
    return it->second;
  };
  for (const auto& t : mesh.triangles) {
    if (mode == CutMode::drop && !(height[t[0]] >= 0 && height[t[1]] >= 0 && height[t[2]] >= 0))
      continue;
    // The triangle clipped to the kept side (Sutherland-Hodgman against one plane): at most
    // four corners, in the triangle's winding.
    std::array<int, 4> polygon{};
    int corners = 0;
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3];
      if (height[a] >= 0) polygon[std::size_t(corners++)] = keep(a);
      if ((height[a] >= 0) != (height[b] >= 0) && height[a] != 0 && height[b] != 0)
        polygon[std::size_t(corners++)] = crossing(a, b);
    }
    for (int k = 1; k + 1 < corners; ++k)
      cut.triangles.push_back({polygon[0], polygon[std::size_t(k)], polygon[std::size_t(k + 1)]});
  }
  if (cut.triangles.empty())
    throw Error("--cut-plane", "", "nothing of the mesh lies on the kept side of the plane");
  // Corners of triangles that clipped away to a point or a segment are left unused.
  std::vector<int> used(cut.vertices.size(), -1);
  SurfaceMesh compact;
  for (auto& t : cut.triangles) {
    for (int& corner : t) {
      if (used[corner] < 0) {
        used[corner] = int(compact.vertices.size());
        compact.vertices.push_back(cut.vertices[corner]);
      }
      corner = used[corner];
    }
    compact.triangles.push_back(t);
  }
  return compact;
}

void cut_segments(std::vector<edges::FeatureSegment>& segments, const Vec& point,
                  const Vec& normal) {
  const Vec n = normal.normalized();
  std::vector<edges::FeatureSegment> kept;
  for (edges::FeatureSegment segment : segments) {
    const double ha = n.dot(segment.a - point), hb = n.dot(segment.b - point);
    if (ha < 0 && hb < 0) continue;
    if (ha < 0) segment.a += ha / (ha - hb) * (segment.b - segment.a);
    if (hb < 0) segment.b += hb / (hb - ha) * (segment.a - segment.b);
    kept.push_back(segment);
  }
  segments = std::move(kept);
}

}  // namespace glint::cad
