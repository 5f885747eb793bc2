#pragma once
// The scene.glb options shared by `glint export` and `glint reconstruct`.
#include <CLI/CLI.hpp>
#include <string>

#include "gltf/scene_export.h"

namespace glint::app {

struct SceneExportOptions {
  gltf::ExportParams params;
  std::string up = "+y";
};

// Adds --mesh-triangles, --texture-size, --denoise-albedo, --denoise-config and --up to
// `command`.
void add_scene_export_options(CLI::App* command, SceneExportOptions& options);
// The parameters with --up parsed (throws glint::Error for an unknown axis).
gltf::ExportParams scene_export_params(const SceneExportOptions& options);
// Reads the reconstruction in `folder`, writes `path`, logs one line and returns the statistics
// with the export's seconds and the file's bytes (for reports). A failure (e.g. a mesh without
// triangles, an atlas too small for the charts) throws glint::Error, or when `optional`
// (reconstruct: a long run keeps its other outputs) logs a warning and returns null.
nlohmann::json export_scene(const std::string& folder, const std::string& path,
                            const SceneExportOptions& options, bool optional);

}  // namespace glint::app
