#include "edges/angle_gap_baseline.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/error.h"
#include "geometry/covariance.h"
#include "geometry/neighbourhoods.h"

namespace glint::edges {
namespace {

void check(const AngleGapParams& params) {
  if (params.k < 3) throw Error("", "angle-gap k", "must be at least 3 (a normal needs 3 points)");
  if (params.k > 1024) throw Error("", "angle-gap k", "must be at most 1024");
  if (!(params.radius >= 0.0) || !std::isfinite(params.radius)) {
    throw Error("", "angle-gap radius", "must be >= 0 (0 = adaptive)");
  }
  if (params.radius == 0.0 && !(params.radius_spacings > 0.0 && params.radius_spacings < 1e6)) {
    throw Error("", "angle-gap radius_spacings", "must be positive");
  }
  if (!(params.angle_threshold > 0.0 && params.angle_threshold < 2.0 * std::numbers::pi)) {
    throw Error("", "angle-gap angle_threshold", "must be in (0, 2π) radians");
  }
}

// Largest gap between the sorted angles, the wrap-around from the last to the first included
// (the rule of PCL's BoundaryEstimation::isBoundaryPoint).
float largest_gap(float* angles, int count) {
  if (count == 0) return 0.f;
  // Insertion sort: a handful of angles per point.
  for (int i = 1; i < count; ++i) {
    const float value = angles[i];
    int j = i;
    for (; j > 0 && angles[j - 1] > value; --j) angles[j] = angles[j - 1];
    angles[j] = value;
  }
  float gap = 2.f * std::numbers::pi_v<float> - angles[count - 1] + angles[0];
  for (int i = 1; i < count; ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
  return gap;
}

}  // namespace

std::vector<float> largest_angle_gap(const PointCloud& cloud, const AngleGapParams& params) {
  check(params);
  std::vector<float> gaps(cloud.size(), 0.f);
  geometry::NeighbourhoodParams search;
  search.k = params.k;
  const double spacing_per_kth = std::sqrt(std::numbers::pi / double(params.k));
  geometry::for_each_neighbourhood(cloud, search, [&](const geometry::Neighbourhood& nb) {
    geometry::Moments moments;
    for (int j = 0; j < nb.size; ++j) moments.add(nb.dx[j], nb.dy[j], nb.dz[j]);
    const Eigen::Vector3d normal = geometry::smallest_eigenvector(moments.covariance());
    // Tangent-plane axes u, v: any orthonormal pair perpendicular to the normal.
    const Eigen::Vector3d helper =
        std::abs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d u = normal.cross(helper).normalized();
    const Eigen::Vector3d v = normal.cross(u);

    const int last = nb.size - 1;
    const double kth =
        std::sqrt(double(nb.dx[last]) * nb.dx[last] + double(nb.dy[last]) * nb.dy[last] +
                  double(nb.dz[last]) * nb.dz[last]);
    const double radius =
        params.radius > 0 ? params.radius : params.radius_spacings * spacing_per_kth * kth;
    const float radius2 = float(radius * radius);
    std::array<float, 1024> angles;
    int count = 0;
    for (int j = 0; j < nb.size; ++j) {
      const float dx = nb.dx[j], dy = nb.dy[j], dz = nb.dz[j];
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (d2 == 0.f || d2 > radius2) continue;  // the point itself, duplicates, outside
      const double along_u = u.x() * dx + u.y() * dy + u.z() * dz;
      const double along_v = v.x() * dx + v.y() * dy + v.z() * dz;
      angles[count++] = float(std::atan2(along_v, along_u));
    }
    gaps[nb.point] = largest_gap(angles.data(), count);
  });
  return gaps;
}

std::vector<std::uint8_t> classify_angle_gap(const PointCloud& cloud,
                                             const AngleGapParams& params) {
  const std::vector<float> gaps = largest_angle_gap(cloud, params);
  std::vector<std::uint8_t> labels(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    labels[i] = gaps[i] > params.angle_threshold ? 2 : 0;
  }
  return labels;
}

}  // namespace glint::edges
