// glint hemicnn dataset: HemiCNN training data from a rendered training set (glint synth
// training), through glint's own geometry fusion and observation collection (paper 1 §4.1).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/timer.h"
#include "reflectance/hemi_dataset.h"
#include "reflectance/hemi_extraction.h"

namespace glint::app {
namespace {

namespace fs = std::filesystem;

struct DatasetOptions {
  std::string training_set;
  std::string output;
  std::string projection = "both";
  std::string input = "both";
  int max_sequences = 0;
  reflectance::HemiExtractionParams params;
};

std::vector<std::string> sequence_folders(const std::string& training_set) {
  if (!fs::is_directory(training_set))
    throw Error(training_set, "", "is not a folder (make one with `glint synth training`)");
  std::vector<std::string> folders;
  for (const auto& entry : fs::directory_iterator(training_set))
    if (entry.is_directory() && entry.path().filename().string().rfind("seq_", 0) == 0)
      folders.push_back(entry.path().string());
  std::sort(folders.begin(), folders.end());
  if (folders.empty()) throw Error(training_set, "", "holds no seq_* sequence folders");
  return folders;
}

void run_dataset(const DatasetOptions& options) {
  Stopwatch total;
  std::vector<std::string> folders = sequence_folders(options.training_set);
  if (options.max_sequences > 0 && std::size_t(options.max_sequences) < folders.size())
    folders.resize(options.max_sequences);
  std::vector<reflectance::HemiImageKind> kinds;
  for (auto projection :
       {reflectance::HemiProjection::parabolic, reflectance::HemiProjection::orthographic})
    for (auto input : {reflectance::HemiInput::radiance, reflectance::HemiInput::reflectance})
      if ((options.projection == "both" ||
           options.projection == reflectance::hemi_projection_name(projection)) &&
          (options.input == "both" || options.input == reflectance::hemi_input_name(input)))
        kinds.push_back({projection, input});
  std::vector<reflectance::HemiDatasetWriter> writers;
  for (const reflectance::HemiImageKind& kind : kinds) {
    const std::string folder =
        std::string(reflectance::hemi_projection_name(kind.projection)) +
        (kind.input == reflectance::HemiInput::reflectance ? "-reflectance" : "");
    writers.emplace_back(
        kinds.size() == 1 ? options.output : (fs::path(options.output) / folder).string(), 15,
        kind.projection, kind.input);
  }

  int skipped = 0;
  ProgressBar progress("hemi-images", folders.size());
  for (const std::string& folder : folders) {
    const reflectance::ExtractedHemiImages extracted =
        reflectance::extract_hemi_images(folder, kinds, options.params);
    progress.advance();
    if (extracted.count < reflectance::kMinHemiImages) {
      log().warn("{}: only {} voxels with {} observations; skipped", folder, extracted.count,
                 options.params.min_observations);
      ++skipped;
      continue;
    }
    for (std::size_t k = 0; k < kinds.size(); ++k)
      writers[k].add_sequence(extracted.images[k].data(), extracted.count, extracted.material,
                              folder);
  }
  progress.finish();
  for (auto& writer : writers) writer.finish();
  log().info("{} sequences -> {} ({} skipped) in {:.0f} s", folders.size(), options.output, skipped,
             total.elapsed_s());
}

}  // namespace

void register_hemicnn_dataset(CLI::App& hemicnn) {
  auto options = std::make_shared<DatasetOptions>();
  CLI::App* command = hemicnn.add_subcommand(
      "dataset",
      "Turn a rendered training set (glint synth training) into HemiCNN training data: each\n"
      "sequence runs through the pipeline's geometry fusion (true poses) and observation\n"
      "collection (true segmentation), and up to --max-images voxels of its object become\n"
      "15x15 hemi-images (paper 1 §4.1), of radiance (the paper's input) or of reflectance\n"
      "(radiance times pi over the true lights' irradiance at the voxel, the default model's\n"
      "input). With more than one kind, each goes to its own folder: OUT/parabolic and\n"
      "OUT/orthographic (radiance, for the paper's modified and unmodified HemiCNN),\n"
      "OUT/parabolic-reflectance and OUT/orthographic-reflectance.");
  command->add_option("training_set", options->training_set, "Folder of seq_* sequences")
      ->required();
  command->add_option("-o,--output", options->output, "Dataset folder")->required();
  command->add_option("--projection", options->projection, "parabolic, orthographic or both")
      ->check(CLI::IsMember({"parabolic", "orthographic", "both"}))
      ->capture_default_str();
  command->add_option("--input", options->input, "radiance, reflectance or both")
      ->check(CLI::IsMember({"radiance", "reflectance", "both"}))
      ->capture_default_str();
  command
      ->add_option("--obs-voxel", options->params.observations.voxel_size_m,
                   "Observation grid voxel, metres")
      ->capture_default_str();
  command->add_option("--max-images", options->params.max_images, "Hemi-images per sequence")
      ->check(CLI::Range(reflectance::kMinHemiImages, reflectance::kMaxHemiImages))
      ->capture_default_str();
  command->add_option("--sequences", options->max_sequences, "Use the first N sequences (0 = all)");
  command->add_option("--seed", options->params.seed, "Seed of the voxel choice")
      ->capture_default_str();
  command->footer(
      "Example:\n"
      "  glint synth training -o train --sequences 400\n"
      "  glint hemicnn dataset train -o hemi\n"
      "  glint hemicnn train hemi/parabolic-reflectance -o models/hemicnn.json");
  command->callback([options] { run_dataset(*options); });
}

}  // namespace glint::app
