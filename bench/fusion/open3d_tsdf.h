#pragma once
// The peer: Open3D's tensor VoxelBlockGrid TSDF integration (Dong et al. 2021) on the CPU, fed
// the same frames and camera-to-world poses as glint; float tsdf/weight/colour attributes, as
// glint stores them.
#include <string>
#include <vector>

#include "core/camera.h"
#include "fusion/triangle_mesh.h"

namespace glint::bench {

struct Open3dTsdfParams {
  double voxel_size_m = 0.005;
  int block_resolution = 8;  // glint's block side
  double trunc_voxel_multiplier = 8;
  double depth_units_per_metre = 1000;
  double depth_max_m = 4.0;
  long block_count = 60000;  // initial hash capacity (the CPU hash map grows)
};

struct Open3dTsdfRun {
  std::vector<double> integrate_ms;  // per frame: GetUniqueBlockCoordinates + Integrate
  fusion::TriangleMesh mesh;         // ExtractTriangleMesh, voxels with weight >= 1
  long blocks = 0;
};

// colour_paths / depth_paths: 8-bit colour and 16-bit depth images (read outside the timing).
Open3dTsdfRun run_open3d_tsdf(const std::vector<std::string>& colour_paths,
                              const std::vector<std::string>& depth_paths,
                              const std::vector<Pose>& camera_to_world,
                              const Intrinsics& intrinsics, const Open3dTsdfParams& params);

}  // namespace glint::bench
