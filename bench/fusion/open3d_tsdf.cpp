#include "open3d_tsdf.h"

#include <open3d/Open3D.h>

#include "core/error.h"
#include "core/timer.h"

namespace glint::bench {

namespace o3c = open3d::core;
namespace o3t = open3d::t::geometry;

namespace {

o3t::Image read_open3d_image(const std::string& path) {
  o3t::Image image;
  if (!open3d::t::io::ReadImage(path, image)) throw Error(path, "", "Open3D cannot read the image");
  return image;
}

o3c::Tensor extrinsic_of(const Pose& camera_to_world) {
  const Eigen::Matrix4d world_to_camera = camera_to_world.inverse().matrix();
  std::vector<double> values(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values[r * 4 + c] = world_to_camera(r, c);
  return o3c::Tensor(values, {4, 4}, o3c::Float64);
}

fusion::TriangleMesh to_glint_mesh(const o3t::TriangleMesh& mesh) {
  fusion::TriangleMesh out;
  const o3c::Tensor vertices = mesh.GetVertexPositions().To(o3c::Float32).Contiguous();
  const o3c::Tensor triangles = mesh.GetTriangleIndices().To(o3c::Int64).Contiguous();
  const float* v = vertices.GetDataPtr<float>();
  for (long i = 0; i < vertices.GetLength(); ++i)
    out.vertices.emplace_back(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  const int64_t* t = triangles.GetDataPtr<int64_t>();
  for (long i = 0; i < triangles.GetLength(); ++i)
    out.triangles.emplace_back(int(t[3 * i]), int(t[3 * i + 1]), int(t[3 * i + 2]));
  return out;
}

}  // namespace

Open3dTsdfRun run_open3d_tsdf(const std::vector<std::string>& colour_paths,
                              const std::vector<std::string>& depth_paths,
                              const std::vector<Pose>& camera_to_world, const Intrinsics& k,
                              const Open3dTsdfParams& params) {
  std::vector<o3t::Image> colours, depths;
  for (std::size_t i = 0; i < depth_paths.size(); ++i) {
    colours.push_back(read_open3d_image(colour_paths[i]));
    depths.push_back(read_open3d_image(depth_paths[i]));
  }
  const o3c::Device cpu("CPU:0");
  o3t::VoxelBlockGrid grid({"tsdf", "weight", "color"}, {o3c::Float32, o3c::Float32, o3c::Float32},
                           {{1}, {1}, {3}}, float(params.voxel_size_m), params.block_resolution,
                           params.block_count, cpu);
  const o3c::Tensor intrinsic(std::vector<double>{k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1}, {3, 3},
                              o3c::Float64);
  const float scale = float(params.depth_units_per_metre), depth_max = float(params.depth_max_m);
  const float trunc = float(params.trunc_voxel_multiplier);
  Open3dTsdfRun run;
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const o3c::Tensor extrinsic = extrinsic_of(camera_to_world[i]);
    Stopwatch watch;
    const o3c::Tensor blocks =
        grid.GetUniqueBlockCoordinates(depths[i], intrinsic, extrinsic, scale, depth_max, trunc);
    grid.Integrate(blocks, depths[i], colours[i], intrinsic, extrinsic, scale, depth_max, trunc);
    run.integrate_ms.push_back(watch.elapsed_ms());
  }
  run.blocks = grid.GetHashMap().Size();
  run.mesh = to_glint_mesh(grid.ExtractTriangleMesh(0.5f));
  return run;
}

}  // namespace glint::bench
