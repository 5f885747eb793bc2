#pragma once
// Each subcommand registers itself on its parent CLI11 app.
#include <CLI/CLI.hpp>
#include <string>

namespace glint::app {

// Options every subcommand shares (--quiet, --threads, --log-level), applied before it runs.
struct CommonOptions {
  bool quiet = false;
  int threads = 0;
  std::string log_level = "info";
};

void register_edges_commands(CLI::App& app);

// `glint edges <name>` subcommands, one file each (apps/glint/edges_<name>.cpp).
void register_edges_classify(CLI::App& edges);
void register_edges_features(CLI::App& edges);
void register_edges_train(CLI::App& edges);
void register_edges_synth(CLI::App& edges);
void register_edges_eval(CLI::App& edges);
void register_edges_label(CLI::App& edges);
void register_edges_gate(CLI::App& edges);

void register_denoise_commands(CLI::App& app);

// `glint denoise <name>` subcommands (apps/glint/denoise_<name>.cpp).
void register_denoise_noise_map(CLI::App& denoise);
void register_denoise_run(CLI::App& denoise);
void register_denoise_eval(CLI::App& denoise);

// `glint render SCENE.json -o DIR` (apps/glint/render_command.cpp).
void register_render_command(CLI::App& app);
// `glint synth cubes|bunnies|office|lights|training -o DIR` (apps/glint/synth_command.cpp).
void register_synth_command(CLI::App& app);
// `glint fuse DATASET -o MESH.ply` (apps/glint/fuse_command.cpp).
void register_fuse_command(CLI::App& app);
// `glint hemicnn dataset|train|predict|probe` (apps/glint/hemicnn_commands.cpp).
void register_hemicnn_commands(CLI::App& app);
// `glint hemicnn dataset TRAINSET -o DIR` (apps/glint/hemicnn_dataset.cpp).
void register_hemicnn_dataset(CLI::App& hemicnn);
// `glint hemicnn train DATASET -o MODEL` and `glint hemicnn predict DATASET --model MODEL`
// (apps/glint/hemicnn_command.cpp).
void register_hemicnn_train(CLI::App& hemicnn);
void register_hemicnn_predict(CLI::App& hemicnn);
// `glint hemicnn probe --model MODEL` (apps/glint/hemicnn_probe.cpp).
void register_hemicnn_probe(CLI::App& hemicnn);
// `glint reconstruct SEQ -o OUT` (apps/glint/reconstruct_command.cpp).
void register_reconstruct_command(CLI::App& app);
// `glint lights CAPTURE -o lights.json` (apps/glint/lights_command.cpp).
void register_lights_command(CLI::App& app);
// `glint export RECONSTRUCTION -o scene.glb` (apps/glint/export_command.cpp).
void register_export_command(CLI::App& app);
// `glint view OUT [--port P] [--write-html DIR]` (apps/glint/view_command.cpp).
void register_view_command(CLI::App& app);

}  // namespace glint::app
