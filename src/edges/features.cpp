#include "edges/features.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "core/cpu_level.h"
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

// One scale of one point: its k nearest neighbours' moments and what later steps need.
struct ScaleState {
  int k = 0;
  Moments all, upper, lower;
  Vector3d centre = Vector3d::Zero();
  Vector3d normal = Vector3d::UnitZ();
  double spread = 0;  // sqrt(σ1) + sqrt(σ2), eq. (5.4)
};

struct Scratch {
  static constexpr int kBuckets = 64;
  std::vector<float> squared_distances;
  std::vector<std::uint8_t> bucket_of;
  std::vector<std::int32_t> sector_of;
  std::vector<std::uint64_t> straddling;
  // Rows handed out in blocks (compute_features_in_blocks): the block's points and rows.
  std::vector<std::uint32_t> block_points;
  std::vector<float> block_rows;
  std::vector<float> weights;  // area weights of the current neighbourhood
  std::vector<ScaleState> states;
  std::vector<geometry::SymmetricMatrix3> matrices;
  std::vector<Vector3d> eigenvalues;
};

// The eight bytes at `bytes` as one word, the first byte lowest (one load on little-endian
// machines).
std::uint64_t bytes_at(const std::uint8_t* bytes) {
  std::uint64_t word = 0;
  for (int b = 0; b < 8; ++b) word |= std::uint64_t(bytes[b]) << (8 * b);
  return word;
}

// The top bit of each byte of `word` that equals `value`, others zero (exact: no carries cross
// bytes, unlike the shorter has-zero-byte test).
std::uint64_t bytes_equal_to(std::uint64_t word, std::uint8_t value) {
  constexpr std::uint64_t kLow7 = 0x7f7f7f7f7f7f7f7fULL;
  const std::uint64_t x = word ^ (0x0101010101010101ULL * value);
  return ~(((x & kLow7) + kLow7) | x | kLow7);
}

// Moments of the `count` neighbours closest to `centre`, each with weight weight_of(j) (§5.4.1:
// the normal is fitted to the floor(k/2) points nearest the centre of mass, which keeps it
// stable near outliers). Bucketing by squared distance finds the cut without sorting: whole
// buckets below the cut are summed branch-free, only the bucket that straddles it is sorted.
template <class WeightOf>
Moments moments_nearest_to(const geometry::Neighbourhood& nb, int k, const Vector3d& centre,
                           int count, WeightOf weight_of, Scratch& scratch) {
  constexpr int buckets = Scratch::kBuckets;
  scratch.squared_distances.resize(k);
  // Padded to whole 8-byte words with a value no bucket has (bytes_equal_to reads words).
  const std::size_t padded = std::size_t(k + 7) / 8 * 8;
  scratch.bucket_of.resize(padded);
  std::fill(scratch.bucket_of.begin() + k, scratch.bucket_of.end(), std::uint8_t(0xff));
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
  // The cut is the first bucket whose cumulative count reaches `count`, found by bisection
  // over vectorised counts (a histogram's increments form a store-to-load chain).
  const auto at_most = [&](int bucket) {
    int n = 0;
    for (int j = 0; j < k; ++j) n += bucket_of[j] <= bucket ? 1 : 0;
    return n;
  };
  int cut = 0, below = 0, last = buckets - 1;
  while (cut < last) {
    const int middle = (cut + last) / 2;
    const int n = at_most(middle);
    if (n >= count) {
      last = middle;
    } else {
      cut = middle + 1;
      below = n;
    }
  }

  Moments nearest =
      sum_moments(nb, 0, k, [&](int j) { return bucket_of[j] < cut ? weight_of(j) : 0.f; });
  // The straddling bucket's members (a few of k), found eight buckets at a time.
  scratch.straddling.clear();
  for (int word = 0; word < k; word += 8) {
    for (std::uint64_t matches = bytes_equal_to(bytes_at(bucket_of + word), std::uint8_t(cut));
         matches != 0; matches &= matches - 1) {
      const int j = word + std::countr_zero(matches) / 8;
      scratch.straddling.push_back((std::uint64_t(std::bit_cast<std::uint32_t>(d2[j])) << 32) |
                                   std::uint32_t(j));
    }
  }
  std::sort(scratch.straddling.begin(), scratch.straddling.end());
  for (int r = 0; r < count - below; ++r) {
    const auto j = static_cast<std::uint32_t>(scratch.straddling[r]);
    nearest.add_weighted(nb.dx[j], nb.dy[j], nb.dz[j], weight_of(int(j)));
  }
  return nearest;
}

