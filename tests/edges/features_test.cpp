#include "edges/features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>
#include <vector>

#include "core/error.h"

namespace glint::edges {
namespace {

enum Feature {
  kSigmaUpper1 = 0,
  kSigmaLower1 = 3,
  kDPerp = 6,
  kDPar,
  kSPerp,
  kSPar,
  kCPerp,
  kCPar
};

// Jittered grid of spacing h on a plane patch, mapped into 3D by `place(u, v)`.
template <class Place>
void add_patch(PointCloud& cloud, int nu, int nv, float h, std::mt19937& rng, Place place) {
  std::uniform_real_distribution<float> jitter(-0.2f * h, 0.2f * h);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const Eigen::Vector3f p = place(i * h + jitter(rng), j * h + jitter(rng));
      cloud.push_back(p.x(), p.y(), p.z());
    }
  }
}

std::size_t nearest_to(const PointCloud& cloud, const Eigen::Vector3f& target) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    if ((cloud.point(i) - target).squaredNorm() < (cloud.point(best) - target).squaredNorm())
      best = i;
  }
  return best;
}

const float h = 0.01f;

TEST(Features, PlaneInteriorIsFlatAndCentred) {
  std::mt19937 rng(1);
  PointCloud plane;
  add_patch(plane, 60, 60, h, rng, [](float u, float v) { return Eigen::Vector3f(u, v, 0.f); });
  const FeatureMatrix f = compute_features(plane);
  ASSERT_EQ(f.points, plane.size());
  ASSERT_EQ(f.scales, 4);
  const std::size_t centre = nearest_to(plane, {0.3f, 0.3f, 0.f});
  for (int s = 0; s < 4; ++s) {
    EXPECT_NEAR(f.at(centre, s, kDPerp), 0.f, 1e-3f) << "scale " << s;
    EXPECT_NEAR(f.at(centre, s, kSPerp), 0.f, 1e-3f) << "scale " << s;
    EXPECT_LT(f.at(centre, s, kSPar), 0.3f) << "scale " << s;
    EXPECT_NEAR(f.at(centre, s, kCPerp), 0.f, 1e-3f) << "scale " << s;
  }
}

TEST(Features, HalfPlaneEdgeHasLargeTangentialOffset) {
  std::mt19937 rng(2);
  PointCloud plane;
  add_patch(plane, 30, 60, h, rng, [](float u, float v) { return Eigen::Vector3f(u, v, 0.f); });
  const FeatureMatrix f = compute_features(plane);
  const std::size_t edge = nearest_to(plane, {0.f, 0.3f, 0.f});
  const std::size_t interior = nearest_to(plane, {0.15f, 0.3f, 0.f});
  for (int s = 0; s < 4; ++s) {
    // A half-disc neighbourhood's centre lies 4r/(3π) inside: about 1.1 in normalised units.
    EXPECT_GT(f.at(edge, s, kSPar), 0.7f) << "scale " << s;
    EXPECT_LT(f.at(interior, 0, kSPar), 0.3f);
    EXPECT_NEAR(f.at(edge, s, kSPerp), 0.f, 1e-3f);
  }
}

// A half plane's border point has neighbours on one side only: an empty half turn (less one
// sector at most, for the nearest neighbours' spread); an interior point's largest gap is a
// few sectors at the large scales. The thesis's twelve values stay as they are.
TEST(Features, AngularGapIsHalfATurnOnABorder) {
  std::mt19937 rng(2);
  PointCloud plane;
  add_patch(plane, 30, 60, h, rng, [](float u, float v) { return Eigen::Vector3f(u, v, 0.f); });
  FeatureParams params;
  params.angular_gap = true;
  const FeatureMatrix f = compute_features(plane, params);
  const FeatureMatrix thesis = compute_features(plane);
  ASSERT_EQ(f.per_scale, 13);
  ASSERT_EQ(thesis.per_scale, 12);
  const std::size_t edge = nearest_to(plane, {0.f, 0.3f, 0.f});
  const std::size_t interior = nearest_to(plane, {0.15f, 0.3f, 0.f});
  for (int s = 0; s < 4; ++s) {
    EXPECT_GE(f.at(edge, s, kAngularGapFeature), 0.4f) << "scale " << s;
    EXPECT_LE(f.at(edge, s, kAngularGapFeature), 0.6f) << "scale " << s;
    for (int v = 0; v < kThesisFeaturesPerScale; ++v)
      EXPECT_EQ(f.at(edge, s, v), thesis.at(edge, s, v)) << "scale " << s << " value " << v;
  }
  EXPECT_LE(f.at(interior, 0, kAngularGapFeature), 0.1f);  // k = 128
  EXPECT_LE(f.at(interior, 3, kAngularGapFeature), 0.3f);  // k = 16: ~15 neighbours
}

