#include "reflectance/hemi_image.h"

#include <array>
#include <cmath>
#include <limits>

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
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Eigen::Vector3f colour = Eigen::Vector3f::Zero();
      float nearest = std::numeric_limits<float>::max();
      for (int k = 0; k < kept; ++k) {
        const float distance = (position[k] - Eigen::Vector2f(float(x), float(y))).squaredNorm();
        if (distance < nearest) {
          nearest = distance;
          colour = observations[source[k]].colour;
        }
      }
      for (int c = 0; c < 3; ++c) out[c * pixels + y * size + x] = colour[c];
    }
}

}  // namespace glint::reflectance
