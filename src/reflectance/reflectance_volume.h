#pragma once
// The TSDF volume of the reflectance pipeline's geometry, in a header of its own so that the
// fusion benchmarks time the same volume without linking the pipeline.
#include "fusion/volume_params.h"

namespace glint::reflectance {

// Depth up to 6 m (the fusion default is 4 m): the paper's synthetic scenes are seen from 4 m
// away, so their far objects lie at 5-5.5 m. The truncation band grows by 0.5 cm per metre
// of depth instead of VoxelHashing's 1 cm: at 5 m it is then +-4.5 cm instead of +-7 cm, which
// fuses less noise beside the surface; narrower leaves holes (docs/decisions.md). No colour:
// the pipeline keeps its colours in the observation grid.
inline fusion::VolumeParams reflectance_volume_params() {
  return {.truncation_per_depth = 0.005, .depth_max_m = 6.0, .colour = false};
}

}  // namespace glint::reflectance