// A plane sampled 16 times more densely (spacing h against 4h) left of x = 0 than right of it.
// By count the neighbourhood of a point on the dense side of the seam is mostly dense points:
// its centre lies well inside, as at a border. Weighed by area the sparse side counts as much
// as the dense one and the centre comes back towards the point.
TEST(Features, AreaWeightsBalanceADensitySeam) {
  std::mt19937 rng(4);
  PointCloud plane;
  add_patch(plane, 40, 120, h, rng, [](float u, float v) { return Eigen::Vector3f(-u, v, 0.f); });
  add_patch(plane, 10, 30, 4 * h, rng,
            [](float u, float v) { return Eigen::Vector3f(u + 4 * h, v, 0.f); });
  FeatureParams weighted;
  weighted.area_weights = true;
  const FeatureMatrix by_area = compute_features(plane, weighted);
  const FeatureMatrix by_count = compute_features(plane);
  const std::size_t seam = nearest_to(plane, {0.f, 0.6f, 0.f});
  for (int s = 0; s < 2; ++s) {  // k = 128, 64: neighbourhoods that reach across the seam
    EXPECT_GT(by_count.at(seam, s, kSPar), 0.6f) << "scale " << s;
    EXPECT_LT(by_area.at(seam, s, kSPar), 0.5f * by_count.at(seam, s, kSPar)) << "scale " << s;
    EXPECT_NEAR(by_area.at(seam, s, kSPerp), 0.f, 1e-3f) << "scale " << s;
  }
  // Far from the seam the density is even and the weights near 1 (the jitter moves them):
  // the centre stays at the point. (On an exactly flat patch the upper / lower split follows
  // rounding, so the subsets' values are not compared.)
  const std::size_t interior = nearest_to(plane, {-0.2f, 0.6f, 0.f});
  for (int s = 0; s < 4; ++s) {
    EXPECT_LT(by_area.at(interior, s, kSPar), 0.3f) << "scale " << s;
    EXPECT_NEAR(by_area.at(interior, s, kSPar), by_count.at(interior, s, kSPar), 0.1f)
        << "scale " << s;
  }
}

TEST(Features, RightAngleCreaseSeparatesUpperAndLower) {
  std::mt19937 rng(3);
  PointCloud crease;  // an L: floor z = 0 (y >= 0) and wall y = 0 (z >= 0), crease on the x axis
  add_patch(crease, 60, 30, h, rng,
            [](float u, float v) { return Eigen::Vector3f(u, v + h / 2, 0.f); });
  add_patch(crease, 60, 30, h, rng,
            [](float u, float v) { return Eigen::Vector3f(u, 0.f, v + h / 2); });
  crease.push_back(0.3f, 0.f, 0.f);
  const std::size_t on_crease = crease.size() - 1;
  const FeatureMatrix f = compute_features(crease);
  for (int s = 0; s < 4; ++s) {
    EXPECT_GT(f.at(on_crease, s, kDPerp), 0.3f) << "scale " << s;
    float difference = 0, size = 0;
    for (int i = 0; i < 3; ++i) {
      const float upper = f.at(on_crease, s, kSigmaUpper1 + i),
                  lower = f.at(on_crease, s, kSigmaLower1 + i);
      difference += (upper - lower) * (upper - lower);
      size += upper * upper + lower * lower;
    }
    EXPECT_GT(std::sqrt(difference), 0.1f * std::sqrt(size)) << "scale " << s;
    EXPECT_GE(f.at(on_crease, s, kSPerp), 0.f);  // orientation convention
  }
}

TEST(Features, ValuesAreFiniteAndOrderIndependentOfThreads) {
  std::mt19937 rng(4);
  PointCloud cloud;
  add_patch(cloud, 40, 40, h, rng,
            [](float u, float v) { return Eigen::Vector3f(u, v, 0.1f * std::sin(20 * u)); });
  const FeatureMatrix a = compute_features(cloud);
  const FeatureMatrix b = compute_features(cloud);
  ASSERT_EQ(a.values.size(), b.values.size());
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a.values[i]));
    ASSERT_EQ(a.values[i], b.values[i]);
  }
}

