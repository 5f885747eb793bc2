#include "fusion/volume_params.h"

#include <cmath>

#include "core/error.h"

namespace glint::fusion {

void validate(const VolumeParams& params) {
  const auto fail = [](const char* name, const char* reason) {
    throw Error("volume parameters", name, reason);
  };
  if (!(params.voxel_size_m > 0)) fail("voxel_size_m", "must be positive");
  if (!(params.truncation_m > 0) || params.truncation_per_depth < 0)
    fail("truncation_m", "must be positive (and truncation_per_depth non-negative)");
  // Weights are whole counts kept in a byte (TsdfVolume::weight).
  if (!(params.max_weight >= 1 && params.max_weight <= 255) ||
      params.max_weight != std::floor(params.max_weight))
    fail("max_weight", "must be a whole number in [1, 255]");
  if (params.allocation_stride_px < 1) fail("allocation_stride_px", "must be at least 1");
  if (params.block_capacity == 0 || params.block_capacity > (std::size_t{1} << 30))
    fail("block_capacity", "must be in [1, 2^30]");
  if (!(params.depth_min_m >= 0) || !(params.depth_max_m > params.depth_min_m))
    fail("depth_max_m", "needs 0 <= depth_min_m < depth_max_m");
  if (params.far_fusion_every < 1 || params.far_fusion_every > 16)
    fail("far_fusion_every", "must be in [1, 16]");
  if (!(params.far_voxel_pixels > 0)) fail("far_voxel_pixels", "must be positive");
}

}  // namespace glint::fusion
