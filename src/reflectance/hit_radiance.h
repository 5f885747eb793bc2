#pragma once
// What a ray that meets the reconstruction brings back from the surface it hit, under the
// diffuse assumption: the observed radiance of the observation voxel that holds the surface
// there (the gather's and the lobe rays' emitters, reflectance/light_transport.h).
#include <Eigen/Core>

#include "reflectance/observation_grid.h"

namespace glint::reflectance {

// The radiance voxel u sends every way: the colour of its observation of median luminance (its
// highlights, seen from few directions, lie above it). False where it has no observation.
bool diffuse_radiance(const ObservationGrid& grid, int u, Eigen::Vector3f& radiance);

// The observed radiance at the hit h of a ray along unit d: that of the voxel holding h; where
// that has none (h lies on a voxel face), of the voxel half a voxel back along the ray; else of
// the neighbours across the faces of h's voxel that lie within `tolerance` (the TSDF's voxel,
// the uncertainty of an interpolated crossing) of h, nearest first. A surface on a voxel face
// (a floor at y = 0) keeps its observations in the voxel on one side, and the crossing may fall
// on the other, which a grazing ray's step back does not leave. False where none has any.
bool hit_radiance(const ObservationGrid& grid, const Eigen::Vector3f& h, const Eigen::Vector3f& d,
                  float tolerance, ObservationGrid::BlockCache& blocks, Eigen::Vector3f& radiance);

}  // namespace glint::reflectance
