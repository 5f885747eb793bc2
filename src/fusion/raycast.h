#pragma once
// Ray casting of the TSDF's zero crossing for one camera view (VoxelHashing §5; KinectFusion
// §3.4): the model view that tracking aligns the next frame to, and a rendering of the model.
// Rays march through the depth interval that allocated blocks cover in their 4x4-pixel tile
// (within depth_min_m..depth_max_m of the volume parameters), as fusion/ray_march.h steps:
// across unallocated space to the end of the region known to be empty, strides through
// unobserved voxels, 0.8 * |sdf| (at least one voxel) through observed ones, reading trilinear
// values within 2 voxels of the surface; the first + to - crossing is located by linear
// interpolation between the two samples around it.
// Back faces (- first) end the ray without a hit. With a depth hint (below), a ray first marches
// from just in front of the hinted depth.
#include "core/camera.h"
#include "core/image.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

struct SurfaceView {
  ImageF depth_m;   // 1 channel, z along the optical axis, 0 = no hit
  ImageF points_m;  // 3 channels, world coordinates, NaN = no hit
  ImageF normals;   // 3 channels, world, unit, towards the camera; NaN = none
  ImageF colour;    // 3 channels, linear RGB of the nearest voxel, 0 = no hit; empty unless asked
};

// Where a view's normals come from. from_points: the cross product of the neighbouring pixels'
// points (cheap; what tracking uses). from_gradient: the same, except beside a depth edge, where
// the neighbours lie on another surface (a silhouette against the background) and their cross
// product is no normal of either: there the TSDF's gradient at the hit (renderings use this).
enum class RaycastNormals { from_points, from_gradient };

// How a view is cast; the defaults cast every pixel from its tile's start, with the points'
// normals and no colour.
struct RaycastOptions {
  RaycastNormals normals = RaycastNormals::from_points;
  // The depth image (same size; 0 = none) of the frame just fused from this very pose: a ray
  // whose pixel has depth d marches from two voxels in front of d first; where that start lies
  // behind a surface (depth noise), from d - truncation_at(d) (the band's front edge, free space
  // in front of the surface the frame fused); and from its tile's start only where neither finds
  // a surface. A surface in front of the band's edge which the frame saw through (a stale one) is
  // then not found.
  const ImageF* depth_hint = nullptr;
  // With a depth hint, cast only the pixels it has depth for (the tracking model): the rest,
  // where the sensor saw nothing, mostly see nothing in the next frame either, and they march
  // from their tiles' starts, mostly to miss.
  bool hinted_pixels_only = false;
  // Read the colour of the voxel at each hit (of a volume that keeps colour): a tenth of a
  // tracking ray cast's time, which no tracking needs.
  bool colour = false;
};

// Throws glint::Error when the depth hint's size differs from the view's.
SurfaceView raycast(const TsdfVolume& volume, const Intrinsics& intrinsics,
                    const Pose& camera_to_world, const RaycastOptions& options = {});

}  // namespace glint::fusion