// Angle of (a, b) in (-pi, pi], polynomial (error ~1e-5 rad), branch-free so it vectorises.
float fast_atan2(float b, float a) {
  const float ax = std::abs(a), ay = std::abs(b);
  const float t = std::min(ax, ay) / std::max(std::max(ax, ay), 1e-30f);
  const float s = t * t;
  float r = ((-0.0464964749f * s + 0.15931422f) * s - 0.327622764f) * s * t + t;
  r = ay > ax ? 1.57079637f - r : r;
  r = a < 0 ? 3.14159274f - r : r;
  return b < 0 ? -r : r;
}

// The angular gap (features.h): the largest empty sector of neighbours [1, k) around `normal`,
// as a fraction of the turn. Sectors rather than the sorted exact angles of the angle-gap
// baseline (edges/angle_gap_baseline.h): k up to 128 per scale on every point, so the angles
// come from a loop that vectorises and gather into one word, with no sort.
float largest_angular_gap(const geometry::Neighbourhood& nb, int k, const Vector3d& normal,
                          double spread, Scratch& scratch) {
  constexpr int kSectors = 64, kNoSector = kSectors;
  const Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  const float ux = float(u.x()), uy = float(u.y()), uz = float(u.z());
  const float vx = float(v.x()), vy = float(v.y()), vz = float(v.z());
  // A neighbour on the normal through the point (the point itself, duplicates) has no direction.
  const float tiny = float(1e-6 * spread) * float(1e-6 * spread);
  scratch.sector_of.resize(std::size_t(k));
  std::int32_t* sector_of = scratch.sector_of.data();
  const float* dx = nb.dx;
  const float* dy = nb.dy;
  const float* dz = nb.dz;
  // From j = 0: the query itself projects to 0 and counts as no sector; k stays a multiple of
  // the vector width at the default scales, so no scalar remainder runs.
  for (int j = 0; j < k; ++j) {
    const float a = dx[j] * ux + dy[j] * uy + dz[j] * uz;
    const float b = dx[j] * vx + dy[j] * vy + dz[j] * vz;
    const int sector = std::min(kSectors - 1, int((fast_atan2(b, a) + 3.14159274f) *
                                                  float(kSectors / (2 * 3.14159265358979))));
    sector_of[j] = a * a + b * b > tiny ? sector : kNoSector;
  }
  // One bit per occupied sector; kNoSector sets none.
  std::uint64_t occupied = 0;
  for (int j = 0; j < k; ++j)
    occupied |= std::uint64_t(sector_of[j] != kNoSector) << (sector_of[j] & (kSectors - 1));
  if (occupied == 0) return 1.0f;
  // Rotated so that sector 0 is occupied, no empty run wraps around.
  std::uint64_t empty = ~std::rotr(occupied, std::countr_zero(occupied));
  int longest = 0;
  for (; empty != 0; ++longest) empty &= empty << 1;
  return float(longest) / float(kSectors);
}

