// glint fusion vs Open3D's tensor VoxelBlockGrid on the CPU, on the same frames and
// ground-truth poses, and glint's per-stage speed with tracking:
//  - per voxel size: per-frame integration ms (median, mean, p90) of both, their ratio, the
//    median point-to-surface distance between the two meshes both ways (metres and voxels);
//  - glint with ICP tracking: per-frame track / raycast / integrate ms, ATE against the ground
//    truth; peak resident memory (getrusage ru_maxrss) after each phase.
// Both use truncation 8 voxels (Open3D's default), weight >= 1 for the mesh, depth <= depth_max.
//
//   fusion_bench --data SEQ [--voxels 0.005,0.01] [--frames N] [--samples 200000]
//                [--meshes DIR] [--json OUT.json]

#include <CLI/CLI.hpp>
#include <iostream>
#include <thread>

#include "core/error.h"
#include "core/timer.h"
#include "fusion/fusion_pipeline.h"
#include "fusion/marching_cubes.h"
#include "fusion/trajectory_error.h"
#include "io/json_report.h"
#include "io/rgbd_sequence.h"
#include "mesh_distance.h"
#include "open3d_tsdf.h"
#include "support/machine.h"

namespace {

using namespace glint;

nlohmann::json summary_of(const std::vector<double>& ms) {
  StageTimings timings;
  for (double value : ms) timings.add("stage", value);
  return timings.to_json()["stage"];
}

nlohmann::json distances_json(const bench::DistanceSummary& d, double voxel) {
  return {{"median_m", d.median_m},
          {"median_voxels", d.median_m / voxel},
          {"mean_m", d.mean_m},
          {"p90_m", d.p90_m},
          {"samples", d.samples}};
}

// glint with the given parameters over all frames; returns the pipeline's report entries.
nlohmann::json run_glint(const std::vector<io::RgbdFrame>& frames, const Intrinsics& intrinsics,
                         const fusion::FusionParams& params, fusion::TriangleMesh* mesh) {
  fusion::FusionPipeline pipeline(intrinsics, params);
  std::vector<Pose> estimated, truth;
  int lost = 0;
  for (const io::RgbdFrame& frame : frames) {
    const fusion::FrameResult result = pipeline.process(frame);
    lost += result.integrated ? 0 : 1;
    estimated.push_back(result.camera_to_world);
    truth.push_back(*frame.ground_truth);
  }
  nlohmann::json out{{"timings_ms", pipeline.timings().to_json()},
                     {"blocks", pipeline.volume().block_count()},
                     {"peak_rss_mb", bench::peak_rss_mib()}};
  if (!params.use_ground_truth_poses) {
    const fusion::TrajectoryError ate = fusion::absolute_trajectory_error(estimated, truth);
    out["ate"] = {{"rmse_m", ate.rmse_m}, {"median_m", ate.median_m}, {"max_m", ate.max_m}};
    out["tracking_lost_frames"] = lost;
  }
  if (mesh) *mesh = fusion::extract_mesh(pipeline.volume());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"glint fusion vs Open3D VoxelBlockGrid (CPU); writes JSON"};
  std::string data, json_path, mesh_dir;
  std::vector<double> voxels{0.005, 0.01};
  std::size_t frame_limit = 0, samples = 200000;
  double depth_max_m = 4.0;
  app.add_option("--data", data, "RGB-D sequence with ground-truth poses")->required();
  app.add_option("--voxels", voxels, "Voxel sizes, metres")->delimiter(',');
  app.add_option("--frames", frame_limit, "First N frames (0 = all)");
  app.add_option("--samples", samples, "Surface samples per mesh-distance direction");
  app.add_option("--depth-max", depth_max_m, "Depth cut-off, metres");
  app.add_option("--meshes", mesh_dir, "Also write both meshes here");
  app.add_option("--json", json_path, "Output (default stdout)");
  CLI11_PARSE(app, argc, argv);

