#include "fusion/depth_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel.h"

namespace glint::fusion {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The three channels of a point or normal map at (x, y).
Eigen::Vector3f vector_at(const ImageF& image, int x, int y) {
  return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
}

}  // namespace

ImageF bilateral_filter_depth(const ImageF& depth_m, const BilateralParams& params) {
  const int width = depth_m.width(), height = depth_m.height(), radius = params.radius_px;
  const float space = static_cast<float>(-0.5 / (params.sigma_space_px * params.sigma_space_px));
  const float range = static_cast<float>(-0.5 / (params.sigma_depth_m * params.sigma_depth_m));
  ImageF filtered(width, height, 1);
  const float* in = depth_m.plane(0);
  float* out = filtered.plane(0);
  std::vector<float> spatial((2 * radius + 1) * (2 * radius + 1));
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      spatial[(dy + radius) * (2 * radius + 1) + dx + radius] =
          std::exp(space * float(dx * dx + dy * dy));
  parallel_for(static_cast<std::size_t>(height), [&](std::size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < width; ++x) {
      const float centre = in[y * width + x];
      if (centre <= 0) {
        out[y * width + x] = 0;
        continue;
      }
      float sum = 0, weights = 0;
      for (int dy = -radius; dy <= radius; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= height) continue;
        for (int dx = -radius; dx <= radius; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= width) continue;
          const float d = in[yy * width + xx];
          if (d <= 0) continue;
          const float w = spatial[(dy + radius) * (2 * radius + 1) + dx + radius] *
                          std::exp(range * (d - centre) * (d - centre));
          sum += w * d;
          weights += w;
        }
      }
      out[y * width + x] = sum / weights;
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
