#include "reflectance/hit_radiance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace glint::reflectance {

bool diffuse_radiance(const ObservationGrid& grid, int u, Eigen::Vector3f& radiance) {
  const int count = std::min(grid.observation_count(u), kMaxObservationsPerVoxel);
  if (count == 0) return false;
  const Observation* observations = grid.observations(u);
  std::array<std::pair<float, int>, kMaxObservationsPerVoxel> luminance;
  for (int k = 0; k < count; ++k) luminance[std::size_t(k)] = {observations[k].colour().mean(), k};
  std::nth_element(luminance.begin(), luminance.begin() + count / 2, luminance.begin() + count);
  radiance = observations[luminance[std::size_t(count / 2)].second].colour();
  return true;
}

bool hit_radiance(const ObservationGrid& grid, const Eigen::Vector3f& h, const Eigen::Vector3f& d,
                  float tolerance, ObservationGrid::BlockCache& blocks, Eigen::Vector3f& radiance) {
  const float size = float(grid.params().voxel_size_m);
  for (const float back : {0.0f, 0.5f}) {
    const int u = grid.find(h - d * (back * size), &blocks);
    if (u >= 0 && diffuse_radiance(grid, u, radiance)) return true;
  }
  const Eigen::Vector3f v = h / size;
  const Eigen::Vector3i voxel(int(std::floor(v.x())), int(std::floor(v.y())),
                              int(std::floor(v.z())));
  // Per axis the nearer face of h's voxel: its distance and the neighbour across it.
  std::array<std::pair<float, Eigen::Vector3i>, 3> faces;
  for (int axis = 0; axis < 3; ++axis) {
    const float below = (v[axis] - float(voxel[axis])) * size, above = size - below;
    Eigen::Vector3i neighbour = voxel;
    neighbour[axis] += below < above ? -1 : 1;
    faces[std::size_t(axis)] = {std::min(below, above), neighbour};
  }
  std::sort(faces.begin(), faces.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [distance, neighbour] : faces) {
    if (!(distance <= tolerance)) break;
    const int u = grid.find_voxel(neighbour, &blocks);
    if (u >= 0 && diffuse_radiance(grid, u, radiance)) return true;
  }
  return false;
}

}  // namespace glint::reflectance
