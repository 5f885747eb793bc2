#include "reflectance/hemi_image.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace glint::reflectance {

Eigen::Matrix3f local_frame(const Eigen::Vector3f& n) {
  // Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin: "Building an Orthonormal Basis,
  // Revisited", JCGT 2017.
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float b = n.x() * n.y() * a;
  const Eigen::Vector3f t(1.0f + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  const Eigen::Vector3f bitangent(b, sign + n.y() * n.y() * a, -n.y());
  Eigen::Matrix3f world_to_local;
  world_to_local.row(0) = t;
  world_to_local.row(1) = bitangent;
  world_to_local.row(2) = n;
  return world_to_local;
}

Eigen::Vector2f project_to_disk(const Eigen::Vector3f& d, HemiProjection projection) {
  if (projection == HemiProjection::orthographic) return {d.x(), d.y()};
  const float scale = 1.0f / (1.0f + d.z());
  return {d.x() * scale, d.y() * scale};
}

void make_hemi_image(const Observation* observations, int count, const Eigen::Vector3f& normal,
                     const HemiImageParams& params, float* out) {
  const int size = params.size;
  const int pixels = size * size;
  if (size < kMinHemiImageSize || size > kMaxHemiImageSize)
    throw Error("hemi-image", "size",
                fmt::format("{} pixels per side is outside [{}, {}]", size, kMinHemiImageSize,
                            kMaxHemiImageSize));
  constexpr int kMaxObservations = 256;
  std::array<Eigen::Vector2f, kMaxObservations> position;
  std::array<int, kMaxObservations> source;
  const Eigen::Matrix3f to_local = local_frame(normal);
  const float half_extent = 0.5f * float(size - 1);
  int kept = 0;
  for (int k = 0; k < count && kept < kMaxObservations; ++k) {
    const Eigen::Vector3f local = to_local * observations[k].direction;
    if (local.z() <= 0.0f) continue;
    position[kept] = (project_to_disk(local, params.projection).array() + 1.0f) * half_extent;
    source[kept++] = k;
  }
  // Nearest observation of every pixel, a row at a time: the loop over a row's pixels has no
  // branches and vectorises (ties go to the first observation, as in a plain scan).
  std::array<float, kMaxHemiImageSize> nearest, column;
  std::array<int, kMaxHemiImageSize> index;
  for (int x = 0; x < size; ++x) column[x] = float(x);
  for (int y = 0; y < size; ++y) {
    nearest.fill(std::numeric_limits<float>::max());
    index.fill(-1);
    for (int k = 0; k < kept; ++k) {
      const float px = position[k].x(), dy = position[k].y() - float(y);
      const float dy2 = dy * dy;
      for (int x = 0; x < size; ++x) {
        const float dx = px - column[x];
        const float distance = dx * dx + dy2;
        const bool closer = distance < nearest[x];
        nearest[x] = closer ? distance : nearest[x];
        index[x] = closer ? k : index[x];
      }
    }
    for (int x = 0; x < size; ++x) {
      const Eigen::Vector3f colour =
          index[x] < 0 ? Eigen::Vector3f::Zero() : observations[source[index[x]]].colour;
      for (int c = 0; c < 3; ++c) out[c * pixels + y * size + x] = colour[c];
    }
  }
}

}  // namespace glint::reflectance
