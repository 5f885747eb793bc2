#include "fusion/marching_cubes_table.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

namespace glint::fusion {
namespace {

Eigen::Vector3d corner_position(int c) {
  return {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)};
}

int edge_between(int a, int b) {
  const int low = std::min(a, b);
  const int axis = std::countr_zero(static_cast<unsigned>(a ^ b));
  for (int e = 0; e < 12; ++e) {
    if (kCubeEdges[e].corner == low && kCubeEdges[e].axis == axis) return e;
  }
  return -1;
}

// The 4 corners of each face, counter-clockwise seen from outside the cube.
std::array<std::array<int, 4>, 6> face_cycles() {
  std::array<std::array<int, 4>, 6> faces{};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      std::array<int, 4> corners{};
      int n = 0;
      for (int c = 0; c < 8; ++c) {
        if (((c >> axis) & 1) == side) corners[n++] = c;
      }
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      normal[axis] = side ? 1.0 : -1.0;
      const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5) + 0.5 * normal;
      const Eigen::Vector3d u = (corner_position(corners[0]) - centre).normalized();
      const Eigen::Vector3d v = normal.cross(u);
      std::sort(corners.begin(), corners.end(), [&](int a, int b) {
        const Eigen::Vector3d pa = corner_position(a) - centre, pb = corner_position(b) - centre;
        return std::atan2(pa.dot(v), pa.dot(u)) < std::atan2(pb.dot(v), pb.dot(u));
      });
      faces[axis * 2 + side] = corners;
    }
  }
  return faces;
}

CubeCase trace_case(int configuration, const std::array<std::array<int, 4>, 6>& faces) {
  const auto inside = [&](int c) { return (configuration >> c) & 1; };
  // next[e]: the polygon edge after crossing edge e. On each face an entering crossing
  // (outside -> inside, walking counter-clockwise) joins the following leaving crossing.
  std::array<int, 12> next;
  next.fill(-1);
  for (const auto& face : faces) {
    std::vector<std::pair<int, bool>> crossings;  // (edge, entering)
    for (int i = 0; i < 4; ++i) {
      const int a = face[i], b = face[(i + 1) % 4];
      if (inside(a) != inside(b)) crossings.push_back({edge_between(a, b), inside(b) != 0});
    }
    for (std::size_t j = 0; j < crossings.size(); ++j) {
      const auto& leaving = crossings[j];
      const auto& entering = crossings[(j + crossings.size() - 1) % crossings.size()];
      if (!leaving.second && entering.second) next[entering.first] = leaving.first;
    }
  }
  CubeCase result;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (next[start] < 0 || used[start]) continue;
    std::vector<int> loop;
    for (int e = start; !used[e]; e = next[e]) {
      used[e] = true;
      loop.push_back(e);
    }
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
      const int t = result.triangle_count++;
      result.edges[3 * t] = static_cast<std::int8_t>(loop[0]);
      result.edges[3 * t + 1] = static_cast<std::int8_t>(loop[i]);
      result.edges[3 * t + 2] = static_cast<std::int8_t>(loop[i + 1]);
    }
  }
  return result;
}

}  // namespace

const std::array<CubeCase, 256>& marching_cubes_cases() {
  static const std::array<CubeCase, 256> cases = [] {
    const auto faces = face_cycles();
    std::array<CubeCase, 256> table;
    for (int configuration = 0; configuration < 256; ++configuration)
      table[configuration] = trace_case(configuration, faces);
    return table;
  }();
  return cases;
}

}  // namespace glint::fusion
