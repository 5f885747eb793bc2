// glint edges gate: joins two BoundED networks into one gated model file.
#include <fmt/format.h>

#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "edges/model.h"

namespace glint::app {
namespace {

struct GateOptions {
  std::string model;
  std::string gate_model;
  std::string statistic = "noise";
  float threshold = 0;
  std::string output;
};

void run_gate(const GateOptions& options) {
  if (!(options.threshold > 0.0f)) {
    throw Error("--threshold", fmt::format("{}", options.threshold), "must be > 0");
  }
  if (options.statistic != "noise" && options.statistic != "sampling") {
    throw Error("--statistic", options.statistic, "expected noise or sampling");
  }
  const edges::GateKind kind =
      options.statistic == "noise" ? edges::GateKind::noise : edges::GateKind::sampling;
  const edges::Model model = edges::Model::load(options.model);
  if (model.gated())
    throw Error(options.model, "", "already has a gate (the second model may hold one)");
  const edges::Model gate_model = edges::Model::load(options.gate_model);
  edges::Model gated;
  try {
    gated = model.with_gate(kind, gate_model, options.threshold);
  } catch (const Error& e) {  // the second network does not fit the first
    throw Error(options.gate_model, e.element(),
                fmt::format("{} (it must have the config of {} but for its neighbour weights)",
                            e.reason(), options.model));
  }
  gated.save(options.output);
  const auto name = [&](bool answered) {
    return edges::network_name({{kind, options.threshold, 0.0, answered}});
  };
  fmt::print("{} ({} clouds) + {} ({} clouds), threshold {} -> {}\n", options.model, name(false),
             options.gate_model, name(true), options.threshold, options.output);
}

}  // namespace

void register_edges_gate(CLI::App& edges) {
  auto options = std::make_shared<GateOptions>();
  CLI::App* command = edges.add_subcommand(
      "gate",
      "Join two BoundED networks into one gated model: the second network answers the clouds\n"
      "the gate picks, the first every other cloud. Both need the same classes, scales and\n"
      "features per scale; they may weigh neighbours differently. The gate reads a sample of\n"
      "the points before the features, so only the chosen network's features are computed.\n"
      "The second model may be gated itself: a chain of networks, one answering each cloud.\n"
      "  --statistic noise: a low-noise network answers a cloud when more than half of the\n"
      "    points read (up to 16,384) have a noise statistic below --threshold\n"
      "    (sqrt(sigma_upper3 + sigma_lower3) at the smallest scale, features of the first).\n"
      "  --statistic sampling: a mesh-vertex network answers a cloud whose spacings spread\n"
      "    like a tessellation's vertices: ln(P90 / P10) of the distance to the 8th nearest\n"
      "    other point (up to 131,072 points read) at least --threshold (about 0.45 on even\n"
      "    samples).\n"
      "See docs/edges.md, \"gate\".\n"
      "Examples:\n"
      "  glint edges gate noisy-3c.json clean-3c.json --threshold 0.01 -o gated-3c.json\n"
      "  glint edges gate any-3c.json vertices-3c.json --statistic sampling --threshold 0.98 \\\n"
      "      -o gated-3c.json");
  command->add_option("model", options->model, "Model for the clouds the gate does not pick")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("gate_model", options->gate_model, "Model for the clouds the gate picks")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--statistic", options->statistic, "What the gate reads: noise or sampling")
      ->capture_default_str();
  command
      ->add_option("--threshold", options->threshold,
                   "Gate threshold, > 0 (noise statistic of a quiet point; spacing spread)")
      ->required();
  command->add_option("-o,--output", options->output, "Output model JSON")
      ->required()
      ->check(kOutputFile);
  command->callback([options] { run_gate(*options); });
}

}  // namespace glint::app
