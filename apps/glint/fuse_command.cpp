// glint fuse: real-time RGB-D reconstruction into a voxel-hashed TSDF (thesis §2.1; paper 1
// §3.3): tracking (or ground-truth poses), integration, marching-cubes mesh, trajectory, report.
#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "cli_support.h"
#include "commands.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"
#include "fusion/fusion_pipeline.h"
#include "fusion/marching_cubes.h"
#include "fusion/trajectory_error.h"
#include "io/json_report.h"
#include "io/ply.h"
#include "io/rgbd_sequence.h"
#include "io/trajectory.h"
#include "volume_options.h"

namespace glint::app {
namespace {

struct FuseOptions {
  std::string dataset;
  std::string mesh;
  std::string points;
  std::string report;
  std::string trajectory;
  std::size_t frames = 0;
  fusion::FusionParams params;
};

PointCloud mesh_vertices_as_points(const fusion::TriangleMesh& mesh) {
  PointCloud cloud;
  cloud.reserve(mesh.vertices.size());
  std::vector<std::uint8_t> red, green, blue;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    cloud.push_back(mesh.vertices[i].x(), mesh.vertices[i].y(), mesh.vertices[i].z());
    red.push_back(fusion::linear_to_srgb8(mesh.colours[i].x()));
    green.push_back(fusion::linear_to_srgb8(mesh.colours[i].y()));
    blue.push_back(fusion::linear_to_srgb8(mesh.colours[i].z()));
  }
  cloud.set("red", std::move(red));
  cloud.set("green", std::move(green));
  cloud.set("blue", std::move(blue));
  return cloud;
}

nlohmann::json trajectory_error_json(const fusion::TrajectoryError& error) {
  return {{"rmse_m", error.rmse_m},
          {"mean_m", error.mean_m},
          {"median_m", error.median_m},
          {"max_m", error.max_m},
          {"poses", error.poses}};
}

void run_fuse(const FuseOptions& options) {
  Stopwatch total;
  const io::RgbdSequence sequence = io::open_rgbd_sequence(options.dataset);
  const std::size_t frames =
      options.frames ? std::min(options.frames, sequence.frames.size()) : sequence.frames.size();
  if (options.params.use_ground_truth_poses)
    sequence.require_ground_truth(frames, "--gt-poses needs every frame's (drop it to track)");
  fusion::FusionPipeline pipeline(sequence.intrinsics, options.params);
  StageTimings command_timings;  // "read" per frame, "mesh" once
  std::vector<io::StampedPose> trajectory;
  std::vector<Pose> tracked_with_truth, truth;
  int lost = 0;
  {
    ProgressBar progress("fuse", frames);
    for (std::size_t i = 0; i < frames; ++i) {
      Stopwatch read_watch;
      const io::RgbdFrame frame = io::read_rgbd_frame(sequence, i);
      command_timings.add("read", read_watch.elapsed_ms());
      const fusion::FrameResult result = pipeline.process(frame);
      if (!result.integrated) ++lost;
      trajectory.push_back({frame.timestamp_s, result.camera_to_world});
      if (frame.ground_truth) {
        tracked_with_truth.push_back(result.camera_to_world);
        truth.push_back(*frame.ground_truth);
      }
      progress.advance();
    }
    progress.finish();
  }
  Stopwatch mesh_watch;
  fusion::TriangleMesh mesh = fusion::extract_mesh(pipeline.volume());
  command_timings.add("mesh", mesh_watch.elapsed_ms());
  mesh.comments = {"glint fuse; red green blue: fused colour, 8-bit sRGB"};
  fusion::write_mesh_ply(options.mesh, mesh);
  if (!options.points.empty()) io::write_ply(options.points, mesh_vertices_as_points(mesh));
  if (!options.trajectory.empty()) io::write_tum_trajectory(options.trajectory, trajectory);

  nlohmann::json timings = pipeline.timings().to_json();
  timings.update(command_timings.to_json());
  nlohmann::json ate = nullptr;
  const bool tracked = !options.params.use_ground_truth_poses;
  if (tracked && truth.size() >= 3)
    ate = trajectory_error_json(fusion::absolute_trajectory_error(tracked_with_truth, truth));

  const auto& volume = options.params.volume;
  log().info(
      "{} ({}, {} frames{}): {} blocks, mesh {} vertices / {} triangles -> {}; integrate "
      "{:.1f} ms/frame on the {}{}",
      options.dataset, sequence.format, frames, tracked ? "" : ", ground-truth poses",
      pipeline.volume().block_count(), mesh.vertices.size(), mesh.triangles.size(), options.mesh,
      pipeline.timings().median_ms("integrate"), pipeline.integration_device(),
      ate.is_null() ? std::string()
                    : fmt::format(", ATE RMSE {:.4f} m", ate["rmse_m"].get<double>()));
  if (!options.report.empty())
    io::write_json(options.report,
                   {{"command", command_line()},
                    {"input", options.dataset},
                    {"format", sequence.format},
                    {"frames", frames},
                    {"intrinsics",
                     {{"width", sequence.intrinsics.width},
                      {"height", sequence.intrinsics.height},
                      {"fx", sequence.intrinsics.fx},
                      {"fy", sequence.intrinsics.fy},
                      {"cx", sequence.intrinsics.cx},
                      {"cy", sequence.intrinsics.cy}}},
                    {"parameters",
                     {{"voxel_size_m", volume.voxel_size_m},
                      {"truncation_m", volume.truncation_m},
                      {"truncation_per_depth", volume.truncation_per_depth},
                      {"depth_max_m", volume.depth_max_m},
                      {"block_capacity", volume.block_capacity},
                      {"ground_truth_poses", !tracked},
                      {"track_model_halvings", options.params.tracking.model_halvings},
                      {"integration_device", pipeline.integration_device()}}},
                    {"blocks", pipeline.volume().block_count()},
                    {"mesh",
                     {{"vertices", mesh.vertices.size()},
                      {"triangles", mesh.triangles.size()},
                      {"path", options.mesh}}},
                    {"tracking_lost_frames", lost},
                    {"ate", ate},
                    {"timings_ms", timings},
                    {"total_s", total.elapsed_s()}});
}

}  // namespace

