// glint export: a reconstruction folder as one glTF 2.0 binary (src/gltf/scene_export.h), the
// file `glint reconstruct` also writes as OUT/scene.glb.
#include <filesystem>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "scene_export_options.h"

namespace glint::app {

void add_scene_export_options(CLI::App* command, SceneExportOptions& options) {
  command
      ->add_option("--mesh-triangles", options.params.mesh_triangles,
                   "scene.glb: simplify the TSDF mesh to at most this many triangles "
                   "(meshoptimizer; 0 = full resolution)")
      ->capture_default_str();
  command
      ->add_option("--texture-size", options.params.texture_size,
                   "scene.glb: side of the baked kd atlas, texels (one density for the whole "
                   "scene; 0 = no texture, per-vertex COLOR_0 instead)")
      ->check(kNonNegative)
      ->capture_default_str();
  command->add_flag("--denoise-albedo", options.params.denoise_albedo,
                    "scene.glb: denoise the kd atlas where its voxels were seen few times "
                    "(guided DIP on the atlas at one texel per observation voxel, guided by the "
                    "local noise level and the observation count; minutes on a CPU)");
  command
      ->add_option("--denoise-config", options.params.denoise.config,
                   "scene.glb, --denoise-albedo: the guided DIP's configuration (fast: sized "
                   "for a CPU; full: the paper's, a GPU job)")
      ->check(CLI::IsMember({"fast", "full"}))
      ->capture_default_str();
  command
      ->add_option("--denoise-iterations", options.params.denoise.iterations,
                   "scene.glb, --denoise-albedo: the guided DIP's steps (default: the "
                   "configuration's, 1200 for fast)")
      ->check(kPositive);
  command
      ->add_option("--up", options.up,
                   "scene.glb: the axis of glint's world that points up (+y for glint's "
                   "synthetic scenes; -y for a sequence whose world is its first camera, e.g. "
                   "7-Scenes); the root node turns it into glTF's +Y")
      ->capture_default_str();
}

gltf::ExportParams scene_export_params(const SceneExportOptions& options) {
  gltf::ExportParams params = options.params;
  params.up = gltf::parse_up_axis(options.up);
  return params;
}

nlohmann::json export_scene(const std::string& folder, const std::string& path,
                            const SceneExportOptions& options, bool optional) {
  const gltf::ExportParams params = scene_export_params(options);
  Stopwatch watch;
  gltf::ExportStats stats;
  try {
    stats = gltf::write_scene_glb(gltf::read_reconstruction(folder), params, path);
  } catch (const Error& e) {
    if (!optional) throw;
    log().warn("scene.glb not written: {}", e.what());
    return nullptr;
  }
  const double seconds = watch.elapsed_s();
  const auto bytes = std::filesystem::file_size(path);
  log().info(
      "scene.glb: {} of {} triangles (deviation {:.1f} mm), {} materials, {} lights, {} charts at "
      "{:.0f} texels/m, {:.1f} MB in {:.1f} s",
      stats.triangles, stats.input_triangles, 1e3 * stats.simplification_error_m, stats.materials,
      stats.lights, stats.charts, stats.texels_per_metre, bytes / 1e6, seconds);
  if (stats.albedo.contains("truth"))
    for (const char* atlas : {"atlas", "denoised"})
      if (stats.albedo["truth"].contains(atlas)) {
        const nlohmann::json& errors = stats.albedo["truth"][atlas];
        log().info("kd {} against the truth: L1 {:.4f} (well observed {:.4f}, poorly {:.4f})",
                   atlas, errors["all"].value("l1", 0.0), errors["well_observed"].value("l1", 0.0),
                   errors["poorly_observed"].value("l1", 0.0));
      }
  nlohmann::json report = stats.to_json();
  report["total_s"] = seconds;
  report["bytes"] = bytes;
  return report;
}

namespace {

struct ExportCommandOptions {
  std::string folder, output, report;
  SceneExportOptions scene;
};

}  // namespace

void register_export_command(CLI::App& app) {
  auto options = std::make_shared<ExportCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "export",
      "A reconstruction (the folder `glint reconstruct` wrote) as one glTF 2.0 binary for\n"
      "three.js, Blender, Unity: the mesh simplified to a budget, one material per segment\n"
      "(metallic 0; base colour = the refined kd, baked into a texture atlas; ks as\n"
      "KHR_materials_specular; roughness from Ward's alpha, roughness = sqrt(0.918 alpha); the\n"
      "raw Ward values in the material's extras), the segment id per vertex (_SEGMENT), the\n"
      "lights as KHR_lights_punctual point lights (candela = glint's intensity), metres, +Y up.\n"
      "`glint reconstruct` writes the same file as OUT/scene.glb.");
  command->add_option("reconstruction", options->folder, "Reconstruction folder")->required();
  command->add_option("-o,--output", options->output, "GLB file to write")
      ->required()
      ->check(kOutputFile);
  add_scene_export_options(command, options->scene);
  command
      ->add_option("--albedo-truth", options->scene.params.albedo_truth,
                   "A synthetic sequence (glint render) the reconstruction came from: report the "
                   "kd atlas's L1 / PSNR against its ground truth, for well-observed (>= 15 "
                   "observations) and poorly observed texels, with and without --denoise-albedo")
      ->check(CLI::ExistingDirectory);
  command->add_option("--report", options->report, "JSON report: counts, sizes, seconds")
      ->check(kOutputFile);
  command->footer(
      "Examples:\n"
      "  glint export out/bunnies -o bunnies.glb\n"
      "  glint export out/kitchen -o kitchen.glb --up -y --mesh-triangles 100000\n"
      "  glint export out/office -o office-full.glb --mesh-triangles 0 --texture-size 4096\n"
      "  glint export out/bunnies -o bunnies.glb --denoise-albedo --albedo-truth seq/bunnies\n"
      "Check a file: node scripts/validate-glb.cjs X.glb (the Khronos glTF-Validator; see\n"
      "docs/reflectance.md, Export).");
  command->callback([options] {
    nlohmann::json report =
        export_scene(options->folder, options->output, options->scene, /*optional=*/false);
    if (options->report.empty()) return;
    report["command"] = command_line();
    report["input"] = options->folder;
    io::write_json(options->report, report);
  });
}

}  // namespace glint::app
