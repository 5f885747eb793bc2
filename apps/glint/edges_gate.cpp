// glint edges gate: joins two BoundED networks into one noise-gated model file.
#include <fmt/format.h>

#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "edges/model.h"

namespace glint::app {
namespace {

struct GateOptions {
  std::string noisy;
  std::string low_noise;
  float threshold = 0;
  std::string output;
};

void run_gate(const GateOptions& options) {
  if (!(options.threshold > 0.0f)) {
    throw Error("--threshold", fmt::format("{}", options.threshold), "must be > 0");
  }
  const edges::Model noisy = edges::Model::load(options.noisy);
  if (noisy.gated()) throw Error(options.noisy, "noise_gate", "already has a noise gate");
  const edges::Model low_noise = edges::Model::load(options.low_noise);
  edges::Model gated;
  try {
    gated = noisy.with_noise_gate(low_noise, options.threshold);
  } catch (const Error& e) {  // the second network does not fit the first
    throw Error(options.low_noise, e.element(),
                fmt::format("{} (it must have the classes, scales and layers of {})", e.reason(),
                            options.noisy));
  }
  gated.save(options.output);
  fmt::print("{} (noisy clouds) + {} (low-noise clouds), threshold {} -> {}\n", options.noisy,
             options.low_noise, options.threshold, options.output);
}

}  // namespace

void register_edges_gate(CLI::App& edges) {
  auto options = std::make_shared<GateOptions>();
  CLI::App* command = edges.add_subcommand(
      "gate",
      "Join two BoundED networks into one noise-gated model: the low-noise network answers a\n"
      "cloud when more than half of its points have a noise statistic below --threshold\n"
      "(sqrt(sigma_upper3 + sigma_lower3) at the smallest scale, see docs/edges.md), the noisy\n"
      "network answers every other cloud. Both need the same classes and scales.\n"
      "Example: glint edges gate noisy-3c.json clean-3c.json --threshold 0.01 -o gated-3c.json");
  command->add_option("noisy", options->noisy, "Model for noisy clouds (e.g. trained with noise)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("low_noise", options->low_noise, "Model for low-noise clouds")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--threshold", options->threshold, "Noise statistic of a quiet point, > 0")
      ->required();
  command->add_option("-o,--output", options->output, "Output model JSON")
      ->required()
      ->check(kOutputFile);
  command->callback([options] { run_gate(*options); });
}

}  // namespace glint::app