TEST(Features, BlocksHoldEveryPointOnceWithTheMatrixRows) {
  std::mt19937 rng(5);
  PointCloud cloud;
  add_patch(cloud, 30, 40, h, rng,
            [](float u, float v) { return Eigen::Vector3f(u, v, u > 0.15f ? u - 0.15f : 0.f); });
  const FeatureMatrix matrix = compute_features(cloud);
  std::mutex mutex;
  std::vector<int> seen(cloud.size(), 0);
  std::size_t mismatches = 0, largest_block = 0;
  compute_features_in_blocks(
      cloud, {}, 100, [&](const std::uint32_t* points, const float* rows, std::size_t count) {
        std::lock_guard<std::mutex> lock(mutex);
        largest_block = std::max(largest_block, count);
        for (std::size_t b = 0; b < count; ++b) {
          ++seen[points[b]];
          for (std::size_t c = 0; c < matrix.row_size(); ++c)
            mismatches += rows[b * matrix.row_size() + c] != matrix.row(points[b])[c];
        }
      });
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(largest_block, 100u);
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  EXPECT_THROW(compute_features_in_blocks(cloud, {}, 0, [](auto...) {}), glint::Error);
}

// A choice before the rows (a gate's) reads the noise statistic of some points and the spacings
// of others on the features' search; the rows then reuse both, and come out as computed afresh.
TEST(Features, RowsReuseWhatAChoiceFoundOnTheSearch) {
  std::mt19937 rng(6);
  PointCloud cloud;  // a density seam, so that area weights change the rows
  add_patch(cloud, 30, 40, h, rng, [](float u, float v) { return Eigen::Vector3f(-u, v, 0.f); });
  add_patch(cloud, 8, 10, 4 * h, rng,
            [](float u, float v) { return Eigen::Vector3f(u + 4 * h, v, u); });
  FeatureParams counted, weighted;
  weighted.area_weights = true;
  const FeatureMatrix by_count = compute_features(cloud, counted);
  const FeatureMatrix by_area = compute_features(cloud, weighted);
  std::vector<std::uint8_t> sampled(cloud.size(), 0), spaced(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); i += 3) sampled[i] = 1;
  for (std::size_t i = 0; i < cloud.size(); i += 2) spaced[i] = 1;
  std::vector<float> statistics;
  std::mutex mutex;
  std::size_t mismatches = 0, rows = 0;
  compute_features_in_blocks(
      cloud, counted, 64,
      [&](const std::uint32_t* points, const float* block, std::size_t count) {
        std::lock_guard<std::mutex> lock(mutex);
        rows += count;
        for (std::size_t b = 0; b < count; ++b)
          for (std::size_t c = 0; c < by_area.row_size(); ++c)
            mismatches += block[b * by_area.row_size() + c] != by_area.row(points[b])[c];
      },
      [&](const geometry::NeighbourhoodSearch& search, SearchFindings& findings) {
        statistics = noise_statistics(cloud, counted, search, sampled, &findings);
        findings.spacings = search.kth_nearest_squared_distances(
            area_spacing_neighbours(cloud.size()), {}, spaced);
        findings.spaced = spaced;
        EXPECT_EQ(findings.neighbourhoods.points.size(), (cloud.size() + 2) / 3);
        return weighted;
      });
  EXPECT_EQ(rows, cloud.size());
  EXPECT_EQ(mismatches, 0u);
  // The statistic is the smallest scale's of the full rows, at the sampled points only.
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ASSERT_EQ(statistics[i], sampled[i] ? noise_statistic(by_count.row(i), 4, 12) : 0.0f) << i;
  // A search of another k and a mask that does not fit the cloud are refused.
  const geometry::NeighbourhoodSearch smaller(cloud, feature_search_params({64, 32}));
  EXPECT_THROW(noise_statistics(cloud, counted, smaller, sampled), glint::Error);
  const geometry::NeighbourhoodSearch search(cloud, feature_search_params(counted.scales));
  sampled.pop_back();
  EXPECT_THROW(noise_statistics(cloud, counted, search, sampled), glint::Error);
}

TEST(Features, RejectsBadInputs) {
  PointCloud small;
  for (int i = 0; i < 100; ++i) small.push_back(float(i), 0.f, float(i % 7));
  EXPECT_THROW(compute_features(small), glint::Error);  // fewer points than k = 128
  EXPECT_THROW(compute_features(PointCloud{}), glint::Error);
  FeatureParams params;
  params.scales = {32, 64};
  EXPECT_THROW(compute_features(small, params), glint::Error);  // not decreasing
  params.scales = {32, 3};
  EXPECT_THROW(compute_features(small, params), glint::Error);  // too small
  params.scales = {32, 16};
  EXPECT_NO_THROW(compute_features(small, params));
  small.x[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(compute_features(small, params), glint::Error);
}

}  // namespace
}  // namespace glint::edges
