#pragma once
// BoundED multi-scale neighbourhood features (thesis §5.4.1–5.4.2, eqs. 5.1–5.21).
//
// For every point and every scale k (default 128, 64, 32, 16) twelve values are computed from
// its k nearest neighbours (the point itself included), in this order:
//   0-2  sigma_upper(1..3)  singular values of the covariance of the upper subset  eq. (5.13)
//   3-5  sigma_lower(1..3)  same for the lower subset                               eq. (5.13)
//   6    d_perp             centre-of-mass distance upper-lower along the normal    eq. (5.9)
//   7    d_parallel         ... and in the tangent plane                            eq. (5.10)
//   8    s_perp             point minus neighbourhood centre along the normal       eq. (5.11)
//   9    s_parallel         ... and in the tangent plane                            eq. (5.12)
//   10   c_perp             centre of this scale minus centre of the largest scale's
//                           remaining points, along the largest scale's normal      eq. (5.17)
//   11   c_parallel         ... and in that tangent plane                           eq. (5.18)
// and, with FeatureParams::angular_gap (our addition, not the thesis's), a thirteenth:
//   12   angular_gap        the largest empty sector of the other neighbours around the normal
//                           n, in 64 sectors, as a fraction of the turn: PCL's and Open3D's
//                           boundary rule (a gap above a quarter turn) as a graded value
// All lengths are in the normalised frame of eq. (5.4) of the scale they belong to, so the
// features do not depend on the cloud's unit or density.
//
// With FeatureParams::area_weights (our addition) every sum over neighbours weighs neighbour j
// by the surface it stands for, relative to the query's: w_j = (r_j / r_q)^2 clamped to
// [1/16, 16], r = distance to the 8th nearest other point. The sums then approximate integrals
// over the surface rather than over the samples, so a sparse face beside a densely tessellated
// one (mesh vertices of a CAD part) weighs by its area, not by its vertex count.
//
// Our decisions where the thesis is silent: the normal n (eigenvector of the smallest
// eigenvalue of the floor(k/2) neighbours closest to the centre, as in the thesis) is oriented
// so that s_perp >= 0, i.e. the query point lies in the upper half-space. This makes convex
// and concave creases look alike and removes the sign ambiguity of the eigenvector.
// An empty subset contributes zeros.
#include <compare>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/point_cloud.h"
#include "geometry/neighbourhoods.h"

namespace glint::edges {

inline constexpr int kThesisFeaturesPerScale = 12;
inline constexpr int kAngularGapFeature = 12;
// Area weights: r is the distance to this nearest other point; weights are clamped to
// [1/kMaxAreaWeight, kMaxAreaWeight] so that an outlier's wide spacing cannot outweigh its
// neighbourhood.
inline constexpr int kAreaSpacingNeighbour = 8;
inline constexpr float kMaxAreaWeight = 16.0f;

// Values per scale: the thesis's twelve, or thirteen with the angular gap.
inline int features_per_scale(bool angular_gap) {
  return kThesisFeaturesPerScale + (angular_gap ? 1 : 0);
}

struct FeatureParams {
  // Neighbourhood sizes, largest first (the largest one is the k0 of eq. 5.17).
  std::vector<int> scales{128, 64, 32, 16};
  bool angular_gap = false;   // the thirteenth value per scale
  bool area_weights = false;  // neighbours weighed by the surface they stand for
  int per_scale() const { return features_per_scale(angular_gap); }
  std::size_t row_size() const { return scales.size() * std::size_t(per_scale()); }
  // Equal params give equal features (models may share one feature matrix).
  auto operator<=>(const FeatureParams&) const = default;
};

// Row-major features: value(point, scale, feature) at
// ((point * scales + scale) * per_scale + feature).
struct FeatureMatrix {
  std::size_t points = 0;
  int scales = 0;
  int per_scale = kThesisFeaturesPerScale;
  std::vector<float> values;

