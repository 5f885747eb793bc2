#pragma once
// Per-pixel maps derived from depth images, for tracking (KinectFusion, Newcombe et al. 2011
// §3.2): edge-preserving smoothing, a coarse-to-fine pyramid, vertex and normal maps.
// Depth maps: one channel, metres, 0 = no measurement. Point and normal maps: three channels
// (x, y, z planes); pixels without a point or normal hold NaN.
#include "core/camera.h"
#include "core/image.h"

namespace glint::fusion {

struct BilateralParams {
  int radius_px = 2;
  double sigma_space_px = 2.0;
  double sigma_depth_m = 0.03;
};

// Bilateral filter of a depth map; neighbours without depth are left out, pixels without depth
// stay without.
ImageF bilateral_filter_depth(const ImageF& depth_m, const BilateralParams& params = {});

// Half-resolution depth: the mean of the valid 2x2 neighbours within 3 sigma_depth_m of the
// block's first valid depth (KinectFusion's block average that does not smooth across edges).
ImageF downsample_depth(const ImageF& depth_m, double sigma_depth_m);

// depth_m downsampled `halvings` times (downsample_depth()): depth_m itself for 0, else the
// result, kept in `storage`.
const ImageF& halved_depth(const ImageF& depth_m, int halvings, double sigma_depth_m,
                           ImageF& storage);

// The camera of an image of `intrinsics`' size halved `halvings` times as downsample_depth()
// halves it: scaled by 1/2 each time, an odd last row / column dropped.
Intrinsics halved_intrinsics(const Intrinsics& intrinsics, int halvings);

// Camera-space points of a depth map.
ImageF points_from_depth(const ImageF& depth_m, const Intrinsics& intrinsics);

// Unit normals from central differences of a point map, oriented towards `viewpoint` (the
// camera centre, in the points' frame); NaN where a neighbour is missing.
ImageF normals_from_points(const ImageF& points, const Eigen::Vector3d& viewpoint);

// Edge-aware smoothing of a normal map: each normal becomes the normalised mean of the normals
// of the pixels whose points lie within radius_m of its own point and whose normals are within
// 60 degrees of its own (the same face of an edge). The window spans radius_m at the pixel's
// depth (at most 8 pixels each way). Pixels without a normal stay without.
ImageF smooth_normals(const ImageF& points, const ImageF& normals, const ImageF& depth_m,
                      const Intrinsics& intrinsics, float radius_m);

}  // namespace glint::fusion