void add_volume_options(CLI::App* command, fusion::VolumeParams& volume) {
  command->add_option("--voxel", volume.voxel_size_m, "Voxel size, metres")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--trunc", volume.truncation_m,
                   "Truncation band half-width at depth 0, metres (grows by --trunc-per-depth per "
                   "metre of depth)")
      ->check(kPositive)
      ->capture_default_str();
  command->add_option("--trunc-per-depth", volume.truncation_per_depth, "Band growth per metre")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_option("--depth-max", volume.depth_max_m, "Ignore depth beyond this, metres")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--blocks", volume.block_capacity,
                   "Block pool capacity (2.5 KiB per block, 8.5 KiB where the volume keeps colour; "
                   "committed as used)")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--far-every", volume.far_fusion_every,
                   "Fuse far-field blocks (a voxel under --far-voxel-pixels pixels wide) only "
                   "every N-th frame, staggered; 1 fuses every block every frame")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  command
      ->add_option("--far-voxel-pixels", volume.far_voxel_pixels,
                   "Far field: where a voxel projects to fewer pixels than this (depth beyond "
                   "voxel x fx / this)")
      ->check(kPositive)
      ->capture_default_str();
}

void add_tracking_options(CLI::App* command, fusion::TrackingParams& tracking) {
  command
      ->add_option("--track-model-halvings", tracking.model_halvings,
                   "Tracking: ray cast the model it aligns each frame to at the frame's resolution "
                   "halved this many times (the ray cast is most of a tracked frame's time)")
      ->check(CLI::Range(0, 2))
      ->capture_default_str();
}

void add_integration_device_option(CLI::App* command, fusion::IntegrationDevice& device) {
  device = fusion::IntegrationDevice::automatic;
  command
      ->add_option_function<std::string>(
          "--device",
          [&device](const std::string& name) {
            device = name == "cpu"    ? fusion::IntegrationDevice::cpu
                     : name == "cuda" ? fusion::IntegrationDevice::cuda
                                      : fusion::IntegrationDevice::automatic;
          },
          "Where TSDF integration runs: cpu, cuda (a GPU, in a build configured with "
          "-DGLINT_WITH_CUDA=ON), or auto (the GPU where there is one)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->default_str("auto");
}

void register_fuse_command(CLI::App& app) {
  auto options = std::make_shared<FuseOptions>();
  CLI::App* command = app.add_subcommand(
      "fuse",
      "Reconstruct a surface from an RGB-D sequence: voxel-hashed TSDF fusion (8^3-voxel blocks,\n"
      "VoxelHashing), camera tracking by coarse-to-fine point-to-plane ICP against the ray-cast\n"
      "model (or the dataset's ground-truth poses), marching-cubes mesh with colours.\n"
      "Layouts, detected from the folder: glint synthetic (intrinsics.json + associations.txt),\n"
      "TUM RGB-D, 7-Scenes/tsdf-fusion (frame-*.depth.png) and Redwood/Open3D (color/, depth/).");
  command->add_option("dataset", options->dataset, "RGB-D sequence folder")->required();
  command->add_option("-o,--output", options->mesh, "Mesh (PLY, binary, sRGB vertex colours)")
      ->required()
      ->check(kOutputFile);
  add_volume_options(command, options->params.volume);
  add_tracking_options(command, options->params.tracking);
  add_integration_device_option(command, options->params.device);
  command->add_flag("--gt-poses", options->params.use_ground_truth_poses,
                    "Use the dataset's ground-truth poses instead of tracking");
  command->add_option("--frames", options->frames, "Use the first N frames (0 = all)")
      ->capture_default_str();
  command->add_option("--trajectory", options->trajectory,
                      "Write the camera trajectory (TUM format, camera-to-world)");
  command->add_option("--points", options->points, "Also write the mesh vertices as a PLY cloud");
  command
      ->add_option("--report", options->report,
                   "JSON report: parameters, per-stage timings (median/mean/p90 ms), ATE")
      ->check(kOutputFile);
  command->footer(
      "Examples:\n"
      "  glint fuse data/rgbd/7scenes-50 -o kitchen.ply --gt-poses --report fuse.json\n"
      "  glint fuse data/rgbd/7scenes-50 -o kitchen.ply --voxel 0.01 --trajectory est.txt\n"
      "  glint fuse my_sequence -o mesh.ply --frames 100 --depth-max 3");
  command->callback([options] { run_fuse(*options); });
}

}  // namespace glint::app