  try {
    const io::RgbdSequence sequence = io::open_rgbd_sequence(data);
    const std::size_t count =
        frame_limit ? std::min(frame_limit, sequence.frames.size()) : sequence.frames.size();
    std::vector<io::RgbdFrame> frames;
    std::vector<std::string> colour_paths, depth_paths;
    std::vector<Pose> poses;
    for (std::size_t i = 0; i < count; ++i) {
      frames.push_back(io::read_rgbd_frame(sequence, i));
      if (!frames.back().ground_truth)
        throw glint::Error(data, "frame " + std::to_string(i), "no ground-truth pose");
      poses.push_back(*frames.back().ground_truth);
      colour_paths.push_back(sequence.frames[i].colour_path);
      depth_paths.push_back(sequence.frames[i].depth_path);
    }
    nlohmann::json report{
        {"machine",
         {{"cpu", bench::cpu_model()}, {"threads", std::thread::hardware_concurrency()}}},
        {"data", data},
        {"format", sequence.format},
        {"frames", count},
        {"size", {sequence.intrinsics.width, sequence.intrinsics.height}},
        {"depth_max_m", depth_max_m},
        {"runs", nlohmann::json::array()}};
    for (double voxel : voxels) {
      std::cerr << "voxel " << voxel << " m: glint (ground-truth poses)\n";
      fusion::FusionParams params;
      params.volume.voxel_size_m = voxel;
      params.volume.truncation_m = 8 * voxel;  // Open3D's trunc_voxel_multiplier
      params.volume.truncation_per_depth = 0;
      params.volume.depth_max_m = depth_max_m;
      params.use_ground_truth_poses = true;
      fusion::TriangleMesh glint_mesh;
      nlohmann::json glint_gt = run_glint(frames, sequence.intrinsics, params, &glint_mesh);

      std::cerr << "voxel " << voxel << " m: Open3D VoxelBlockGrid\n";
      bench::Open3dTsdfParams open3d_params;
      open3d_params.voxel_size_m = voxel;
      open3d_params.depth_units_per_metre = sequence.depth_units_per_metre;
      open3d_params.depth_max_m = depth_max_m;
      const bench::Open3dTsdfRun open3d = bench::run_open3d_tsdf(
          colour_paths, depth_paths, poses, sequence.intrinsics, open3d_params);
      const double open3d_peak = bench::peak_rss_mib();

      std::cerr << "voxel " << voxel << " m: mesh distances\n";
      const auto glint_to_open3d = bench::surface_distance(glint_mesh, open3d.mesh, samples);
      const auto open3d_to_glint = bench::surface_distance(open3d.mesh, glint_mesh, samples);
      if (!mesh_dir.empty()) {
        const std::string suffix = std::to_string(int(voxel * 1000 + 0.5)) + "mm.ply";
        fusion::write_mesh_ply(mesh_dir + "/glint_" + suffix, glint_mesh);
        fusion::write_mesh_ply(mesh_dir + "/open3d_" + suffix, open3d.mesh);
      }

      std::cerr << "voxel " << voxel << " m: glint with tracking\n";
      params.use_ground_truth_poses = false;
      params.volume = fusion::VolumeParams{};
      params.volume.voxel_size_m = voxel;
      params.volume.depth_max_m = depth_max_m;
      const nlohmann::json glint_tracked = run_glint(frames, sequence.intrinsics, params, nullptr);

      const double glint_median = glint_gt["timings_ms"]["integrate"]["median"];
      const nlohmann::json open3d_summary = summary_of(open3d.integrate_ms);
      report["runs"].push_back({{"voxel_size_m", voxel},
                                {"glint_ground_truth_poses", glint_gt},
                                {"open3d",
                                 {{"integrate_ms", open3d_summary},
                                  {"blocks", open3d.blocks},
                                  {"peak_rss_mb", open3d_peak}}},
                                {"integrate_ms_ratio_glint_to_open3d",
                                 glint_median / open3d_summary["median"].get<double>()},
                                {"mesh",
                                 {{"glint_triangles", glint_mesh.triangles.size()},
                                  {"open3d_triangles", open3d.mesh.triangles.size()},
                                  {"glint_to_open3d", distances_json(glint_to_open3d, voxel)},
                                  {"open3d_to_glint", distances_json(open3d_to_glint, voxel)}}},
                                {"glint_tracking", glint_tracked}});
    }
    report["peak_rss_mb"] = bench::peak_rss_mib();
    if (json_path.empty()) {
      std::cout << report.dump(2) << "\n";
    } else {
      io::write_json(json_path, report);
    }
  } catch (const std::exception& e) {
    std::cerr << "fusion_bench: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
