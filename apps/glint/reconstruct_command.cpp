// glint reconstruct: the online reflectance pipeline of paper 1 on an RGB-D sequence: geometry,
// observations, segmentation, HemiCNN materials, albedo refinement, every frame; then the mesh
// with per-vertex albedo and segment, materials.json, lights.json, re-rendered frames and, on
// synthetic sequences with ground truth, the Table 1 metrics and Figure 4 plots.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/resources.h"
#include "core/timer.h"
#include "fusion/marching_cubes.h"
#include "io/image_io.h"
#include "io/json_report.h"
#include "io/rgbd_sequence.h"
#include "io/trajectory.h"
#include "reconstruct_outputs.h"
#include "reflectance/hemi_dataset.h"
#include "reflectance/light_estimation.h"
#include "reflectance/material_evaluation.h"
#include "reflectance/material_maps.h"
#include "reflectance/reconstruction_outputs.h"
#include "reflectance/reflectance_pipeline.h"
#include "render/embree_scene.h"
#include "render/renderer.h"
#include "render/scene_json.h"
#include "scene_export_options.h"
#include "volume_options.h"

namespace glint::app {
namespace {

namespace fs = std::filesystem;

// --specular's values: the HemiCNN's ks, alpha alone (the paper), or with the lobe fit.
constexpr const char* kHemiCnnOnly = "hemicnn";
constexpr const char* kHemiCnnAndFit = "hemicnn+fit";
const char* specular_name(const reflectance::SpecularParams& params) {
  return params.fit_lobe ? kHemiCnnAndFit : kHemiCnnOnly;
}

// --normals' values: the observation voxels' normals from the TSDF gradient at their surface
// point, or from the plane through their neighbours' surface points.
constexpr const char* kGradientNormals = "gradient";
constexpr const char* kPlaneNormals = "plane";
const char* normals_name(const reflectance::ObservationGridParams& params) {
  return params.normal_from_neighbours ? kPlaneNormals : kGradientNormals;
}

struct ReconstructOptions {
  std::string sequence;
  std::string output;
  std::string lights;  // a capture sequence folder or a lights.json
  bool ground_truth_lights = false;
  std::string model;
  std::string report;
  std::size_t frames = 0;
  std::optional<float> exposure;
  bool ground_truth_segmentation = false;
  bool ground_truth_visibility = false;
  bool ground_truth_indirect = false;
  int evaluate_every = 5;
  int render_every = 0;  // 0: only the last frame
  std::string views;     // TUM trajectory of extra poses to re-render at the end
  float render_normal_radius_m = reflectance::kRenderNormalRadiusM;
  bool glb = true;  // OUT/scene.glb
  SceneExportOptions scene;
  reflectance::ReflectanceParams params;
};

// An option that takes on or off into `flag`, whose value is the default shown.
void add_on_off_option(CLI::App* command, const std::string& name, bool& flag,
                       const std::string& help) {
  command
      ->add_option_function<std::string>(
          name, [&flag](const std::string& value) { flag = value == "on"; }, help)
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str(flag ? "on" : "off");
}

// The plane that gather and lobe rays leaving the reconstruction met at the end (null: none).
nlohmann::json continued_plane_json(const reflectance::ContinuedPlane& plane) {
  if (!plane.known()) return nullptr;
  return {{"normal", io::vector_json(plane.normal)},
          {"offset_m", plane.offset},
          {"kd", io::vector_json(plane.albedo)}};
}

reflectance::LightEstimate load_lights(const ReconstructOptions& options) {
  if (options.ground_truth_lights) {
    const std::string scene_path = (fs::path(options.sequence) / "scene.json").string();
    if (!fs::exists(scene_path))
      throw Error(options.sequence, "--gt-lights", "has no scene.json with the true lights");
    reflectance::LightEstimate estimate;
    estimate.lights = render::read_scene_json(scene_path).lights;
    estimate.capture = scene_path + " (ground truth)";
    return estimate;
  }
  if (options.lights.empty())
    throw Error(options.sequence, "--lights",
                "the pipeline needs the scene's lights: give the light-capture sequence or a "
                "lights.json (--lights), or --gt-lights for a synthetic sequence");
  return reflectance::load_lights(options.lights);
}

// The scene.json of a synthetic sequence, for the oracle `flag` needs.
render::Scene read_true_scene(const ReconstructOptions& options, const char* flag) {
  const std::string scene_path = (fs::path(options.sequence) / "scene.json").string();
  if (!fs::exists(scene_path))
    throw Error(options.sequence, flag, "has no scene.json with the true scene");
  return render::read_scene_json(scene_path);
}

// The true scene for --gt-visibility (null without it), read before the long run.
std::shared_ptr<const render::EmbreeScene> load_true_scene(const ReconstructOptions& options) {
  if (!options.ground_truth_visibility) return nullptr;
  if (!options.params.light_transport.shadows)
    throw Error(options.sequence, "--gt-visibility", "casts shadow rays: it needs --shadows on");
  return std::make_shared<const render::EmbreeScene>(read_true_scene(options, "--gt-visibility"));
}

// The true scene's path tracer for --gt-indirect (null without it), read before the long run.
std::shared_ptr<const render::Renderer> load_true_indirect(const ReconstructOptions& options) {
  if (!options.ground_truth_indirect) return nullptr;
  if (!options.params.light_transport.indirect)
    throw Error(options.sequence, "--gt-indirect",
                "replaces the gather's estimate: it needs --indirect on");
  return std::make_shared<const render::Renderer>(read_true_scene(options, "--gt-indirect"));
}

void run_reconstruct(ReconstructOptions options) {
  Stopwatch total;
  scene_export_params(options.scene);  // an unknown --up fails before the long run
  const io::RgbdSequence sequence = io::open_rgbd_sequence(options.sequence);
  const std::size_t frames =
      options.frames ? std::min(options.frames, sequence.frames.size()) : sequence.frames.size();
  if (options.params.geometry.use_ground_truth_poses)
    sequence.require_ground_truth(frames, "--gt-poses needs every frame's (drop it to track)");
  const bool has_truth = reflectance::has_ground_truth_maps(sequence);
  if (options.ground_truth_segmentation && !has_truth)
    throw Error(options.sequence, "--gt-segmentation", "the sequence has no gt/segment maps");
  options.params.exposure =
      options.exposure.value_or(reflectance::capture_exposure(options.sequence));
  const reflectance::LightEstimate lights = load_lights(options);
  const std::shared_ptr<const render::EmbreeScene> true_scene = load_true_scene(options);
  const std::shared_ptr<const render::Renderer> true_indirect = load_true_indirect(options);
  const std::vector<io::StampedPose> views = options.views.empty()
                                                 ? std::vector<io::StampedPose>{}
                                                 : io::read_tum_trajectory(options.views);
  const std::string model_path =
      options.model.empty() ? glint::model_path("hemicnn.json").string() : options.model;
  const reflectance::HemiCnn network = reflectance::HemiCnn::load(model_path);

  // Everything goes to a temporary folder renamed onto OUT at the end: a failure leaves no
  // half-written result.
  reflectance::ReconstructionFolder folder(options.output);
  const std::string& staging = folder.path();
  fs::create_directories(fs::path(staging) / "frames");
  reflectance::ReflectancePipeline pipeline(sequence.intrinsics, options.params, network,
                                            lights.lights);
  if (true_scene) pipeline.use_true_visibility(true_scene);
  if (true_indirect) pipeline.use_true_indirect(true_indirect);
  reflectance::MaterialEvaluation evaluation;
  // Per frame: read; render (the re-rendering alone), evaluate (scoring and pictures); per
  // extra view: render; mesh once.
  StageTimings command_timings, render_timings;
  reflectance::MaterialMaps maps;  // every re-rendering's, its storage reused
  int lost = 0;
  {
    ProgressBar progress("reconstruct", frames);
    for (std::size_t i = 0; i < frames; ++i) {
      Stopwatch watch;
      const io::RgbdFrame frame = io::read_rgbd_frame(sequence, i);
      const bool last = i + 1 == frames;
      const bool evaluate =
          has_truth && options.evaluate_every > 0 && (int(i) % options.evaluate_every == 0 || last);
      const bool render = last || (options.render_every > 0 && int(i) % options.render_every == 0);
      // The gt/ maps of a scored frame also hold its segment ids: each file is read once.
      std::optional<reflectance::GroundTruthMaps> truth;
      if (evaluate) {
        truth = reflectance::read_ground_truth_maps(sequence, i);
      } else if (options.ground_truth_segmentation) {
        truth.emplace();
        truth->segment = reflectance::read_ground_truth_segments(sequence, i);
      }
      command_timings.add("read", watch.elapsed_ms());
      const reflectance::ReflectanceFrame result =
          pipeline.process(frame, options.ground_truth_segmentation ? &truth->segment : nullptr);
      if (!result.geometry.integrated) ++lost;
      if (result.geometry.integrated && (evaluate || render)) {
        watch.restart();
        reflectance::render_model(pipeline, sequence.intrinsics, result.geometry.camera_to_world,
                                  options.render_normal_radius_m, render_timings, maps,
                                  &frame.depth_m);
        command_timings.add("render", watch.elapsed_ms());
        watch.restart();
        if (evaluate) evaluation.add_frame(int(i), maps, *truth, frame.colour);
        if (render) write_frame_pictures(staging, int(i), frame.colour, maps);
        command_timings.add("evaluate", watch.elapsed_ms());
      }
      progress.advance();
    }
    progress.finish();
  }

  if (!options.views.empty()) {
    // Re-renderings of the final model from any poses (e.g. views the camera never took).
    fs::create_directories(fs::path(staging) / "views");
    ProgressBar progress("views", views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
      Stopwatch watch;
      reflectance::render_model(pipeline, sequence.intrinsics, views[k].pose,
                                options.render_normal_radius_m, render_timings, maps);
      command_timings.add("render", watch.elapsed_ms());
      write_view_pictures((fs::path(staging) / "views").string(), int(k), maps);
      progress.advance();
    }
    progress.finish();
  }

  Stopwatch watch;
  reflectance::write_reconstruction(staging, pipeline, lights);
  command_timings.add("mesh", watch.elapsed_ms());
  nlohmann::json glb_report = nullptr;
  if (options.glb) {
    // From the files just written, as `glint export OUT` would: both give the same scene.glb.
    watch.restart();
    glb_report = export_scene(staging, (fs::path(staging) / "scene.glb").string(), options.scene,
                              /*optional=*/true);
    command_timings.add("glb", watch.elapsed_ms());
  }
  if (has_truth && !evaluation.series().empty()) {
    write_material_plots((fs::path(staging) / "materials-over-time.png").string(), evaluation,
                         options.evaluate_every);
    print_evaluation_table(evaluation);
  }

  folder.commit();
  const StageTimings& timings = pipeline.timings();
  log().info(
      "{} frames of {} ({}): {} segments, {} observation voxels; per frame: geometry "
      "{:.1f}, observations {:.1f}, segmentation {:.1f}, shadows {:.1f}, indirect {:.1f}, "
      "specular {:.1f}, mirror {:.1f}, albedo {:.1f}, total {:.1f} ms (median) -> {}",
      frames, options.sequence, sequence.format, pipeline.segments().max_segment_id(),
      pipeline.observations().voxel_count(), timings.median_ms("geometry"),
      timings.median_ms("observations"), timings.median_ms("segmentation"),
      timings.median_ms("shadows"), timings.median_ms("indirect"), timings.median_ms("specular"),
      timings.median_ms("mirror"), timings.median_ms("albedo"), timings.median_ms("total"),
      options.output);
  const reflectance::SpecularParams& specular = options.params.specular;
  const reflectance::MaterialCoverage coverage =
      reflectance::material_coverage(pipeline, specular.min_distinct_voxels);
  if (coverage.without_material > 0) {
    const reflectance::ObservationGridParams& grid = options.params.observations;
    log().warn(
        "{} of {} segments got no material: no frame found {} of their voxels with {} "
        "observations each (seen in too few frames){}",
        coverage.without_material, coverage.segments, specular.min_distinct_voxels,
        specular.min_observations,
        grid.min_observation_spacing_deg > 0
            ? fmt::format("; a voxel stores a new observation only {:g}° from its newest{}, "
                          "so a short sequence or a slow camera stores few: --obs-spacing 0 "
                          "stores one every frame",
                          grid.min_observation_spacing_deg,
                          grid.spacing_max_frames > 0
                              ? fmt::format(" or {} frames after it", grid.spacing_max_frames)
                              : std::string())
            : std::string());
  }
  if (pipeline.light_transport().indirect_scale_capped())
    log().warn(
        "the gathered indirect light's scale ended at its cap of {:g}: where no light of --lights "
        "reaches, the surfaces are typically at least that many times as bright as the gathered "
        "light explains. A light missing from --lights (a lamp, a window) would do it, and leaves "
        "the albedo too bright where that light falls; --indirect-scale off keeps the gather "
        "unscaled",
        options.params.light_transport.indirect_scale_max);
  if (options.report.empty()) return;
  nlohmann::json command = command_timings.to_json();
  io::write_json(
      options.report,
      {{"command", command_line()},
       {"input", options.sequence},
       {"format", sequence.format},
       {"frames", frames},
       {"tracking_lost_frames", lost},
       {"parameters",
        {{"obs_voxel_m", options.params.observations.voxel_size_m},
         {"voxel_m", options.params.geometry.volume.voxel_size_m},
         {"integration_device", pipeline.integration_device()},
         {"observations_per_voxel", options.params.observations.observations_per_voxel},
         {"obs_spacing_deg", options.params.observations.min_observation_spacing_deg},
         {"obs_spacing_frames", options.params.observations.spacing_max_frames},
         {"albedo_average", reflectance::albedo_average_name(options.params.albedo_average)},
         {"albedo_keep_clipped", options.params.albedo_keep_clipped},
         {"albedo_min_light_cosine", options.params.albedo_min_light_cosine},
         {"albedo_max_ratio", options.params.albedo_max_ratio},
         {"albedo_max_indirect_share", options.params.albedo_max_indirect_share},
         {"albedo_shrinkage", options.params.albedo_shrinkage},
         {"albedo_normal_error", options.params.albedo_normal_error},
         {"albedo_smoothing", options.params.albedo_smoothing},
         {"specular", specular_name(options.params.specular)},
         {"normals", normals_name(options.params.observations)},
         {"render_normal_radius_m", options.render_normal_radius_m},
         {"ground_truth_poses", options.params.geometry.use_ground_truth_poses},
         {"track_model_halvings", options.params.geometry.tracking.model_halvings},
         {"ground_truth_segmentation", options.ground_truth_segmentation},
         {"ground_truth_visibility", options.ground_truth_visibility},
         {"ground_truth_indirect", options.ground_truth_indirect},
         {"segment_noise", options.params.segmentation.convexity_noise_k},
         {"exposure", options.params.exposure},
         {"shadows", options.params.light_transport.shadows},
         {"shadow_test", options.params.light_transport.shadow_test},
         {"shadow_test_sigmas", options.params.light_transport.shadow_test_sigmas},
         {"indirect", options.params.light_transport.indirect},
         {"unseen_light", options.params.light_transport.unseen},
         {"indirect_rays", options.params.light_transport.indirect_rays},
         {"indirect_rays_per_frame", options.params.light_transport.indirect_rays_per_frame},
         {"indirect_pooling", options.params.light_transport.indirect_pooling},
         {"continue_plane", options.params.light_transport.continue_plane},
         {"indirect_scaled", options.params.light_transport.indirect_scaled},
         {"indirect_specular",
          reflectance::indirect_specular_name(options.params.light_transport.indirect_specular)},
         {"ray_offset_m", options.params.light_transport.ray_offset_m},
         {"model", model_path},
         {"model_input", reflectance::hemi_input_name(network.input())},
         {"lights", lights.capture}}},
       {"indirect_scale", pipeline.light_transport().indirect_scale()},
       {"indirect_error", pipeline.light_transport().indirect_error()},
       {"continued_plane", continued_plane_json(pipeline.light_transport().continued_plane())},
       {"timings_ms", timings.to_json()},
       {"geometry_timings_ms", pipeline.geometry_timings().to_json()},
       {"command_timings_ms", command},
       {"render_timings_ms", render_timings.to_json()},
       {"materials", reflectance::materials_json(pipeline)},
       {"material_coverage",
        {{"segments", coverage.segments}, {"without_material", coverage.without_material}}},
       {"evaluation", has_truth ? evaluation.to_json() : nlohmann::json(nullptr)},
       {"scene_glb", glb_report},
       {"total_s", total.elapsed_s()}});
}

}  // namespace

void register_reconstruct_command(CLI::App& app) {
  auto options = std::make_shared<ReconstructOptions>();
  reflectance::ReflectanceParams& params = options->params;
  CLI::App* command = app.add_subcommand(
      "reconstruct",
      "Online multi-material reflectance reconstruction (paper 1): every frame fuses the\n"
      "geometry (voxel-hashed TSDF), collects (radiance, direction) observations in a coarse\n"
      "voxel grid, segments the depth image into objects (or uses the ground truth), predicts\n"
      "each segment's Ward kd, ks, alpha with the HemiCNN from 25 hemi-images (ks, alpha\n"
      "from a photometric lobe fit to the same voxels where it explains them), fuses them over\n"
      "time, and refines the diffuse albedo per voxel (eq. 7) under the estimated point lights.\n"
      "Writes OUT/mesh.ply (per vertex: refined kd as colour; kd_r/g/b, ks_r/g/b, alpha,\n"
      "scalar_segment as floats), OUT/materials.json, OUT/lights.json, OUT/frames/ (input,\n"
      "re-rendering, albedo), OUT/scene.glb (glTF 2.0: mesh, materials, lights; as `glint\n"
      "export`), and on synthetic sequences with gt/ the paper's Table 1 metrics and\n"
      "OUT/materials-over-time.png.");
  command->add_option("sequence", options->sequence, "RGB-D sequence folder")->required();
  command
      ->add_option("-o,--output", options->output,
                   "Output folder, written whole at the end; an existing one is replaced only when "
                   "empty or a previous reconstruction")
      ->required();
  command->add_option("--lights", options->lights,
                      "Light-capture sequence folder (low exposure, paper §3.2) or a lights.json");
  command->add_flag("--gt-lights", options->ground_truth_lights,
                    "Use the true lights of a synthetic sequence's scene.json");
  command->add_option("--model", options->model,
                      "HemiCNN weights (default: models/hemicnn.json, on reflectance hemi-images; "
                      "models/hemicnn-radiance.json reads radiance, as the paper)");
  command
      ->add_option("--obs-voxel", params.observations.voxel_size_m,
                   "Observation grid voxel, metres (paper: 0.02 or 0.01)")
      ->capture_default_str();
  command
      ->add_option("--obs-voxels", params.observations.voxel_capacity,
                   "Observation voxel pool (about 0.8 KB each, committed as used); default 2^20 "
                   "at 2 cm, 2 x (0.02 / obs-voxel)^2 times that below")
      ->check(kPositive);
  command
      ->add_option("--obs-spacing", params.observations.min_observation_spacing_deg,
                   "Degrees: an observation this close in direction to its voxel's newest stored "
                   "one is not stored, unless that is --obs-spacing-frames old (0 stores every "
                   "one)")
      ->check(CLI::Range(0.0, 89.9))
      ->capture_default_str();
  command
      ->add_option("--obs-spacing-frames", params.observations.spacing_max_frames,
                   "Frames: an observation is stored however close to its voxel's newest one "
                   "once that is this old, so a slowly moving camera still collects enough for "
                   "the specular stage (0: never)")
      ->check(kNonNegative)
      ->capture_default_str();
  add_volume_options(command, params.geometry.volume);
  add_tracking_options(command, params.geometry.tracking);
  add_integration_device_option(command, params.geometry.device);
  command->add_flag("--gt-poses", params.geometry.use_ground_truth_poses,
                    "Use the dataset's ground-truth poses instead of tracking");
  command->add_flag("--gt-segmentation", options->ground_truth_segmentation,
                    "Use gt/segment ids instead of the depth segmentation (evaluation)");
  command->add_flag("--gt-visibility", options->ground_truth_visibility,
                    "Cast the shadow rays against the true scene of a synthetic sequence (its "
                    "scene.json) instead of the fused geometry: the refined albedo as it would be "
                    "if the pipeline knew every occluder, also the sides the camera never saw "
                    "(evaluation)");
  command->add_flag("--gt-indirect", options->ground_truth_indirect,
                    "With --indirect on: take each voxel's indirect irradiance from the true "
                    "scene of a synthetic sequence (its scene.json's path tracer, as many "
                    "bounces as it was rendered with) instead of the gather: the refined albedo "
                    "as it would be if the pipeline knew all the bounced light (evaluation)");
  command->add_option("--exposure", options->exposure,
                      "Exposure of the sequence (radiance = pixel / exposure); default: its "
                      "scene.json's, else 1");
  command->add_option("--frames", options->frames, "Use the first N frames (0 = all)");
  command
      ->add_option("--eval-every", options->evaluate_every,
                   "With gt/: score every N-th frame against the ground truth (0 = never)")
      ->capture_default_str();
  command->add_option("--render-every", options->render_every,
                      "Write re-rendered pictures of every N-th frame (0 = the last only)");
  command
      ->add_option("--render-normal-radius", options->render_normal_radius_m,
                   "Smooth the re-renderings' normals over this radius in metres, within each "
                   "face (0 = per-pixel normals of the ray cast)")
      ->capture_default_str()
      ->check(kNonNegative);
  command->add_flag("!--no-glb", options->glb, "Do not write OUT/scene.glb");
  add_scene_export_options(command, options->scene);
  command->add_option("--views", options->views,
                      "TUM trajectory (camera-to-world) of extra poses to re-render the final "
                      "model from, into OUT/views/");
  command
      ->add_option("--segment-noise", params.segmentation.convexity_noise_k,
                   "Depth segmentation: a neighbour within this many Kinect noise sigmas (Nguyen "
                   "et al.: 1.2 mm + 1.9 mm (z - 0.4 m)^2) in front of a pixel's tangent plane "
                   "still counts convex, so sensor noise does not cut surfaces into fragments; "
                   "lower it for a less noisy sensor (0 = a fixed 0.5 mm)")
      ->check(CLI::Range(0.0f, 10.0f))
      ->capture_default_str();
  command
      ->add_option("--albedo-every", params.albedo_refresh_frames,
                   "Re-solve each visible voxel's albedo every N frames (staggered)")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option_function<std::string>(
          "--albedo-average",
          [options](const std::string& name) {
            options->params.albedo_average = reflectance::parse_albedo_average(name);
          },
          "Combine a voxel's per-observation albedos (eq. 7) by their mean (the paper) or their "
          "per-channel median (robust to mispredicted highlights)")
      ->check(CLI::IsMember({"mean", "median"}))
      ->default_str(reflectance::albedo_average_name(params.albedo_average));
  command->add_flag("--albedo-keep-clipped", params.albedo_keep_clipped,
                    "Solve eq. 7 from observations with a clipped channel too, as the paper (by "
                    "default they are left out where a voxel has others: their albedo comes out "
                    "too dark)");
  command
      ->add_option("--albedo-min-cosine", params.albedo_min_light_cosine,
                   "Trust a voxel's refined albedo only where its light's effective incidence "
                   "cosine reaches this (grazing light makes eq. 7 ill-conditioned); elsewhere "
                   "the re-renderings and the mesh use the reliable voxels around it; those "
                   "blend in the segment's refined albedo as one more voxel lit at this cosine, "
                   "and weigh each voxel by its light (0 = trust all and no segment albedo, as "
                   "the paper)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  command
      ->add_option("--albedo-max-ratio", params.albedo_max_ratio,
                   "Distrust a voxel's refined albedo where it is more than this factor below or "
                   "above the median of its segment's: the lights do not explain its "
                   "observations, most often a shadow cast by a part of the scene the camera "
                   "never saw (the shadow ray passes through it); the re-renderings and the mesh "
                   "use the reliable voxels around it or the segment's albedo instead, and where "
                   "it is too dark they leave that light out, unless its observations without the "
                   "specular lobe are bright enough (the lobe over-predicts a highlight) (0 = "
                   "trust all, as the paper)")
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            char* end = nullptr;
            const float ratio = std::strtof(text.c_str(), &end);
            const bool valid = end != text.c_str() && *end == '\0' && (ratio == 0 || ratio >= 1);
            return valid ? "" : "must be 0 (off) or a number >= 1, not " + text;
          },
          "0 or >= 1"))
      ->capture_default_str();
  command
      ->add_option("--albedo-max-indirect", params.albedo_max_indirect_share,
                   "With --indirect on: distrust a voxel's refined albedo where more than this "
                   "share of its irradiance is the gathered indirect light (an estimate whose "
                   "error then dominates: mostly voxels in shadow); they take the albedo of the "
                   "reliable voxels around them or their segment's (1 = trust all)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  add_on_off_option(command, "--albedo-shrinkage", params.albedo_shrinkage,
                    "Pull each voxel's refined albedo towards its segment's by how much its "
                    "error exceeds the segment's own spread of albedo: the error is how its "
                    "observations scatter (a voxel across two faces, a misfit highlight), its "
                    "normal's (--albedo-normal-error, grown by grazing light) and, with "
                    "--indirect on, the gathered light's (its share of the irradiance times the "
                    "gather's measured error); the colour stays, texture seen consistently "
                    "stays (off = eq. 7 as is)");
  command
      ->add_option("--albedo-normal-error", params.albedo_normal_error,
                   "With --albedo-shrinkage on: the error of the voxels' normals, radians; eq. 7 "
                   "turns it into an albedo error of tan(light incidence) times it, so voxels "
                   "under grazing light take more of their segment's albedo (0 = the normals "
                   "are exact)")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--albedo-smoothing", params.albedo_smoothing,
                   "Re-renderings and the mesh smooth the refined albedo between neighbouring "
                   "observation voxels whose albedos differ by about this relative contrast or "
                   "less (a Gaussian range weight of this standard deviation; texture edges of "
                   "more contrast stay sharp); 0 = trilinear interpolation only, as the paper")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option_function<std::string>(
          "--specular",
          [options](const std::string& name) {
            options->params.specular.fit_lobe = name == kHemiCnnAndFit;
          },
          "Each frame's ks and alpha per segment: the HemiCNN's (the paper), or a photometric "
          "fit of the Ward lobe to the same voxels' observations where the lobe explains them")
      ->check(CLI::IsMember({kHemiCnnOnly, kHemiCnnAndFit}))
      ->default_str(specular_name(params.specular));
  command
      ->add_option_function<std::string>(
          "--normals",
          [options](const std::string& name) {
            options->params.observations.normal_from_neighbours = name == kPlaneNormals;
          },
          "Observation voxels' normals: the TSDF gradient at the surface point, or the plane "
          "through the surface points of the voxel and its neighbours (steadier on flat faces, "
          "where a sharp highlight needs the normal to a fraction of a degree)")
      ->check(CLI::IsMember({kGradientNormals, kPlaneNormals}))
      ->default_str(normals_name(params.observations));
  command
      ->add_option_function<std::uint64_t>(
          "--seed",
          [options](std::uint64_t seed) {
            options->params.specular.seed = seed;
            options->params.segments.seed = seed;
            options->params.light_transport.seed = seed;
          },
          "Seed of the voxel sampling (each segment's voxel reservoir and each frame's draw "
          "from it) and of the gather rays' directions")
      ->default_str(std::to_string(params.specular.seed));
  reflectance::LightTransportParams& transport = params.light_transport;
  add_on_off_option(command, "--shadows", transport.shadows,
                    "Shadows: eq. 7, the hemi-images, the lobe fit and the re-renderings count "
                    "only the lights a voxel's shadow ray through the fused geometry reaches "
                    "(off = every light reaches every point, as the paper: only for input "
                    "rendered without shadows)");
  add_on_off_option(command, "--shadow-test", transport.shadow_test,
                    "With --shadows on: shadows the fused geometry misses (occluders whose far "
                    "side the camera never saw). A voxel whose albedo differs from its segment's "
                    "by more than 1.2x (wider under gathered light, --shadow-test-sigmas) leaves "
                    "out the light, among those whose shadow ray grazes fused geometry, that "
                    "brings its albedo nearest its segment's (off = shadow rays alone; it may "
                    "flatten a texture's darkest texels near objects)");
  command
      ->add_option("--shadow-test-sigmas", transport.shadow_test_sigmas,
                   "With --shadow-test on and the scaled gather: the test's 1.2x widens by this "
                   "many times the albedo's uncertainty from the gathered light (its share of "
                   "the irradiance times the gather's measured error); 0 = 1.2x everywhere")
      ->check(kNonNegative)
      ->capture_default_str();
  add_on_off_option(command, "--indirect", transport.indirect,
                    "Interreflections: each voxel's indirect irradiance, gathered over its "
                    "hemisphere from the radiance observed on the surfaces around it, adds to the "
                    "irradiance eq. 7 and the reflectance hemi-images divide by (off = direct "
                    "light only, as the paper)");
  add_on_off_option(command, "--unseen-light", transport.unseen,
                    "Per segment, the indirect irradiance that shadows and the gather leave "
                    "unexplained (light bounced off surfaces the camera never saw; all of it with "
                    "--indirect off), fitted from how the segment's diffuse radiance grows with "
                    "the irradiance it is known to get, and added to its voxels' (off = none)");
  command
      ->add_option("--indirect-rays", transport.indirect_rays,
                   "Cosine-weighted gather rays per voxel in its indirect estimate (afterwards a "
                   "moving average over this many)")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  command
      ->add_option("--indirect-rays-per-frame", transport.indirect_rays_per_frame,
                   "Gather rays cast per seen voxel and frame until it has --indirect-rays")
      ->check(kPositive)
      ->capture_default_str();
  add_on_off_option(command, "--indirect-pooling", transport.indirect_pooling,
                    "With --indirect on: a voxel's indirect estimate pools the gather rays of its "
                    "neighbours on the same surface (within 26 degrees and half a voxel of its "
                    "tangent plane), so it has light after a few frames and less noise (off = "
                    "its own rays only)");
  add_on_off_option(command, "--continue-plane", transport.continue_plane,
                    "With --indirect on: gather and lobe rays that leave the reconstruction meet "
                    "its largest plane (mostly the floor) continued beyond it, and bring that "
                    "plane's albedo / pi times the lights' irradiance there (unshadowed); a floor "
                    "scanned from one side goes on behind the camera (off = such rays are dark)");
  add_on_off_option(command, "--indirect-scale", transport.indirect_scaled,
                    "With --indirect on: scale the gathered light by what the voxels no light "
                    "reaches directly show (their brightness over the gather's prediction, the "
                    "scene's median): none where they are black, more where the gather misses "
                    "light bounced off surfaces the camera never saw (off = the gather as is)");
  command
      ->add_option_function<std::string>(
          "--indirect-specular",
          [options](const std::string& name) {
            options->params.light_transport.indirect_specular =
                reflectance::parse_indirect_specular(name);
          },
          "With --indirect on: what the specular lobe of a glossy surface mirrors of the bounced "
          "light, which eq. (7) takes out of the observations and re-renderings add: mirror = "
          "per observation, what one ray drawn from the lobe around its mirror direction meets "
          "in the reconstruction (the floor below a glossy object, the dark above it; one ray "
          "per stored observation, four per re-rendered pixel), sky = the gathered light as an "
          "even sky, off = none")
      ->check(CLI::IsMember({"off", "sky", "mirror"}))
      ->default_str(reflectance::indirect_specular_name(transport.indirect_specular));
  command
      ->add_option("--ray-offset", transport.ray_offset_m,
                   "Shadow and gather rays start this far (metres) off the surface along its "
                   "normal, so they do not find the surface they start on")
      ->check(kNonNegative)
      ->capture_default_str();
  command
      ->add_option("--report", options->report,
                   "JSON report: parameters, per-stage timings, materials, evaluation")
      ->check(kOutputFile);
  command->footer(
      "Examples:\n"
      "  glint synth bunnies -o seq/bunnies && glint synth lights --scene bunnies -o seq/cap\n"
      "  glint reconstruct seq/bunnies --lights seq/cap -o out/bunnies --gt-poses --report r.json\n"
      "  glint reconstruct seq/bunnies --lights out/bunnies/lights.json -o out/b1 --obs-voxel "
      "0.01\n"
      "  glint reconstruct data/rgbd/7scenes-50 --lights lights.json -o out/kitchen --gt-poses");
  command->callback([options] { run_reconstruct(*options); });
}

}  // namespace glint::app
