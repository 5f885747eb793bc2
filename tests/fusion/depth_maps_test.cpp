// Depth and normal maps: the bilateral depth filter against its definition, edge-aware smoothing
// of ray-cast normals.
#include "fusion/depth_maps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace glint::fusion {
namespace {

const Intrinsics kCamera{64, 48, 50.0, 50.0, 31.5, 23.5};

// A ridge z = 1 + |x| seen from the origin: two faces meeting at 90 degrees along x = 0.
struct Ridge {
  ImageF depth_m{kCamera.width, kCamera.height, 1};
  ImageF points{kCamera.width, kCamera.height, 3};
  ImageF normals{kCamera.width, kCamera.height, 3};
  ImageF true_normals{kCamera.width, kCamera.height, 3};
};

Ridge noisy_ridge() {
  Ridge ridge;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.15f, 0.15f);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      const Eigen::Vector3d ray = kCamera.ray(x, y);
      const double z = 1.0 / (1.0 - std::abs(ray.x()));
      const Eigen::Vector3f point = (ray * z).cast<float>();
      const Eigen::Vector3f face =
          Eigen::Vector3f(point.x() > 0 ? 1.0f : -1.0f, 0.0f, -1.0f).normalized();
      const Eigen::Vector3f measured =
          (face + Eigen::Vector3f(noise(rng), noise(rng), noise(rng))).normalized();
      ridge.depth_m.at(x, y, 0) = float(z);
      for (int c = 0; c < 3; ++c) {
        ridge.points.at(x, y, c) = point[c];
        ridge.true_normals.at(x, y, c) = face[c];
        ridge.normals.at(x, y, c) = measured[c];
      }
    }
  return ridge;
}

float angle_deg(const ImageF& a, const ImageF& b, int x, int y) {
  const Eigen::Vector3f u(a.at(x, y, 0), a.at(x, y, 1), a.at(x, y, 2));
  const Eigen::Vector3f v(b.at(x, y, 0), b.at(x, y, 1), b.at(x, y, 2));
  return std::acos(std::clamp(u.dot(v), -1.0f, 1.0f)) * 180.0f / float(M_PI);
}

TEST(SmoothNormals, NoiseIsAveragedWithinEachFaceButNotAcrossTheEdge) {
  Ridge ridge = noisy_ridge();
  const int hole_x = 10, hole_y = 20;
  for (int c = 0; c < 3; ++c) ridge.normals.at(hole_x, hole_y, c) = NAN;
  const ImageF smoothed = smooth_normals(ridge.points, ridge.normals, ridge.depth_m, kCamera, 0.1f);
  double before = 0, after = 0;
  float worst_beside_edge = 0;
  int count = 0;
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x) {
      if (x == hole_x && y == hole_y) continue;
      before += angle_deg(ridge.normals, ridge.true_normals, x, y);
      after += angle_deg(smoothed, ridge.true_normals, x, y);
      ++count;
      // The ridge runs between columns 31 and 32 (cx = 31.5).
      if (x == 31 || x == 32)
        worst_beside_edge =
            std::max(worst_beside_edge, angle_deg(smoothed, ridge.true_normals, x, y));
    }
  EXPECT_LT(after / count, 0.4 * before / count) << before / count << " -> " << after / count;
  // Averaging across the 90-degree edge would tilt these by tens of degrees.
  EXPECT_LT(worst_beside_edge, 8.0f);
  EXPECT_TRUE(std::isnan(smoothed.at(hole_x, hole_y, 0)));
}

TEST(SmoothNormals, ExactNormalsOfAPlaneStayExact) {
  Ridge ridge = noisy_ridge();
  const ImageF smoothed =
      smooth_normals(ridge.points, ridge.true_normals, ridge.depth_m, kCamera, 0.1f);
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 0; x < kCamera.width; ++x)
      ASSERT_LT(angle_deg(smoothed, ridge.true_normals, x, y), 0.05f) << x << ", " << y;
}

// smooth_normals()' definition, pixel by pixel (in double).
ImageF smoothing_by_definition(const ImageF& points, const ImageF& normals, const ImageF& depth,
                               const Intrinsics& camera, double radius_m) {
  ImageF out(points.width(), points.height(), 3, NAN);
  for (int y = 0; y < points.height(); ++y)
    for (int x = 0; x < points.width(); ++x) {
      const Eigen::Vector3d n(normals.at(x, y, 0), normals.at(x, y, 1), normals.at(x, y, 2));
      const Eigen::Vector3d p(points.at(x, y, 0), points.at(x, y, 1), points.at(x, y, 2));
      if (!n.allFinite() || !(depth.at(x, y, 0) > 0)) continue;
      const int window =
          std::min(8, int(std::ceil(float(radius_m) * float(camera.fx) / depth.at(x, y, 0))));
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int v = std::max(0, y - window); v <= std::min(points.height() - 1, y + window); ++v)
        for (int u = std::max(0, x - window); u <= std::min(points.width() - 1, x + window); ++u) {
          const Eigen::Vector3d m(normals.at(u, v, 0), normals.at(u, v, 1), normals.at(u, v, 2));
          const Eigen::Vector3d q(points.at(u, v, 0), points.at(u, v, 1), points.at(u, v, 2));
          if (m.allFinite() && m.dot(n) >= 0.5 && (q - p).norm() <= radius_m) sum += m;
        }
      sum.normalize();
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = float(sum[c]);
    }
  return out;
}

