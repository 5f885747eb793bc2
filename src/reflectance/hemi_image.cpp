#include "reflectance/hemi_image.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/error.h"
#include "reflectance/light_incidence.h"

namespace glint::reflectance {

const char* hemi_projection_name(HemiProjection projection) {
  return projection == HemiProjection::parabolic ? "parabolic" : "orthographic";
}

HemiProjection parse_hemi_projection(const std::string& name, const std::string& where) {
  if (name == "parabolic") return HemiProjection::parabolic;
  if (name == "orthographic") return HemiProjection::orthographic;
  throw Error(where, "projection",
              fmt::format("unknown projection \"{}\" (parabolic or orthographic)", name));
}

const char* hemi_input_name(HemiInput input) {
  return input == HemiInput::radiance ? "radiance" : "reflectance";
}

HemiInput parse_hemi_input(const std::string& name, const std::string& where) {
  if (name == "radiance") return HemiInput::radiance;
  if (name == "reflectance") return HemiInput::reflectance;
  throw Error(where, "input", fmt::format("unknown input \"{}\" (radiance or reflectance)", name));
}

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

Eigen::Vector3f hemi_input_scale(HemiInput input, const std::vector<render::PointLight>& lights,
                                 const Eigen::Vector3f& position, const Eigen::Vector3f& normal,
                                 const PointLighting& lighting) {
  return input == HemiInput::radiance ? Eigen::Vector3f::Ones()
                                      : reflectance_scale(lights, position, normal, lighting);
}

void make_hemi_image(const Observation* observations, int count, const Eigen::Vector3f& normal,
                     const HemiImageParams& params, float* out, const Eigen::Vector3f& scale) {
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
    const Eigen::Vector3f local = to_local * observations[k].direction();
    if (local.z() <= 0.0f) continue;
    position[kept] = (project_to_disk(local, params.projection).array() + 1.0f) * half_extent;
    source[kept++] = k;
  }
  // Nearest observation of every pixel, a row at a time in lanes of four columns, without
  // branches (ties go to the first observation, as in a plain scan). The compiler left the plain
  // loop over a row's pixels scalar, with a mispredicted branch per pixel and observation.
  constexpr int kHemiLanes = 4;  // one SSE register of floats
  using Lanes = float __attribute__((vector_size(kHemiLanes * sizeof(float))));
  using Indices = std::int32_t __attribute__((vector_size(kHemiLanes * sizeof(std::int32_t))));
  constexpr int kMaxChunks = (kMaxHemiImageSize + kHemiLanes - 1) / kHemiLanes;
  const int chunks = (size + kHemiLanes - 1) / kHemiLanes;
  std::array<Lanes, kMaxChunks> column, nearest;
  std::array<Indices, kMaxChunks> index;
  for (int c = 0; c < chunks; ++c)
    for (int lane = 0; lane < kHemiLanes; ++lane) column[c][lane] = float(c * kHemiLanes + lane);
  for (int y = 0; y < size; ++y) {
    for (int c = 0; c < chunks; ++c) {
      nearest[c] = Lanes{} + std::numeric_limits<float>::max();
      index[c] = Indices{} - 1;
    }
    for (int k = 0; k < kept; ++k) {
      const float px = position[k].x(), dy = position[k].y() - float(y);
      const float dy2 = dy * dy;
      for (int c = 0; c < chunks; ++c) {
        const Lanes dx = px - column[c];
        const Lanes distance = dx * dx + dy2;
        const Indices closer = distance < nearest[c];
        nearest[c] = closer ? distance : nearest[c];
        index[c] = closer ? Indices{} + k : index[c];
      }
    }
    for (int x = 0; x < size; ++x) {
      const int nearest_index = index[x / kHemiLanes][x % kHemiLanes];
      const Eigen::Vector3f colour = nearest_index < 0
                                         ? Eigen::Vector3f::Zero()
                                         : observations[source[nearest_index]].colour();
      for (int c = 0; c < 3; ++c) out[c * pixels + y * size + x] = colour[c] * scale[c];
    }
  }
}

}  // namespace glint::reflectance
