#include "fusion/depth_maps.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/fast_exp.h"
#include "core/parallel.h"

namespace glint::fusion {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The three channels of a point or normal map at (x, y).
Eigen::Vector3f vector_at(const ImageF& image, int x, int y) {
  return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
}

// Adds to sum[x] and weights[x], for x in [begin, end), the bilateral terms of the neighbour at
// column x + dx of row `neighbours`: one loop over the row per offset, which vectorises (a
// per-pixel window with std::exp did not, and was most of a tracked frame's filtering).
// |difference| is clamped at `max_difference`, where the range weight is e^-100 (0 in
// exp_nonpositive()'s range), and a neighbour without depth is masked out with an integer AND:
// with a float select or clamp instead, GCC 12 left the loop scalar.
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void add_bilateral_offset(const float* __restrict centre, const float* __restrict neighbours,
                          int dx, int begin, int end, float spatial, float range,
                          float max_difference, float* __restrict sum, float* __restrict weights) {
  for (int x = begin; x < end; ++x) {
    const float d = neighbours[x + dx];
    const float difference = std::min(std::fabs(d - centre[x]), max_difference);
    const float falloff = spatial * exp_nonpositive(range * difference * difference);
    const std::int32_t has_depth = -std::int32_t(std::bit_cast<std::int32_t>(d) > 0);
    const float w = std::bit_cast<float>(std::bit_cast<std::int32_t>(falloff) & has_depth);
    sum[x] += w * d;
    weights[x] += w;
  }
}

}  // namespace

ImageF bilateral_filter_depth(const ImageF& depth_m, const BilateralParams& params) {
  const int width = depth_m.width(), height = depth_m.height(), radius = params.radius_px;
  const float space = static_cast<float>(-0.5 / (params.sigma_space_px * params.sigma_space_px));
  const float range = static_cast<float>(-0.5 / (params.sigma_depth_m * params.sigma_depth_m));
  const float max_difference = std::sqrt(-100.0f / range);
  std::vector<float> spatial((2 * radius + 1) * (2 * radius + 1));
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      spatial[(dy + radius) * (2 * radius + 1) + dx + radius] =
          std::exp(space * float(dx * dx + dy * dy));
  ImageF filtered(width, height, 1);
  const float* in = depth_m.plane(0);
  float* out = filtered.plane(0);
  parallel_for_chunks(
      static_cast<std::size_t>(height), 8, [&](std::size_t first, std::size_t last) {
        std::vector<float> sum(static_cast<std::size_t>(width)), weights(sum.size());
        for (int y = int(first); y < int(last); ++y) {
          std::fill(sum.begin(), sum.end(), 0.0f);
          std::fill(weights.begin(), weights.end(), 0.0f);
          const float* centre = in + std::size_t(y) * width;
          for (int dy = std::max(-radius, -y); dy <= std::min(radius, height - 1 - y); ++dy)
            for (int dx = -radius; dx <= radius; ++dx)
              add_bilateral_offset(centre, centre + std::ptrdiff_t(dy) * width, dx,
                                   std::max(0, -dx), std::min(width, width - dx),
                                   spatial[(dy + radius) * (2 * radius + 1) + dx + radius], range,
                                   max_difference, sum.data(), weights.data());
          // A pixel with depth weighs itself in, so its weights are positive.
          for (int x = 0; x < width; ++x)
            out[std::size_t(y) * width + x] = centre[x] > 0 ? sum[x] / weights[x] : 0.0f;
        }
      });
  return filtered;
}

ImageF downsample_depth(const ImageF& depth_m, double sigma_depth_m) {
  const int width = depth_m.width() / 2, height = depth_m.height() / 2;
  const float limit = static_cast<float>(3 * sigma_depth_m);
  ImageF half(width, height, 1);
  const float* in = depth_m.plane(0);
  float* out = half.plane(0);
  parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < width; ++x) {
      float reference = 0, sum = 0;
      int count = 0;
      for (int k = 0; k < 4; ++k) {
        const float d = in[(2 * y + k / 2) * depth_m.width() + 2 * x + k % 2];
        if (d <= 0) continue;
        if (count == 0) reference = d;
        if (std::abs(d - reference) > limit) continue;
        sum += d;
        ++count;
      }
      out[y * width + x] = count ? sum / count : 0.0f;
    }
  });
  return half;
}

