#include "edges/features.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "geometry/covariance.h"
#include "geometry/neighbourhoods.h"

namespace glint::edges {
namespace {

using Eigen::Vector3d;
using geometry::Moments;

// Perpendicular and tangential parts of v with respect to the unit normal n.
void split_along(const Vector3d& v, const Vector3d& n, float& perpendicular, float& tangential) {
  const double along = v.dot(n);
  perpendicular = static_cast<float>(along);
  tangential = static_cast<float>((v - along * n).norm());
}

// Moments of neighbours [begin, end), each with weight weight_of(j) (0 or 1 selects a subset
// without branches). Plain float accumulators: the loop vectorises (features.cpp is built with
// reassociation allowed) and the sums stay accurate since positions are relative to the query.
template <class WeightOf>
Moments sum_moments(const geometry::Neighbourhood& nb, int begin, int end, WeightOf weight_of) {
  float n = 0, sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
  const float* dx = nb.dx;
  const float* dy = nb.dy;
  const float* dz = nb.dz;
  for (int j = begin; j < end; ++j) {
    const float w = weight_of(j);
    const float wx = w * dx[j], wy = w * dy[j], wz = w * dz[j];
    n += w;
    sx += wx, sy += wy, sz += wz;
    sxx += wx * dx[j], sxy += wx * dy[j], sxz += wx * dz[j];
    syy += wy * dy[j], syz += wy * dz[j], szz += wz * dz[j];
  }
  return Moments({n, sx, sy, sz, sxx, sxy, sxz, syy, syz, szz});
}

struct Scratch {
  static constexpr int kBuckets = 64;
  std::vector<float> squared_distances;
  std::vector<std::uint8_t> bucket_of;
  std::vector<std::uint64_t> straddling;
  std::vector<Moments> scale_moments;
};

// Moments of the `count` neighbours closest to `centre` (§5.4.1: the normal is fitted to the
// floor(k/2) points nearest the centre of mass, which keeps it stable near outliers).
// Bucketing by squared distance finds the cut without sorting: whole buckets below the cut are
// summed branch-free, only the bucket that straddles it is sorted.
Moments moments_nearest_to(const geometry::Neighbourhood& nb, int k, const Vector3d& centre,
                           int count, Scratch& scratch) {
  constexpr int buckets = Scratch::kBuckets;
  scratch.squared_distances.resize(k);
  scratch.bucket_of.resize(k);
  float* d2 = scratch.squared_distances.data();
  const float cx = float(centre.x()), cy = float(centre.y()), cz = float(centre.z());
  // The largest squared distance as the maximum of its bit patterns (the same order for
  // non-negative floats): an integer maximum, which vectorises where a float one may not.
  std::int32_t largest_bits = 0;
  for (int j = 0; j < k; ++j) {
    const float ex = nb.dx[j] - cx, ey = nb.dy[j] - cy, ez = nb.dz[j] - cz;
    d2[j] = ex * ex + ey * ey + ez * ez;
    largest_bits = std::max(largest_bits, std::bit_cast<std::int32_t>(d2[j]));
  }
  const float largest = std::bit_cast<float>(largest_bits);
  const float to_bucket = largest > 0 ? float(buckets) / largest : 0.f;
  std::uint8_t* bucket_of = scratch.bucket_of.data();
  for (int j = 0; j < k; ++j)
    bucket_of[j] = std::uint8_t(std::min(int(d2[j] * to_bucket), buckets - 1));
  std::array<int, buckets + 1> histogram{};
  for (int j = 0; j < k; ++j) ++histogram[bucket_of[j]];
  int cut = 0, below = 0;
  while (below + histogram[cut] < count) below += histogram[cut++];

  Moments nearest = sum_moments(nb, 0, k, [&](int j) { return bucket_of[j] < cut ? 1.f : 0.f; });
  scratch.straddling.clear();
  for (int j = 0; j < k; ++j) {
    if (bucket_of[j] == cut) {
      scratch.straddling.push_back((std::uint64_t(std::bit_cast<std::uint32_t>(d2[j])) << 32) |
                                   std::uint32_t(j));
    }
  }
  std::sort(scratch.straddling.begin(), scratch.straddling.end());
  for (int r = 0; r < count - below; ++r) {
    const auto j = static_cast<std::uint32_t>(scratch.straddling[r]);
    nearest.add(nb.dx[j], nb.dy[j], nb.dz[j]);
  }
  return nearest;
}

// The largest scale's centre and normal, needed by every smaller scale for eq. (5.17).
struct LargestScale {
  int k = 0;
  Vector3d centre = Vector3d::Zero();
  Vector3d normal = Vector3d::UnitZ();
};

// Features of one scale from its k nearest neighbours (positions relative to the query point,
// which is therefore the origin) and their precomputed moments.
void scale_features(const geometry::Neighbourhood& nb, int k, const Moments& moments,
                    LargestScale& largest, Scratch& scratch, float* out) {
  std::fill(out, out + kFeaturesPerScale, 0.0f);
  const Vector3d centre = moments.mean();                                         // eq. (5.3)
  const Vector3d sigma = geometry::eigenvalues_descending(moments.covariance());  // eq. (5.2)

  const Moments core = moments_nearest_to(nb, k, centre, std::max(3, k / 2), scratch);
  Vector3d normal = geometry::smallest_eigenvector(core.covariance());
  // Orientation (our choice): the query point lies in the upper half-space, s_perp >= 0.
  if ((-centre).dot(normal) < 0) normal = -normal;

  const bool is_largest = largest.k == 0;
  if (is_largest) largest = {k, centre, normal};

  const double spread = std::sqrt(sigma[0]) + std::sqrt(sigma[1]);
  if (!(spread > 0) || !std::isfinite(spread)) return;  // all neighbours coincide
  const double scale = 2.0 / spread;                    // eq. (5.4)

  // Upper / lower split, eqs. (5.5)-(5.6): <p - centre, n> >= 0. Only the upper moments are
  // summed (branch-free weight); lower = all - upper. Moments are gathered in the query frame
  // and normalised afterwards (mean: (m - centre)·scale, covariance: ·scale²).
  const float nx = float(normal.x()), ny = float(normal.y()), nz = float(normal.z());
  const float plane = float(centre.dot(normal));
  const Moments upper = sum_moments(nb, 0, k, [&](int j) {
    return nb.dx[j] * nx + nb.dy[j] * ny + nb.dz[j] * nz >= plane ? 1.f : 0.f;
  });
  const Moments lower = moments.minus(upper);
  const double scale2 = scale * scale;
  if (upper.count() > 0) {
    const Vector3d s = geometry::eigenvalues_descending(upper.covariance()) * scale2;
    for (int i = 0; i < 3; ++i) out[i] = float(s[i]);
  }
  if (lower.count() > 0) {
    const Vector3d s = geometry::eigenvalues_descending(lower.covariance()) * scale2;
    for (int i = 0; i < 3; ++i) out[3 + i] = float(s[i]);
  }
  if (upper.count() > 0 && lower.count() > 0) {
    split_along((upper.mean() - lower.mean()) * scale, normal, out[6], out[7]);  // (5.9)-(5.10)
  }
  split_along(-centre * scale, normal, out[8], out[9]);  // eqs. (5.11)-(5.12)

  if (!is_largest && largest.k > k) {
    // Centre of the largest scale's points that are not in this scale, eqs. (5.17)-(5.18).
    const Vector3d rest = (largest.centre * largest.k - centre * k) / double(largest.k - k);
    split_along((centre - rest) * scale, largest.normal, out[10], out[11]);
  }
}

// All scales of one point. The neighbour list is ordered nearest first, so the moments of
// every scale come from one pass with prefix sums.
void point_features(const geometry::Neighbourhood& nb, const std::vector<int>& scales,
                    Scratch& scratch, float* row) {
  const int count = static_cast<int>(scales.size());
  scratch.scale_moments.resize(count);
  Moments prefix;
  int added = 0;
  for (int s = count - 1; s >= 0; --s) {
    prefix = prefix.plus(sum_moments(nb, added, scales[s], [](int) { return 1.f; }));
    added = scales[s];
    scratch.scale_moments[s] = prefix;
  }
  LargestScale largest;
  for (int s = 0; s < count; ++s) {
    scale_features(nb, scales[s], scratch.scale_moments[s], largest, scratch,
                   row + s * kFeaturesPerScale);
  }
}

}  // namespace

void check_scales(const std::vector<int>& scales) {
  if (scales.empty()) throw Error("", "scales", "at least one scale is needed");
  for (std::size_t s = 0; s < scales.size(); ++s) {
    if (scales[s] < 6) {
      throw Error("", "scales",
                  "scale " + std::to_string(scales[s]) +
                      " is too small (a neighbourhood needs at least 6 points)");
    }
    if (s > 0 && scales[s] >= scales[s - 1]) {
      throw Error("", "scales", "scales must be strictly decreasing, largest first");
    }
  }
}

FeatureMatrix compute_features(const PointCloud& cloud, const FeatureParams& params) {
  check_scales(params.scales);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!std::isfinite(cloud.x[i]) || !std::isfinite(cloud.y[i]) || !std::isfinite(cloud.z[i])) {
      throw Error("", "point " + std::to_string(i), "non-finite coordinate");
    }
    // Squared distances and covariance sums of larger coordinates overflow float: NaN
    // probabilities (a coordinate of 1e37 gave them).
    for (const float value : {cloud.x[i], cloud.y[i], cloud.z[i]}) {
      if (std::abs(value) > kMaxCloudCoordinate)
        throw Error("", "point " + std::to_string(i),
                    fmt::format("coordinate {} is more than {:g} from the cloud's origin (the "
                                "allowed range for edge features; split or rescale the cloud)",
                                value, kMaxCloudCoordinate));
    }
  }
  if (cloud.size() < static_cast<std::size_t>(params.scales[0])) {
    throw Error("", "point cloud",
                "has " + std::to_string(cloud.size()) +
                    " points; the largest scale needs at least " +
                    std::to_string(params.scales[0]));
  }

  FeatureMatrix features;
  features.points = cloud.size();
  features.scales = static_cast<int>(params.scales.size());
  features.values.resize(features.points * features.row_size());

  tbb::enumerable_thread_specific<Scratch> scratches;
  geometry::NeighbourhoodParams search;
  search.k = params.scales[0];
  ProgressBar progress("features", cloud.size());
  const geometry::NeighbourhoodStats stats = geometry::for_each_neighbourhood(
      cloud, search,
      [&](const geometry::Neighbourhood& nb) {
        point_features(nb, params.scales, scratches.local(), features.row(nb.point));
      },
      [&](std::size_t done) { progress.advance(done); });
  log().debug(
      "neighbourhoods: {} points, {} grid cells of {:.4g}, {} queries retried on a larger "
      "block, {} answered by the k-d tree",
      cloud.size(), stats.cells, stats.cell_size, stats.retried_queries, stats.fallback_queries);
  return features;
}

}  // namespace glint::edges