// The twelve features of one scale, eqs. (5.9)-(5.18); `upper_sigma` and `lower_sigma` are the
// subsets' covariance eigenvalues. Positions are relative to the query point (the origin).
void scale_features(const ScaleState& state, const ScaleState& largest, const Vector3d& upper_sigma,
                    const Vector3d& lower_sigma, float* out) {
  std::fill(out, out + kThesisFeaturesPerScale, 0.0f);
  if (!(state.spread > 0) || !std::isfinite(state.spread)) return;  // all neighbours coincide
  const double scale = 2.0 / state.spread;                          // eq. (5.4)
  // Moments were gathered in the query frame and are normalised here (mean: (m - centre)·scale,
  // covariance: ·scale²).
  const double scale2 = scale * scale;
  const bool has_upper = state.upper.count() > 0, has_lower = state.lower.count() > 0;
  for (int i = 0; i < 3; ++i) {
    if (has_upper) out[i] = float(upper_sigma[i] * scale2);  // eq. (5.13)
    if (has_lower) out[3 + i] = float(lower_sigma[i] * scale2);
  }
  const Vector3d& normal = state.normal;
  if (has_upper && has_lower) {
    split_along((state.upper.mean() - state.lower.mean()) * scale, normal, out[6],
                out[7]);  // eqs. (5.9)-(5.10)
  }
  split_along(-state.centre * scale, normal, out[8], out[9]);  // eqs. (5.11)-(5.12)

  if (largest.k > state.k) {
    // Centre of the largest scale's points that are not in this scale, eqs. (5.17)-(5.18);
    // counts are the weighted ones (k and k0 without area weights).
    const double n = state.all.count(), largest_n = largest.all.count();
    const Vector3d rest = (largest.centre * largest_n - state.centre * n) / (largest_n - n);
    split_along((state.centre - rest) * scale, largest.normal, out[10], out[11]);
  }
}

// The area weights of neighbourhood nb (features.h) from its neighbours' squared spacings,
// nb.values. The nearest neighbour is the query point or a duplicate of it: the same spacing.
const float* area_weights(const geometry::Neighbourhood& nb, Scratch& scratch) {
  scratch.weights.resize(std::size_t(nb.size));
  float* weights = scratch.weights.data();
  // A query with duplicates closer than its spacing neighbour has spacing 0: the clamp decides.
  const float query = std::max(nb.values[0], std::numeric_limits<float>::min());
  for (int j = 0; j < nb.size; ++j)
    weights[j] = std::clamp(nb.values[j] / query, 1.0f / kMaxAreaWeight, kMaxAreaWeight);
  return weights;
}

