#include "edges/features.h"

#include <tbb/enumerable_thread_specific.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/progress.h"
#include "geometry/neighbourhoods.h"

namespace glint::edges {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Running first and second moments of a point set (six unique second moments).
struct Moments {
  double count = 0;
  double sx = 0, sy = 0, sz = 0;
  double sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;

  void add(double x, double y, double z) {
    count += 1;
    sx += x;
    sy += y;
    sz += z;
    sxx += x * x;
    sxy += x * y;
    sxz += x * z;
    syy += y * y;
    syz += y * z;
    szz += z * z;
  }
  void add_weighted(double x, double y, double z, double w) {
    count += w;
    const double wx = w * x, wy = w * y, wz = w * z;
    sx += wx;
    sy += wy;
    sz += wz;
    sxx += wx * x;
    sxy += wx * y;
    sxz += wx * z;
    syy += wy * y;
    syz += wy * z;
    szz += wz * z;
  }
  // Moments of this set without a subset of it.
  Moments minus(const Moments& subset) const {
    Moments rest;
    rest.count = count - subset.count;
    rest.sx = sx - subset.sx;
    rest.sy = sy - subset.sy;
    rest.sz = sz - subset.sz;
    rest.sxx = sxx - subset.sxx;
    rest.sxy = sxy - subset.sxy;
    rest.sxz = sxz - subset.sxz;
    rest.syy = syy - subset.syy;
    rest.syz = syz - subset.syz;
    rest.szz = szz - subset.szz;
    return rest;
  }
  Vec3 mean() const { return Vec3(sx, sy, sz) / count; }
  Mat3 covariance() const {
    const Vec3 m = mean();
    Mat3 c;
    c << sxx / count - m.x() * m.x(), sxy / count - m.x() * m.y(), sxz / count - m.x() * m.z(),
        0, syy / count - m.y() * m.y(), syz / count - m.y() * m.z(),
        0, 0, szz / count - m.z() * m.z();
    c(1, 0) = c(0, 1);
    c(2, 0) = c(0, 2);
    c(2, 1) = c(1, 2);
    return c;
  }
};

// Eigenvalues of a covariance in descending order (the singular values of eq. 5.2), clamped
// at zero against round-off.
Vec3 descending_eigenvalues(const Mat3& covariance) {
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(covariance, Eigen::EigenvaluesOnly);
  const Vec3& ascending = solver.eigenvalues();
  return {std::max(0.0, ascending[2]), std::max(0.0, ascending[1]), std::max(0.0, ascending[0])};
}

Vec3 smallest_eigenvector(const Mat3& covariance) {
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(covariance, Eigen::ComputeEigenvectors);
  return solver.eigenvectors().col(0).normalized();
}

// Perpendicular and tangential parts of v with respect to the unit normal n.
void split_along(const Vec3& v, const Vec3& n, float& perpendicular, float& tangential) {
  const double along = v.dot(n);
  perpendicular = static_cast<float>(along);
  tangential = static_cast<float>((v - along * n).norm());
}

struct Scratch {
  std::vector<std::uint64_t> ranked;
  std::vector<Moments> scale_moments;
};

// The largest scale's centre and normal, needed by every smaller scale for eq. (5.17).
struct LargestScale {
  int k = 0;
  Vec3 centre = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
};

// Features of one scale from its k nearest neighbours (positions relative to the query point,
// which is therefore the origin) and their precomputed moments.
void scale_features(const geometry::Neighbourhood& nb, int k, const Moments& moments,
                    LargestScale& largest, Scratch& scratch, float* out) {
  std::fill(out, out + kFeaturesPerScale, 0.0f);
  const float* dx = nb.dx;
  const float* dy = nb.dy;
  const float* dz = nb.dz;

  const Vec3 centre = moments.mean();                                  // eq. (5.3)
  const Vec3 sigma = descending_eigenvalues(moments.covariance());     // eq. (5.2)

  // Normal from the floor(k/2) points closest to the centre (outlier-robust, §5.4.1).
  const int half = std::max(3, k / 2);
  scratch.ranked.resize(k);
  const float cx = float(centre.x()), cy = float(centre.y()), cz = float(centre.z());
  for (int j = 0; j < k; ++j) {
    const float ex = dx[j] - cx, ey = dy[j] - cy, ez = dz[j] - cz;
    const float d2 = ex * ex + ey * ey + ez * ez;
    scratch.ranked[j] = (std::uint64_t(std::bit_cast<std::uint32_t>(d2)) << 32) | std::uint32_t(j);
  }
  std::nth_element(scratch.ranked.begin(), scratch.ranked.begin() + (half - 1),
                   scratch.ranked.end());
  Moments core;
  for (int r = 0; r < half; ++r) {
    const auto j = static_cast<std::uint32_t>(scratch.ranked[r]);
    core.add(dx[j], dy[j], dz[j]);
  }
  Vec3 normal = smallest_eigenvector(core.covariance());
  // Orientation (our choice): the query point lies in the upper half-space, s_perp >= 0.
  if ((-centre).dot(normal) < 0) normal = -normal;

  const bool is_largest = largest.k == 0;
  if (is_largest) largest = {k, centre, normal};

  const double spread = std::sqrt(sigma[0]) + std::sqrt(sigma[1]);
  if (!(spread > 0) || !std::isfinite(spread)) return;  // all neighbours coincide
  const double scale = 2.0 / spread;  // eq. (5.4)

  // Upper / lower split, eqs. (5.5)-(5.6): <p - centre, n> >= 0. Moments are gathered in the
  // query frame and normalised afterwards (mean: (m - centre)·scale, covariance: ·scale²).
  // Only the upper moments are summed (branch-free, weight 0 or 1); lower = all - upper.
  Moments upper;
  const float nx = float(normal.x()), ny = float(normal.y()), nz = float(normal.z());
  const float plane = float(centre.dot(normal));
  for (int j = 0; j < k; ++j) {
    const float height = dx[j] * nx + dy[j] * ny + dz[j] * nz;
    upper.add_weighted(dx[j], dy[j], dz[j], height >= plane ? 1.0 : 0.0);
  }
  const Moments lower = moments.minus(upper);
  const double scale2 = scale * scale;
  if (upper.count > 0) {
    const Vec3 s = descending_eigenvalues(upper.covariance()) * scale2;
    for (int i = 0; i < 3; ++i) out[i] = float(s[i]);
  }
  if (lower.count > 0) {
    const Vec3 s = descending_eigenvalues(lower.covariance()) * scale2;
    for (int i = 0; i < 3; ++i) out[3 + i] = float(s[i]);
  }
  if (upper.count > 0 && lower.count > 0) {
    split_along((upper.mean() - lower.mean()) * scale, normal, out[6], out[7]);  // (5.9)-(5.10)
  }
  split_along(-centre * scale, normal, out[8], out[9]);  // eqs. (5.11)-(5.12)

  if (!is_largest && largest.k > k) {
    // Centre of the largest scale's points that are not in this scale, eqs. (5.17)-(5.18).
    const Vec3 rest = (largest.centre * largest.k - centre * k) / double(largest.k - k);
    split_along((centre - rest) * scale, largest.normal, out[10], out[11]);
  }
}

// All scales of one point. The neighbour list is nested (the first k entries are the k
// nearest), so the moments of every scale come from one pass with prefix sums.
void point_features(const geometry::Neighbourhood& nb, const std::vector<int>& scales,
                    Scratch& scratch, float* row) {
  const int count = static_cast<int>(scales.size());
  scratch.scale_moments.resize(count);
  Moments prefix;
  int added = 0;
  for (int s = count - 1; s >= 0; --s) {
    for (; added < scales[s]; ++added) prefix.add(nb.dx[added], nb.dy[added], nb.dz[added]);
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
      throw Error("", "scales", "scale " + std::to_string(scales[s]) +
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
  }
  if (cloud.size() < static_cast<std::size_t>(params.scales[0])) {
    throw Error("", "point cloud",
                "has " + std::to_string(cloud.size()) + " points; the largest scale needs at least " +
                    std::to_string(params.scales[0]));
  }

  FeatureMatrix features;
  features.points = cloud.size();
  features.scales = static_cast<int>(params.scales.size());
  features.values.resize(features.points * features.row_size());

  tbb::enumerable_thread_specific<Scratch> scratches;
  geometry::NeighbourhoodParams search;
  search.nested_sizes = params.scales;
  ProgressBar progress("features", cloud.size());
  geometry::for_each_neighbourhood(
      cloud, search,
      [&](const geometry::Neighbourhood& nb) {
        point_features(nb, params.scales, scratches.local(), features.row(nb.point));
      },
      [&](std::size_t done) { progress.advance(done); });
  return features;
}

}  // namespace glint::edges