const ImageF& halved_depth(const ImageF& depth_m, int halvings, double sigma_depth_m,
                           ImageF& storage) {
  for (int level = 0; level < halvings; ++level)
    storage = downsample_depth(level == 0 ? depth_m : storage, sigma_depth_m);
  return halvings == 0 ? depth_m : storage;
}

ImageF points_from_depth(const ImageF& depth_m, const Intrinsics& intrinsics) {
  ImageF points(depth_m.width(), depth_m.height(), 3);
  const float* depth = depth_m.plane(0);
  float* px = points.plane(0);
  float* py = points.plane(1);
  float* pz = points.plane(2);
  const int width = depth_m.width();
  parallel_for(depth_m.pixel_count(), [&](std::size_t i) {
    const float d = depth[i];
    if (d <= 0) {
      px[i] = py[i] = pz[i] = kNaN;
      return;
    }
    const Eigen::Vector3d p = intrinsics.back_project(double(i % width), double(i / width), d);
    px[i] = float(p.x());
    py[i] = float(p.y());
    pz[i] = float(p.z());
  });
  return points;
}

ImageF normals_from_points(const ImageF& points, const Eigen::Vector3d& viewpoint) {
  const int width = points.width(), height = points.height();
  ImageF normals(width, height, 3, kNaN);
  const auto point = [&](int x, int y) { return vector_at(points, x, y); };
  const Eigen::Vector3f eye = viewpoint.cast<float>();
  parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
    const int y = static_cast<int>(row);
    if (y == 0 || y == height - 1) return;
    for (int x = 1; x < width - 1; ++x) {
      const Eigen::Vector3f n =
          (point(x + 1, y) - point(x - 1, y)).cross(point(x, y + 1) - point(x, y - 1));
      const float length = n.norm();
      if (!(length > 0)) continue;  // also false for NaN
      const float sign = n.dot(eye - point(x, y)) < 0 ? -1.0f : 1.0f;
      for (int c = 0; c < 3; ++c) normals.at(x, y, c) = sign * n[c] / length;
    }
  });
  return normals;
}

ImageF smooth_normals(const ImageF& points, const ImageF& normals, const ImageF& depth_m,
                      const Intrinsics& intrinsics, float radius_m) {
  const int width = points.width(), height = points.height();
  ImageF smoothed(width, height, 3, kNaN);
  constexpr int kMaxRadiusPx = 8;
  constexpr float kSameFace = 0.5f;  // cos 60 degrees
  const float radius_squared = radius_m * radius_m;
  parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3f n = vector_at(normals, x, y);
      const float depth = depth_m.at(x, y, 0);
      if (!n.allFinite() || !(depth > 0)) continue;
      const Eigen::Vector3f p = vector_at(points, x, y);
      const int window = std::min(
          kMaxRadiusPx, static_cast<int>(std::ceil(radius_m * float(intrinsics.fx) / depth)));
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (int v = std::max(0, y - window); v <= std::min(height - 1, y + window); ++v)
        for (int u = std::max(0, x - window); u <= std::min(width - 1, x + window); ++u) {
          const Eigen::Vector3f m = vector_at(normals, u, v);
          if (!m.allFinite() || m.dot(n) < kSameFace) continue;
          if ((vector_at(points, u, v) - p).squaredNorm() > radius_squared) continue;
          sum += m;
        }
      const Eigen::Vector3f mean = sum.normalized();
      for (int c = 0; c < 3; ++c) smoothed.at(x, y, c) = mean[c];
    }
  });
  return smoothed;
}

}  // namespace glint::fusion
