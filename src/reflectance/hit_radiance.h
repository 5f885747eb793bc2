#pragma once
// The observation voxel that holds the surface at a point of the reconstruction (a ray's hit,
// a re-rendered pixel's surface point), and what a ray that meets it brings back under the
// diffuse assumption: its observed radiance (the gather's and the lobe rays' emitters,
// reflectance/light_transport.h).
#include <Eigen/Core>

#include "reflectance/observation_grid.h"

namespace glint::reflectance {

// The voxel holding the surface at p: p's voxel where it has observations, else the neighbours
// across the faces of p's voxel that lie within `tolerance` (the TSDF's voxel) of p and have
// some, nearest first (a surface on a voxel face keeps its observations on one side, and a
// point interpolated on it may fall on the other); -1 where none has any.
int observed_voxel(const ObservationGrid& grid, const Eigen::Vector3f& p, float tolerance,
                   ObservationGrid::BlockCache& blocks);

// The observed radiance at the hit h of a ray along unit d: that of the voxel holding h; where
// that has none (h lies on a voxel face), of the voxel half a voxel back along the ray; else of
// observed_voxel() at h (the crossing, interpolated within a TSDF voxel, may fall past a face
// that a grazing ray's step back does not cross again). False where none has any.
bool hit_radiance(const ObservationGrid& grid, const Eigen::Vector3f& h, const Eigen::Vector3f& d,
                  float tolerance, ObservationGrid::BlockCache& blocks, Eigen::Vector3f& radiance);

}  // namespace glint::reflectance