TEST(SmoothNormals, MatchesItsDefinitionWithHolesBordersAndWindowsOfEveryWidth) {
  // A 61x45 view (rows end in partial groups of lanes) of a ridge 0.6-2.6 m away, so windows
  // range from 2 to the 8-pixel cap; pixels without a normal, and with a normal but no depth.
  const Intrinsics camera{61, 45, 50.0, 50.0, 30.0, 22.0};
  ImageF depth(camera.width, camera.height, 1), points(camera.width, camera.height, 3),
      normals(camera.width, camera.height, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> noise(-0.4f, 0.4f);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.ray(x, y);
      const double z = 0.6 + 2.0 * y / camera.height + 0.5 * std::abs(ray.x());
      const Eigen::Vector3f point = (ray * z).cast<float>();
      const Eigen::Vector3f normal =
          (Eigen::Vector3f(ray.x() > 0 ? 1.0f : -1.0f, 0.0f, -1.0f).normalized() +
           Eigen::Vector3f(noise(rng), noise(rng), noise(rng)))
              .normalized();
      depth.at(x, y, 0) = (x * 7 + y * 3) % 23 == 0 ? 0.0f : float(z);
      for (int c = 0; c < 3; ++c) {
        points.at(x, y, c) = point[c];
        normals.at(x, y, c) = (x * 5 + y) % 17 == 0 ? NAN : normal[c];
      }
    }
  for (const float radius : {0.05f, 0.2f}) {
    const ImageF smoothed = smooth_normals(points, normals, depth, camera, radius);
    const ImageF expected = smoothing_by_definition(points, normals, depth, camera, radius);
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x)
        for (int c = 0; c < 3; ++c) {
          if (std::isnan(expected.at(x, y, c))) {
            ASSERT_TRUE(std::isnan(smoothed.at(x, y, c))) << x << ", " << y;
            continue;
          }
          ASSERT_NEAR(smoothed.at(x, y, c), expected.at(x, y, c), 1e-5f) << x << ", " << y;
        }
  }
}

// The bilateral filter's definition, pixel by pixel: the mean of the window's pixels with depth,
// weighted by exp(-dist^2 / 2 sigma_space^2) exp(-(d - centre)^2 / 2 sigma_depth^2).
ImageF bilateral_by_definition(const ImageF& depth, const BilateralParams& params) {
  ImageF out(depth.width(), depth.height(), 1);
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const double centre = depth.at(x, y, 0);
      if (!(centre > 0)) continue;
      double sum = 0, weights = 0;
      for (int v = y - params.radius_px; v <= y + params.radius_px; ++v)
        for (int u = x - params.radius_px; u <= x + params.radius_px; ++u) {
          if (u < 0 || v < 0 || u >= depth.width() || v >= depth.height()) continue;
          const double d = depth.at(u, v, 0);
          if (!(d > 0)) continue;
          const double w = std::exp(-((u - x) * (u - x) + (v - y) * (v - y)) /
                                    (2 * params.sigma_space_px * params.sigma_space_px)) *
                           std::exp(-(d - centre) * (d - centre) /
                                    (2 * params.sigma_depth_m * params.sigma_depth_m));
          sum += w * d;
          weights += w;
        }
      out.at(x, y, 0) = float(sum / weights);
    }
  return out;
}

TEST(BilateralFilterDepth, MatchesItsDefinitionWithHolesStepsAndBorders) {
  // 37 x 23: rows not a multiple of the vector width; noise on a step from 1.2 m to 2.5 m, holes.
  ImageF depth(37, 23, 1);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      depth.at(x, y, 0) = uniform(rng) < 0.1f ? 0.0f : (x < 17 ? 1.2f : 2.5f) + noise(rng);
  depth.at(30, 2, 0) = 60.0f;  // far beyond the range term's reach: must not disturb its neighbours
  // Depths a few centimetres from 0, where only the mask keeps the holes beside them out.
  for (int x = 0; x < 9; ++x) depth.at(x, 20, 0) = x % 3 == 0 ? 0.0f : 0.03f + 0.001f * x;
  const BilateralParams params;
  const ImageF filtered = bilateral_filter_depth(depth, params);
  const ImageF expected = bilateral_by_definition(depth, params);
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      EXPECT_NEAR(filtered.at(x, y, 0), expected.at(x, y, 0), 2e-6f * expected.at(x, y, 0))
          << x << ", " << y;
      EXPECT_EQ(filtered.at(x, y, 0) > 0, depth.at(x, y, 0) > 0) << "holes stay holes";
    }
}

TEST(BilateralFilterDepth, AConstantDepthStaysConstant) {
  const ImageF depth(19, 11, 1, 1.75f);
  const ImageF filtered = bilateral_filter_depth(depth, {});
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) EXPECT_FLOAT_EQ(filtered.at(x, y, 0), 1.75f);
}

}  // namespace
}  // namespace glint::fusion