// All scales of one point. The neighbour list is ordered nearest first, so the moments of
// every scale come from one pass with prefix sums; the eigen solves of all scales run as two
// batches (vectorised across matrices). Neighbours weigh 1, or their area weight when the
// neighbourhood carries squared spacings (kAreaWeights).
template <bool kAreaWeights>
void point_features(const geometry::Neighbourhood& nb, const FeatureParams& params,
                    Scratch& scratch, float* row) {
  const float* weights = nullptr;
  if constexpr (kAreaWeights) weights = area_weights(nb, scratch);
  const auto weight = [weights](int j) {
    if constexpr (kAreaWeights) return weights[j];
    return 1.f;
  };
  const std::vector<int>& scales = params.scales;
  const int count = static_cast<int>(scales.size());
  const int per_scale = params.per_scale();
  std::vector<ScaleState>& states = scratch.states;
  std::vector<geometry::SymmetricMatrix3>& matrices = scratch.matrices;
  std::vector<Vector3d>& eigenvalues = scratch.eigenvalues;
  states.resize(count);
  matrices.resize(2 * count);
  eigenvalues.resize(2 * count);
  Moments prefix;
  int added = 0;
  for (int s = count - 1; s >= 0; --s) {
    prefix = prefix.plus(sum_moments(nb, added, scales[s], weight));
    added = scales[s];
    states[s].k = scales[s];
    states[s].all = prefix;
  }

  // Batch 1: each scale's covariance (eq. 5.2) and that of the floor(k/2) neighbours nearest
  // its centre (eq. 5.3), whose smallest eigenvector is the normal (§5.4.1).
  for (int s = 0; s < count; ++s) {
    ScaleState& state = states[s];
    state.centre = state.all.mean();
    matrices[s] = state.all.covariance();
    matrices[count + s] =
        moments_nearest_to(nb, state.k, state.centre, std::max(3, state.k / 2), weight, scratch)
            .covariance();
  }
  geometry::eigenvalues_descending(matrices.data(), 2 * count, eigenvalues.data());

  // Batch 2: the upper and lower subsets, eqs. (5.5)-(5.6): <p - centre, n> >= 0. Only the
  // upper moments are summed (branch-free weight); lower = all - upper.
  for (int s = 0; s < count; ++s) {
    ScaleState& state = states[s];
    state.spread = std::sqrt(eigenvalues[s][0]) + std::sqrt(eigenvalues[s][1]);
    Vector3d normal =
        geometry::smallest_eigenvector(matrices[count + s], eigenvalues[count + s][2]);
    // Orientation (our choice): the query point lies in the upper half-space, s_perp >= 0.
    if ((-state.centre).dot(normal) < 0) normal = -normal;
    state.normal = normal;
    const float nx = float(normal.x()), ny = float(normal.y()), nz = float(normal.z());
    const float plane = float(state.centre.dot(normal));
    state.upper = sum_moments(nb, 0, state.k, [&](int j) {
      return nb.dx[j] * nx + nb.dy[j] * ny + nb.dz[j] * nz >= plane ? weight(j) : 0.f;
    });
    state.lower = state.all.minus(state.upper);
    matrices[s] = state.upper.count() > 0 ? state.upper.covariance() : geometry::SymmetricMatrix3{};
    matrices[count + s] =
        state.lower.count() > 0 ? state.lower.covariance() : geometry::SymmetricMatrix3{};
  }
  geometry::eigenvalues_descending(matrices.data(), 2 * count, eigenvalues.data());

  for (int s = 0; s < count; ++s) {
    float* out = row + s * per_scale;
    scale_features(states[s], states[0], eigenvalues[s], eigenvalues[count + s], out);
    if (params.angular_gap)
      out[kAngularGapFeature] =
          largest_angular_gap(nb, states[s].k, states[s].normal, states[s].spread, scratch);
  }
}

using PointKernel = void (*)(const geometry::Neighbourhood&, const FeatureParams&, Scratch&,
                             float*);

void point_features_either(const geometry::Neighbourhood& nb, const FeatureParams& params,
                           Scratch& scratch, float* row) {
  if (nb.values)
    point_features<true>(nb, params, scratch, row);
  else
    point_features<false>(nb, params, scratch, row);
}

[[gnu::flatten]] void point_features_baseline(const geometry::Neighbourhood& nb,
                                              const FeatureParams& params, Scratch& scratch,
                                              float* row) {
  point_features_either(nb, params, scratch, row);
}
#if defined(__x86_64__)
// The same code in eight-lane vectors with fused multiply-adds: the moment sums round in
// another order, so features differ from the baseline's by float rounding.
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] void point_features_x86_64_v3(
    const geometry::Neighbourhood& nb, const FeatureParams& params, Scratch& scratch, float* row) {
  point_features_either(nb, params, scratch, row);
}
#endif

PointKernel point_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v3()) return point_features_x86_64_v3;
#endif
  return point_features_baseline;
}

}  // namespace

int area_spacing_neighbours(std::size_t cloud_points) {
  return static_cast<int>(
      std::min(cloud_points, static_cast<std::size_t>(kAreaSpacingNeighbour + 1)));
}

geometry::NeighbourhoodParams feature_search_params(const std::vector<int>& scales) {
  geometry::NeighbourhoodParams params;
  params.k = scales.front();
  return params;
}

