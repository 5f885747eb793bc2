#pragma once
// Angle-gap boundary baseline: the criterion of PCL's BoundaryEstimation and Open3D's
// ComputeBoundaryPoints, on PCA normals, as a reference for BoundED's boundary class.
//
// For every point p: the normal n is the smallest-eigenvalue eigenvector of the covariance of
// its k nearest neighbours (itself included). The neighbours q within `radius` of p (p itself
// excluded) are projected onto the tangent plane of n and their angles atan2(v·(q-p), u·(q-p))
// around p are sorted; the largest gap between consecutive angles (the wrap-around included) is
// the point's score. p is boundary when that gap exceeds `angle_threshold` (default π/2, the
// default of both libraries): on a closed surface neighbours surround the point, at a border
// they cover only a half-plane and leave a gap of about π.
//
// Radius (our choice where the libraries leave it to the user): `radius_spacings` times the
// local point spacing, the side of the square each point covers on a surface,
// spacing = r_k·sqrt(π/k) with r_k the distance to the k-th neighbour (k points fill a disc of
// radius r_k). With the defaults (k = 16, 1.5 spacings) the radius is 0.66·r_k and holds about
// 7 neighbours; since it stays below r_k, the k nearest already contain every neighbour inside
// it and one kNN query serves the normal, the spacing and the radius search. A fixed `radius`
// (cloud units) replaces the adaptive one; neighbours beyond the k nearest are then not seen,
// as with Open3D's max_nn.
#include <cstdint>
#include <numbers>
#include <vector>

#include "core/point_cloud.h"

namespace glint::edges {

struct AngleGapParams {
  int k = 16;                    // neighbours for the PCA normal and the spacing (at least 3)
  double radius_spacings = 1.5;  // search radius in local point spacings (used when radius = 0)
  double radius = 0.0;           // fixed search radius in cloud units; 0 = adaptive
  double angle_threshold = std::numbers::pi / 2;  // radians, in (0, 2π)
};

// Largest angular gap of every point, radians in [0, 2π]; 2π for a point with exactly one
// neighbour inside the radius, 0 for a point with none (as PCL, such a point is not boundary).
// Throws glint::Error for invalid parameters or a cloud with fewer than k points. Parallel (TBB).
std::vector<float> largest_angle_gap(const PointCloud& cloud, const AngleGapParams& params = {});

// Labels: 2 (boundary) where the largest gap exceeds angle_threshold, else 0.
std::vector<std::uint8_t> classify_angle_gap(const PointCloud& cloud,
                                             const AngleGapParams& params = {});

}  // namespace glint::edges
