#pragma once
// HemiImages (paper 1 §3.6): a voxel's observations as a small image over the hemisphere
// around its normal, the input of the HemiCNN. Directions are rotated so the normal is +z,
// projected to the unit disk and scaled to pixel coordinates [0, size-1]^2; every pixel takes
// the colour of the nearest projected observation (nearest-neighbour fill).
//  - parabolic (paper 1, default): u = x / (1 + z), v = y / (1 + z) (keeps flat angles apart)
//  - orthographic (Kim et al. 2017, the unmodified HemiCNN): u = x, v = y
#include <Eigen/Core>

#include "reflectance/observation.h"

namespace glint::reflectance {

enum class HemiProjection { parabolic, orthographic };

// Hemi-image sizes glint supports (pixels per side).
inline constexpr int kMinHemiImageSize = 3, kMaxHemiImageSize = 64;

struct HemiImageParams {
  int size = 15;  // pixels per side, in [kMinHemiImageSize, kMaxHemiImageSize]
  HemiProjection projection = HemiProjection::parabolic;
};

// A right-handed orthonormal frame (t, b, n) around unit normal n, continuous except at
// n = -z (Duff et al. 2017); rows of the returned matrix map world to local coordinates.
Eigen::Matrix3f local_frame(const Eigen::Vector3f& normal);

// Disk coordinates (u, v) in [-1, 1]^2 of a local direction with z >= 0.
Eigen::Vector2f project_to_disk(const Eigen::Vector3f& local_direction, HemiProjection projection);

// Writes size*size*3 floats, channel-major (CHW) like the network's input, into `out`.
// Observations below the surface (direction . normal <= 0) are ignored; with none left the
// image is black. At most the first 256 observations are used. No allocation.
void make_hemi_image(const Observation* observations, int count, const Eigen::Vector3f& normal,
                     const HemiImageParams& params, float* out);

}  // namespace glint::reflectance
