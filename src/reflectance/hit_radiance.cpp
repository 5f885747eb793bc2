#include "reflectance/hit_radiance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace glint::reflectance {

namespace {

// The radiance observed voxel u sends every way: the colour of its observation of median
// luminance (its highlights, seen from few directions, lie above it).
Eigen::Vector3f diffuse_radiance(const ObservationGrid& grid, int u) {
  const int count = std::min(grid.observation_count(u), kMaxObservationsPerVoxel);
  const Observation* observations = grid.observations(u);
  std::array<std::pair<float, int>, kMaxObservationsPerVoxel> luminance;
  for (int k = 0; k < count; ++k) luminance[std::size_t(k)] = {observations[k].colour().mean(), k};
  std::nth_element(luminance.begin(), luminance.begin() + count / 2, luminance.begin() + count);
  return observations[luminance[std::size_t(count / 2)].second].colour();
}

bool observed(const ObservationGrid& grid, int u) {
  return u >= 0 && grid.observation_count(u) > 0;
}

// The observed one of the neighbours across the faces of p's voxel within `tolerance` of p,
// nearest first; -1 where none is.
int observed_across_faces(const ObservationGrid& grid, const Eigen::Vector3f& p, float tolerance,
                          ObservationGrid::BlockCache& blocks) {
  const float size = float(grid.params().voxel_size_m);
  const Eigen::Vector3f v = p / size;
  const Eigen::Vector3i voxel(int(std::floor(v.x())), int(std::floor(v.y())),
                              int(std::floor(v.z())));
  // Per axis the nearer face of p's voxel: its distance and the neighbour across it.
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
    if (const int u = grid.find_voxel(neighbour, &blocks); observed(grid, u)) return u;
  }
  return -1;
}

}  // namespace

int observed_voxel(const ObservationGrid& grid, const Eigen::Vector3f& p, float tolerance,
                   ObservationGrid::BlockCache& blocks) {
  if (const int u = grid.find(p, &blocks); observed(grid, u)) return u;
  return observed_across_faces(grid, p, tolerance, blocks);
}

bool hit_radiance(const ObservationGrid& grid, const Eigen::Vector3f& h, const Eigen::Vector3f& d,
                  float tolerance, ObservationGrid::BlockCache& blocks, Eigen::Vector3f& radiance) {
  const float size = float(grid.params().voxel_size_m);
  int u = grid.find(h, &blocks);
  if (!observed(grid, u)) u = grid.find(h - d * (0.5f * size), &blocks);
  if (!observed(grid, u)) u = observed_across_faces(grid, h, tolerance, blocks);
  if (u < 0) return false;
  radiance = diffuse_radiance(grid, u);
  return true;
}

}  // namespace glint::reflectance
