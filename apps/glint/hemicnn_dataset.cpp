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
  std::vector<reflectance::HemiProjection> projections;
  if (options.projection == "both")
    projections = {reflectance::HemiProjection::parabolic,
                   reflectance::HemiProjection::orthographic};
  else
    projections = {reflectance::parse_hemi_projection(options.projection, "--projection")};
  std::vector<reflectance::HemiDatasetWriter> writers;
  for (reflectance::HemiProjection projection : projections)
    writers.emplace_back(
        projections.size() == 1
            ? options.output
            : (fs::path(options.output) / reflectance::hemi_projection_name(projection)).string(),
        15, projection);

  int skipped = 0;
  ProgressBar progress("hemi-images", folders.size());
  for (const std::string& folder : folders) {
    const reflectance::ExtractedHemiImages extracted =
        reflectance::extract_hemi_images(folder, projections, options.params);
    progress.advance();
    if (extracted.count < reflectance::kMinHemiImages) {
      log().warn("{}: only {} voxels with {} observations; skipped", folder, extracted.count,
                 options.params.min_observations);
      ++skipped;
      continue;
    }
    for (std::size_t p = 0; p < projections.size(); ++p)
      writers[p].add_sequence(extracted.images[p].data(), extracted.count, extracted.material,
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
      "15x15 hemi-images (paper 1 §4.1). With --projection both (default) OUT/parabolic and\n"
      "OUT/orthographic are written, for the modified and the unmodified HemiCNN.");
  command->add_option("training_set", options->training_set, "Folder of seq_* sequences")
      ->required();
  command->add_option("-o,--output", options->output, "Dataset folder")->required();
  command->add_option("--projection", options->projection, "parabolic, orthographic or both")
      ->check(CLI::IsMember({"parabolic", "orthographic", "both"}))
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
      "  glint hemicnn train hemi/parabolic -o models/hemicnn.json");
  command->callback([options] { run_dataset(*options); });
}

}  // namespace glint::app
