#include "fusion/depth_maps.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/fast_exp.h"
#include "core/parallel.h"
#include "fusion/vector_lanes.h"

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

// A point map and a normal map as six planes (x, y, z of each), where a pixel without a normal
// has the zero normal, padded on both sides of each row by pixels without one: a run of lanes
// then reads any neighbour up to kPad columns off the image.
struct SurfacePlanes {
  static constexpr int kPad = 16;

  SurfacePlanes(const ImageF& points, const ImageF& normals)
      : width(points.width()),
        stride(width + 2 * kPad),
        plane_size(std::size_t(stride) * points.height()),
        values(6 * plane_size, 0.0f) {
    parallel_for(static_cast<std::size_t>(points.height()), [&](std::size_t row) {
      const int y = static_cast<int>(row);
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3f n = vector_at(normals, x, y);
        if (!n.allFinite()) continue;
        for (int c = 0; c < 3; ++c) {
          plane(c, y)[x] = points.at(x, y, c);
          plane(3 + c, y)[x] = n[c];
        }
      }
    });
  }
  // Column 0 of row y of plane k: points' x, y, z (k = 0..2), normals' x, y, z (3..5).
  float* plane(int k, int y) {
    return values.data() + (std::size_t(k) * plane_size + std::size_t(y) * stride + kPad);
  }
  const float* plane(int k, int y) const { return const_cast<SurfacePlanes*>(this)->plane(k, y); }

  int width, stride;
  std::size_t plane_size;
  std::vector<float> values;
};

constexpr int kSmoothingMaxRadiusPx = 8;
static_assert(kSmoothingMaxRadiusPx + kLaneCount <= SurfacePlanes::kPad);

// values[0, kLaneCount). (By reference: see vector_lanes.h.)
[[gnu::always_inline]] inline void read_lanes(const float* values, Floats& lanes) {
  std::memcpy(&lanes, values, sizeof(lanes));
}

// Row y of smooth_normals() into `smoothed`, eight centre pixels at a time: per window offset,
// each lane adds its neighbour's normal where it is on the lane's face (within 60 degrees of
// its normal and within radius_m of its point) and inside its window. Per pixel, the window's
// rows were too short for vectors, and summing them up was most of the work.
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void smooth_normals_row(const SurfacePlanes& planes, const ImageF& depth_m, float fx,
                        float radius_m, int y, ImageF& smoothed) {
  constexpr float kSameFace = 0.5f;  // cos 60 degrees
  const int width = planes.width, height = depth_m.height();
  const float radius_squared = radius_m * radius_m;
  for (int x0 = 0; x0 < width; x0 += kLaneCount) {
    // Each lane's window half-width in pixels; -1 for no normal, no depth or off the image.
    alignas(32) std::int32_t windows[kLaneCount];
    int widest = -1;
    for (int lane = 0; lane < kLaneCount; ++lane) {
      const int x = x0 + lane;
      const float depth = x < width ? depth_m.at(x, y, 0) : 0.0f;
      const bool has_normal =
          planes.plane(3, y)[x] != 0 || planes.plane(4, y)[x] != 0 || planes.plane(5, y)[x] != 0;
      windows[lane] =
          has_normal && depth > 0
              ? std::min(kSmoothingMaxRadiusPx, static_cast<int>(std::ceil(radius_m * fx / depth)))
              : -1;
      widest = std::max(widest, windows[lane]);
    }
    if (widest < 0) continue;
    Ints window;
    std::memcpy(&window, windows, sizeof(window));
    Floats px, py, pz, nx, ny, nz;
    read_lanes(planes.plane(0, y) + x0, px);
    read_lanes(planes.plane(1, y) + x0, py);
    read_lanes(planes.plane(2, y) + x0, pz);
    read_lanes(planes.plane(3, y) + x0, nx);
    read_lanes(planes.plane(4, y) + x0, ny);
    read_lanes(planes.plane(5, y) + x0, nz);
    Floats sx{}, sy{}, sz{};
    for (int dv = -widest; dv <= widest; ++dv) {
      const int v = y + dv;
      if (v < 0 || v >= height) continue;
      const Ints row_inside = window >= std::abs(dv);
      const float *qx = planes.plane(0, v) + x0, *qy = planes.plane(1, v) + x0,
                  *qz = planes.plane(2, v) + x0;
      const float *mx = planes.plane(3, v) + x0, *my = planes.plane(4, v) + x0,
                  *mz = planes.plane(5, v) + x0;
      for (int du = -widest; du <= widest; ++du) {
        Floats m_x, m_y, m_z, q_x, q_y, q_z;
        read_lanes(mx + du, m_x);
        read_lanes(my + du, m_y);
        read_lanes(mz + du, m_z);
        read_lanes(qx + du, q_x);
        read_lanes(qy + du, q_y);
        read_lanes(qz + du, q_z);
        const Floats dx = q_x - px, dy = q_y - py, dz = q_z - pz;
        const Ints same_face = row_inside & (window >= std::abs(du)) &
                               (m_x * nx + m_y * ny + m_z * nz >= kSameFace) &
                               (dx * dx + dy * dy + dz * dz <= radius_squared);
        sx += same_face ? m_x : Floats{};
        sy += same_face ? m_y : Floats{};
        sz += same_face ? m_z : Floats{};
      }
    }
    for (int lane = 0; lane < kLaneCount; ++lane) {
      if (windows[lane] < 0) continue;
      const Eigen::Vector3f mean = Eigen::Vector3f(sx[lane], sy[lane], sz[lane]).normalized();
      for (int c = 0; c < 3; ++c) smoothed.at(x0 + lane, y, c) = mean[c];
    }
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

Intrinsics halved_intrinsics(const Intrinsics& intrinsics, int halvings) {
  Intrinsics halved = intrinsics;
  for (int level = 0; level < halvings; ++level) {
    const int width = halved.width / 2, height = halved.height / 2;
    halved = halved.scaled(0.5);
    halved.width = width;
    halved.height = height;
  }
  return halved;
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
  ImageF smoothed(points.width(), points.height(), 3, kNaN);
  const SurfacePlanes planes(points, normals);
  parallel_for(static_cast<std::size_t>(points.height()), [&](std::size_t row) {
    smooth_normals_row(planes, depth_m, float(intrinsics.fx), radius_m, static_cast<int>(row),
                       smoothed);
  });
  return smoothed;
}

}  // namespace glint::fusion