float noise_statistic(const float* row, int scales, int per_scale) {
  const float* smallest = row + (scales - 1) * per_scale;
  // Rounding can leave a flat subset's smallest eigenvalue slightly negative.
  return std::sqrt(std::max(0.0f, smallest[2] + smallest[5]));
}

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

namespace {

void check_cloud(const PointCloud& cloud, const FeatureParams& params) {
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
}

// Every point's squared distance to its kAreaSpacingNeighbour-th nearest other point (or the
// farthest, in a smaller cloud): the area it stands for, up to a constant. Those a choice before
// the rows found are taken from `findings`.
std::vector<float> squared_spacings(const PointCloud& cloud,
                                    const geometry::NeighbourhoodSearch& search,
                                    const SearchFindings& findings) {
  const std::span<const std::uint8_t> spaced = findings.spaced;
  std::vector<std::uint8_t> missing;
  if (!spaced.empty()) {
    missing.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) missing[i] = spaced[i] ? 0 : 1;
    if (std::none_of(missing.begin(), missing.end(), [](std::uint8_t m) { return m != 0; }))
      return findings.spacings;
  }
  ProgressBar progress("spacings", cloud.size());
  std::vector<float> spacings = search.kth_nearest_squared_distances(
      area_spacing_neighbours(cloud.size()), [&](std::size_t done) { progress.advance(done); },
      missing);
  for (std::size_t i = 0; i < spaced.size(); ++i)
    if (spaced[i]) spacings[i] = findings.spacings[i];
  return spacings;
}

// Every point's features, written to row_for(point, scratch); row_written(scratch) follows
// on the same thread. search_ready as in compute_features_in_blocks. The cloud must have passed
// check_cloud.
template <class RowFor, class RowWritten>
void compute_rows(const PointCloud& cloud, const FeatureParams& given_params,
                  tbb::enumerable_thread_specific<Scratch>& scratches, RowFor&& row_for,
                  RowWritten&& row_written, const SearchReady& search_ready) {
  const PointKernel kernel = point_kernel();
  const geometry::NeighbourhoodSearch search(cloud, feature_search_params(given_params.scales));
  FeatureParams params = given_params;
  SearchFindings findings;
  if (search_ready) {
    params = search_ready(search, findings);
    FeatureParams same_rows = params;
    same_rows.area_weights = given_params.area_weights;
    if (same_rows != given_params)
      throw Error("", "features", "a choice before the rows may change the neighbour weights only");
  }
  // Handed out per neighbour with the positions, where the kernel weighs by them.
  const std::vector<float> spacings =
      params.area_weights ? squared_spacings(cloud, search, findings) : std::vector<float>();
  // The points whose lists the choice kept are visited from those lists, not searched again.
  const geometry::KeptNeighbourhoods& kept = findings.neighbourhoods;
  std::vector<std::uint8_t> unlisted;
  if (!kept.points.empty()) {
    unlisted.assign(cloud.size(), 1);
    for (const std::uint32_t point : kept.points) unlisted[point] = 0;
  }
  ProgressBar progress("features", cloud.size());
  const auto visit = [&](const geometry::Neighbourhood& nb) {
    Scratch& scratch = scratches.local();
    kernel(nb, params, scratch, row_for(nb.point, scratch));
    row_written(scratch);
  };
  const auto advance = [&](std::size_t done) { progress.advance(done); };
  const geometry::NeighbourhoodStats stats = search.for_each(visit, advance, spacings, unlisted);
  geometry::visit_kept(cloud, kept, visit, advance, spacings);
  log().debug(
      "neighbourhoods: {} points ({} from kept lists), {} grid cells of {:.4g}, {} queries "
      "retried on a larger block, {} answered by the k-d tree",
      cloud.size(), kept.points.size(), stats.cells, stats.cell_size, stats.retried_queries,
      stats.fallback_queries);
}

}  // namespace

