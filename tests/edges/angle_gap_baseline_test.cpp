#include "edges/angle_gap_baseline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "core/error.h"

namespace glint::edges {
namespace {

constexpr double kPi = std::numbers::pi;

// Hexagonal grid of unit spacing in z = 0 (the regular sampling mesh vertices approach):
// every inner point has six neighbours one unit away, 60° apart. Keeps the points for which
// keep(x, y) holds.
template <class Keep>
PointCloud hex_grid(int half_width, Keep keep) {
  PointCloud cloud;
  for (int row = -half_width; row <= half_width; ++row) {
    for (int col = -half_width; col <= half_width; ++col) {
      const double x = col + 0.5 * (row & 1), y = row * std::sqrt(3.0) / 2;
      if (keep(x, y)) cloud.push_back(float(x), float(y), 0.f);
    }
  }
  return cloud;
}

// Unit icosphere subdivided `levels` times: the vertices of a closed, near-regular mesh.
PointCloud icosphere(int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                           {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                           {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& v : vertices) v.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto [it, is_new] = midpoints.try_emplace(key, int(vertices.size()));
      if (is_new) vertices.push_back((vertices[a] + vertices[b]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& [a, b, c] : faces) {
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  PointCloud cloud;
  for (const auto& v : vertices) cloud.push_back(float(v.x()), float(v.y()), float(v.z()));
  return cloud;
}

TEST(AngleGapBaseline, DiscRimIsBoundaryAndInteriorIsNot) {
  const double radius = 20;
  const PointCloud disc =
      hex_grid(24, [&](double x, double y) { return std::hypot(x, y) <= radius; });
  const std::vector<float> gaps = largest_angle_gap(disc);
  const std::vector<std::uint8_t> labels = classify_angle_gap(disc);
  int rim = 0;
  for (std::size_t i = 0; i < disc.size(); ++i) {
    const double r = std::hypot(disc.x[i], disc.y[i]);
    if (r > radius - 0.4) {
      // At least two of the six neighbour directions leave the disc: a gap of 180°.
      ++rim;
      EXPECT_EQ(labels[i], 2) << "rim point at r = " << r;
      EXPECT_GT(gaps[i], 0.99 * kPi);
    } else if (r < radius - 1.5) {
      EXPECT_EQ(labels[i], 0) << "interior point at r = " << r;
      EXPECT_NEAR(gaps[i], kPi / 3, 1e-4) << "six neighbours 60° apart";
    }
  }
  EXPECT_GT(rim, 60);
}

TEST(AngleGapBaseline, ClosedSphereHasNoBoundary) {
  const PointCloud sphere = icosphere(4);  // 2562 vertices
  const std::vector<std::uint8_t> labels = classify_angle_gap(sphere);
  EXPECT_EQ(std::count(labels.begin(), labels.end(), 2), 0);
}

TEST(AngleGapBaseline, RandomSphereNeedsTheLargerRadius) {
  // Uniform random samples leave gaps between neighbours that a regular sampling has not: at
  // 1.5 spacings (about 7 neighbours) some interior points look like borders, at 4 spacings
  // (about 50) none do.
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  PointCloud sphere;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d p = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    sphere.push_back(float(p.x()), float(p.y()), float(p.z()));
  }
  const std::vector<std::uint8_t> tight = classify_angle_gap(sphere);
  EXPECT_GT(std::count(tight.begin(), tight.end(), 2), 0);
  AngleGapParams wide;
  wide.radius_spacings = 4;
  wide.k = 64;
  const std::vector<std::uint8_t> labels = classify_angle_gap(sphere, wide);
  EXPECT_EQ(std::count(labels.begin(), labels.end(), 2), 0);
}

TEST(AngleGapBaseline, HalfPlaneEdgeIsBoundary) {
  // Hexagonal grid on y >= 0, slightly jittered and tilted about the x axis so the normal is
  // not a coordinate axis; its edge is the row y = 0.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.03f, 0.03f);
  const PointCloud flat = hex_grid(30, [](double, double y) { return y >= 0; });
  PointCloud plane;
  const float c = std::cos(0.4f), s = std::sin(0.4f);
  for (std::size_t i = 0; i < flat.size(); ++i) {
    const float x = flat.x[i] + jitter(rng), y = flat.y[i] + jitter(rng);
    plane.push_back(x, y * c, y * s);
  }
  const std::vector<std::uint8_t> labels = classify_angle_gap(plane);
  int edge = 0;
  for (std::size_t i = 0; i < plane.size(); ++i) {
    if (std::abs(flat.x[i]) > 27 || flat.y[i] > 24) continue;  // away from the other borders
    if (flat.y[i] == 0.f) {
      ++edge;
      EXPECT_EQ(labels[i], 2) << "edge point at x = " << flat.x[i];
    } else if (flat.y[i] > 1.5f) {
      EXPECT_EQ(labels[i], 0) << "inner point at " << flat.x[i] << ", " << flat.y[i];
    }
  }
  EXPECT_GT(edge, 50);
}

TEST(AngleGapBaseline, FixedRadiusMatchesAdaptiveOnUniformGrid) {
  // On a unit hexagonal grid the adaptive radius is about 1.3 spacings' worth: a fixed 1.3
  // gives the same labels.
  const PointCloud disc = hex_grid(16, [](double x, double y) { return std::hypot(x, y) <= 15; });
  AngleGapParams fixed;
  fixed.radius = 1.3;
  EXPECT_EQ(classify_angle_gap(disc, fixed), classify_angle_gap(disc));
}

TEST(AngleGapBaseline, ThresholdSelectsGapsAboveIt) {
  const PointCloud disc = hex_grid(12, [](double x, double y) { return std::hypot(x, y) <= 10; });
  const std::vector<float> gaps = largest_angle_gap(disc);
  AngleGapParams params;
  params.angle_threshold = 2.5;
  const std::vector<std::uint8_t> labels = classify_angle_gap(disc, params);
  for (std::size_t i = 0; i < gaps.size(); ++i) EXPECT_EQ(labels[i] == 2, gaps[i] > 2.5f);
}

TEST(AngleGapBaseline, RejectsBadParameters) {
  const PointCloud disc = hex_grid(6, [](double x, double y) { return std::hypot(x, y) <= 5; });
  AngleGapParams params;
  params.k = 2;
  EXPECT_THROW(largest_angle_gap(disc, params), Error);
  params = {};
  params.angle_threshold = 7.0;
  EXPECT_THROW(largest_angle_gap(disc, params), Error);
  params = {};
  params.radius = -1.0;
  EXPECT_THROW(largest_angle_gap(disc, params), Error);
  params = {};
  params.radius_spacings = 0.0;
  EXPECT_THROW(largest_angle_gap(disc, params), Error);
  PointCloud tiny;
  for (int i = 0; i < 5; ++i) tiny.push_back(float(i), 0.f, 0.f);
  EXPECT_THROW(largest_angle_gap(tiny), Error);
}

}  // namespace
}  // namespace glint::edges