  std::size_t row_size() const { return static_cast<std::size_t>(scales) * per_scale; }
  const float* row(std::size_t point) const { return values.data() + point * row_size(); }
  float* row(std::size_t point) { return values.data() + point * row_size(); }
  float at(std::size_t point, int scale, int feature) const {
    return row(point)[scale * per_scale + feature];
  }
};

// Computes the features of every point. Throws glint::Error when the cloud has fewer points
// than the largest scale, a non-finite coordinate, or the scales are not strictly decreasing.
// Runs in parallel (TBB) and shows a progress bar on a terminal.
FeatureMatrix compute_features(const PointCloud& cloud, const FeatureParams& params = {});

// What a choice made on the features' search before the rows found there, so that the rows do
// not search for it again: neighbour lists of the largest scale, and area-weight spacings.
struct SearchFindings {
  geometry::KeptNeighbourhoods neighbourhoods;
  // Squared spacings (as area_spacing_neighbours gives them) of the points `spaced` marks, one
  // entry per point; both empty when none were found.
  std::vector<float> spacings;
  std::vector<std::uint8_t> spaced;
};

// The same features handed over in blocks as they are computed, never all stored (a 1M-point
// cloud's rows are 192 MB): consume(points, rows, count) gets up to block_size point indices
// and their rows (row-major, scales·per_scale floats each), from several threads at once; every
// point comes in exactly one block. Same checks and errors as compute_features.
// search_ready(search, findings), when given, is called once before the first row with the
// cloud's neighbour search (its k is the largest scale): a choice that depends on the whole
// cloud, such as a gate's, is made there, before any row is handed to `consume`, and what it
// finds on the search may be left in `findings` for the rows. It returns the params of the rows:
// `params` with other neighbour weights at most (glint::Error otherwise).
using FeatureBlockConsumer =
    std::function<void(const std::uint32_t* points, const float* rows, std::size_t count)>;
using SearchReady = std::function<FeatureParams(const geometry::NeighbourhoodSearch& search,
                                                SearchFindings& findings)>;
void compute_features_in_blocks(const PointCloud& cloud, const FeatureParams& params,
                                std::size_t block_size, const FeatureBlockConsumer& consume,
                                const SearchReady& search_ready = {});

// The k whose k-th nearest point (itself first) gives a point's area-weight spacing in a cloud
// of this many points: the kAreaSpacingNeighbour-th nearest other point, or the farthest.
int area_spacing_neighbours(std::size_t cloud_points);

// The neighbour search the features build: exact neighbourhoods of the largest scale.
geometry::NeighbourhoodParams feature_search_params(const std::vector<int>& scales);

// The noise statistic of one point, from its feature row (`scales` scales of `per_scale`
// values each): at the smallest scale, sqrt(sigma_upper(3) + sigma_lower(3)), the spread of
// the two half-neighbourhoods off their own planes in the eq. (5.4) frame. Near 0 on clean surfaces
// away from edges; it grows with displacement noise relative to the point spacing. The noise gate
// of edges/model.h counts the points where it is below a threshold.
float noise_statistic(const float* row, int scales, int per_scale);

// noise_statistic of the points `wanted` marks (one entry per point; 0 elsewhere), as their
// feature rows at `params` give it, from the smallest scale of their lists on `search`, the
// features' search (its k the largest scale). With `findings`, the lists (and, with area
// weights, every point's spacings) are left there for the rows, so that a gate's sample is not
// searched twice. Checks and errors as compute_features; glint::Error for a search of another k.
std::vector<float> noise_statistics(const PointCloud& cloud, const FeatureParams& params,
                                    const geometry::NeighbourhoodSearch& search,
                                    std::span<const std::uint8_t> wanted,
                                    SearchFindings* findings = nullptr);

// Validates scales (>= 6, strictly decreasing); throws glint::Error naming the problem.
void check_scales(const std::vector<int>& scales);

}  // namespace glint::edges