FeatureMatrix compute_features(const PointCloud& cloud, const FeatureParams& params) {
  check_cloud(cloud, params);
  FeatureMatrix features;
  features.points = cloud.size();
  features.scales = static_cast<int>(params.scales.size());
  features.per_scale = params.per_scale();
  features.values.resize(features.points * features.row_size());
  tbb::enumerable_thread_specific<Scratch> scratches;
  compute_rows(
      cloud, params, scratches, [&](std::uint32_t point, Scratch&) { return features.row(point); },
      [](Scratch&) {}, {});
  return features;
}

std::vector<float> noise_statistics(const PointCloud& cloud, const FeatureParams& params,
                                    const geometry::NeighbourhoodSearch& search,
                                    std::span<const std::uint8_t> wanted,
                                    SearchFindings* findings) {
  check_cloud(cloud, params);
  if (wanted.size() != cloud.size())
    throw Error("", "noise statistic",
                fmt::format("{} wanted entries for {} points", wanted.size(), cloud.size()));
  if (search.k() != params.scales.front())
    throw Error("", "noise statistic",
                fmt::format("needs the features' search (k = {}); got k = {}",
                            params.scales.front(), search.k()));
  // The lists are nearest first, so the smallest scale's features come from their first k alone:
  // a one-scale kernel on them gives the values the full rows hold.
  FeatureParams smallest = params;
  smallest.scales = {params.scales.back()};
  const PointKernel kernel = point_kernel();
  const SearchFindings none;
  std::vector<float> spacings = params.area_weights
                                    ? squared_spacings(cloud, search, findings ? *findings : none)
                                    : std::vector<float>();
  geometry::KeptNeighbourhoods kept;
  if (findings) kept = geometry::KeptNeighbourhoods(wanted, search.k());
  std::vector<float> statistics(cloud.size(), 0.0f);
  tbb::enumerable_thread_specific<Scratch> scratches([&] {
    Scratch scratch;
    scratch.block_rows.resize(smallest.row_size());
    return scratch;
  });
  search.for_each(
      [&](const geometry::Neighbourhood& nb) {
        Scratch& scratch = scratches.local();
        kernel(nb, smallest, scratch, scratch.block_rows.data());
        statistics[nb.point] = noise_statistic(scratch.block_rows.data(), 1, smallest.per_scale());
        if (findings) kept.keep(nb);
      },
      {}, spacings, wanted);
  if (findings) {
    findings->neighbourhoods = std::move(kept);
    if (params.area_weights) {
      findings->spacings = std::move(spacings);
      findings->spaced.assign(cloud.size(), 1);
    }
  }
  return statistics;
}

void compute_features_in_blocks(const PointCloud& cloud, const FeatureParams& params,
                                std::size_t block_size, const FeatureBlockConsumer& consume,
                                const SearchReady& search_ready) {
  check_cloud(cloud, params);
  if (block_size == 0) throw Error("", "block size", "must be at least 1");
  const std::size_t row_size = params.row_size();
  tbb::enumerable_thread_specific<Scratch> scratches([&] {
    Scratch scratch;
    scratch.block_points.reserve(block_size);
    scratch.block_rows.resize(block_size * row_size);
    return scratch;
  });
  compute_rows(
      cloud, params, scratches,
      [&](std::uint32_t point, Scratch& scratch) {
        scratch.block_points.push_back(point);
        return scratch.block_rows.data() + (scratch.block_points.size() - 1) * row_size;
      },
      [&](Scratch& scratch) {
        if (scratch.block_points.size() < block_size) return;
        consume(scratch.block_points.data(), scratch.block_rows.data(), block_size);
        scratch.block_points.clear();
      },
      search_ready);
  // Each thread's last, partial block.
  for (Scratch& scratch : scratches) {
    if (scratch.block_points.empty()) continue;
    consume(scratch.block_points.data(), scratch.block_rows.data(), scratch.block_points.size());
    scratch.block_points.clear();
  }
}

}  // namespace glint::edges
