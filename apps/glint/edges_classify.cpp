// glint edges classify: per-point non-edge / sharp-edge / boundary labels for one cloud.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "commands.h"
#include "core/distributed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/timer.h"
#include "edges/angle_gap_baseline.h"
#include "edges/classifier.h"
#include "edges/tiled_classify.h"
#include "io/json_report.h"
#include "io/ply.h"
#include "io/point_cloud_io.h"
#include "point_preview.h"

namespace glint::app {
namespace {

struct ClassifyOptions {
  std::string input;
  std::string output;
  std::string model;
  std::string png;
  std::string report;
  std::vector<int> scales;
  std::string method = "bounded";
  std::string memory_limit;
  std::uint64_t tile_points = 0;
  bool no_gate = false;
};

std::string model_path(const ClassifyOptions& options) {
  return options.model.empty() ? default_edges_model() : options.model;
}

// The model of --model (or the shipped one); under --no-gate its first network alone.
edges::Model load_model(const ClassifyOptions& options) {
  edges::Model model = edges::Model::load(model_path(options));
  if (options.no_gate) model.gate_network = nullptr;
  return model;
}

// The angle-gap baseline as a Classification: labels 0 / 2, p_boundary 0 / 1, no sharp class.
edges::Classification classify_angle_gap(const PointCloud& cloud) {
  const Stopwatch watch;
  edges::Classification result;
  result.labels = edges::classify_angle_gap(cloud);
  result.p_sharp.assign(cloud.size(), 0.f);
  result.p_boundary.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) result.p_boundary[i] = result.labels[i] == 2;
  result.features_s = watch.elapsed_s();
  return result;
}

bool is_las(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".las" || extension == ".laz";
}

// What the gates of a gated model chose, for the log and the report (null otherwise): the first
// gate's entry, holding the next gate's under "gate" where the first passed the cloud on.
nlohmann::json gate_entry(const std::vector<edges::GateDecision>& decisions) {
  for (const edges::GateDecision& decision : decisions) {
    const std::string network = edges::network_name({decision});
    if (decision.kind == edges::GateKind::noise) {
      log().info("noise gate: {:.1f} % of the points read below {} -> the {} network",
                 100.0 * decision.statistic, decision.threshold, network);
    } else {
      log().info("sampling gate: spacing spread ln(P90/P10) {:.3f} against {} -> the {} network",
                 decision.statistic, decision.threshold, network);
    }
  }
  nlohmann::json entry = nullptr;
  for (auto decision = decisions.rbegin(); decision != decisions.rend(); ++decision) {
    nlohmann::json inner = std::move(entry);
    entry = {{"kind", decision->kind == edges::GateKind::noise ? "noise" : "sampling"},
             {"threshold", decision->threshold},
             {"statistic", decision->statistic},
             {"network", edges::network_name({*decision})}};
    if (!inner.is_null()) entry["gate"] = std::move(inner);
  }
  return entry;
}

// LAS in, LAS out: streamed, tiled when the cloud exceeds the memory limit, spread over the
// ranks of mpirun when built with MPI.
void run_classify_las(const ClassifyOptions& options) {
  if (!is_las(options.output)) {
    throw Error(options.output, "", "a LAS input is written back as a .las file");
  }
  if (!options.png.empty()) {
    throw Error(options.output, "--png", "is not available for LAS input (use a PLY cloud)");
  }
  if (options.method != "bounded") {
    throw Error(options.input, "--method",
                "only the network classifies LAS input (use a PLY cloud)");
  }
  const edges::Model model = load_model(options);
  edges::TiledClassifyParams params;
  params.scales = options.scales;
  if (!params.scales.empty() && params.scales.size() != model.config.scales.size()) {
    throw Error("", "--scales",
                fmt::format("the model was trained on {} scales; got {}",
                            model.config.scales.size(), params.scales.size()));
  }
  if (!options.memory_limit.empty()) {
    params.memory_limit_bytes = edges::parse_memory_size(options.memory_limit);
  }
  params.tile_points = options.tile_points;
  Distributed& world = Distributed::world();
  edges::TiledClassifyStats stats;
  try {
    stats = edges::classify_las(options.input, options.output, model, params);
  } catch (const Error& e) {
    if (world.size() <= 1) throw;
    // The other ranks wait in a collective call: end them all.
    std::fprintf(stderr, "glint: error (rank %d of %d): %s\n", world.rank(), world.size(),
                 e.what());
    world.abort(1);
  }
  const nlohmann::json gate = gate_entry(stats.gates);
  if (world.size() > 1) {
    fmt::print(
        "rank {}/{}: {} tiles, {} points classified in {:.2f} s (read {:.2f} s, write "
        "{:.2f} s)\n",
        world.rank(), world.size(), stats.rank_tiles, stats.rank_points, stats.classify_s,
        stats.read_s, stats.write_s);
    if (world.rank() != 0) return;
  }
  fmt::print(
      "{}: {} points -> {} non-edge, {} sharp, {} boundary in {:.2f} s ({:.0f} points/s){} -> "
      "{}\n",
      options.input, stats.points, stats.labels[0], stats.labels[1], stats.labels[2], stats.total_s,
      double(stats.points) / stats.total_s,
      stats.tiled
          ? fmt::format("; {} tiles of {:.1f} m, halo up to {:.2f} m, {:.1f} % halo "
                        "points, {} rank(s)",
                        stats.tiles, stats.tile_side_m, stats.halo_m_max,
                        100.0 * double(stats.halo_points) / double(stats.points), world.size())
          : std::string("; whole cloud in memory"),
      options.output);
  if (!options.report.empty()) {
    io::write_json(options.report,
                   {{"command", command_line()},
                    {"input", options.input},
                    {"output", options.output},
                    {"model", model_path(options)},
                    {"scales", options.scales.empty() ? model.config.scales : options.scales},
                    {"points", stats.points},
                    {"labels",
                     {{"non_edge", stats.labels[0]},
                      {"sharp", stats.labels[1]},
                      {"boundary", stats.labels[2]}}},
                    {"ranks", world.size()},
                    {"tiled", stats.tiled},
                    {"tiles", stats.tiles},
                    {"points_per_tile_limit", stats.points_per_tile_limit},
                    {"tile_side_m", stats.tile_side_m},
                    {"halo_m_max", stats.halo_m_max},
                    {"halo_points", stats.halo_points},
                    {"gate", gate},
                    {"timings_s",
                     {{"read", stats.read_s},
                      {"classify", stats.classify_s},
                      {"write", stats.write_s},
                      {"total", stats.total_s}}},
                    {"points_per_s", double(stats.points) / stats.total_s}});
  }
}

void run_classify(const ClassifyOptions& options) {
  if (is_las(options.input)) return run_classify_las(options);
  if (std::filesystem::path(options.output).extension() != ".ply") {
    throw Error(options.output, "", "the output must be a .ply file");
  }
  PointCloud cloud = io::read_point_cloud(options.input);
  const edges::Model model = load_model(options);
  log().info("{}: {} points; model {} ({} classes, scales {})", options.input, cloud.size(),
             model_path(options), model.config.classes, fmt::join(model.config.scales, ","));

  edges::Classification result;
  try {
    result = options.method == "angle-gap" ? classify_angle_gap(cloud)
                                           : edges::classify(cloud, model, options.scales);
  } catch (const Error& e) {
    throw Error(options.input, e.element(), e.reason());
  }
  const nlohmann::json gate =
      options.method == "angle-gap" ? nlohmann::json(nullptr) : gate_entry(result.gates);
  edges::attach_classification(cloud, result);
  // The picture is made before any file is written, and a failure writing it takes the PLY
  // back: the command leaves both outputs or neither.
  std::vector<std::uint8_t> preview;
  if (!options.png.empty()) preview = encode_point_preview(options.png, cloud);
  io::write_ply(options.output, cloud);
  if (!options.png.empty()) {
    try {
      write_png_bytes(options.png, preview);
    } catch (...) {
      std::error_code ignored;
      std::filesystem::remove(options.output, ignored);
      throw;
    }
  }

  std::size_t counts[3] = {0, 0, 0};
  for (const auto label : result.labels) ++counts[std::min<int>(label, 2)];
  const double total_s = result.features_s + result.inference_s;
  fmt::print(
      "{}: {} points -> {} non-edge, {} sharp, {} boundary in {:.3f} s "
      "(features {:.3f} s, network {:.3f} s, {:.0f} points/s) -> {}\n",
      options.input, cloud.size(), counts[0], counts[1], counts[2], total_s, result.features_s,
      result.inference_s, double(cloud.size()) / total_s, options.output);

  if (!options.png.empty()) fmt::print("picture -> {}\n", options.png);
  if (!options.report.empty()) {
    io::write_json(
        options.report,
        {{"command", command_line()},
         {"input", options.input},
         {"output", options.output},
         {"method", options.method},
         {"model", model_path(options)},
         {"scales", options.scales.empty() ? model.config.scales : options.scales},
         {"points", cloud.size()},
         {"labels", {{"non_edge", counts[0]}, {"sharp", counts[1]}, {"boundary", counts[2]}}},
         {"gate", gate},
         {"timings_s",
          {{"features", result.features_s}, {"network", result.inference_s}, {"total", total_s}}},
         {"points_per_s", double(cloud.size()) / total_s}});
  }
}

}  // namespace

void register_edges_classify(CLI::App& edges) {
  auto options = std::make_shared<ClassifyOptions>();
  CLI::App* command = edges.add_subcommand(
      "classify",
      "Label every point as non-edge (0), sharp edge (1) or boundary (2).\n"
      "Reads PLY, XYZ/PTS/TXT or PCD; only positions are used (no normals needed).\n"
      "Writes a binary PLY with uchar scalar_label, float scalar_p_sharp, float\n"
      "scalar_p_boundary (CloudCompare shows scalar_* as scalar fields) and red/green/blue\n"
      "(red = sharp, green = boundary) besides the input's own properties.\n"
      "LAS 1.2-1.4 (formats 0-10, uncompressed) is written back as LAS with Extra Bytes\n"
      "bounded_label, p_sharp, p_boundary; every input field (Classification included) and\n"
      "VLR is kept. A LAS cloud larger than --memory-limit is classified in tiles with\n"
      "measured halos (same labels as in one piece); under mpirun (MPI build) the tiles\n"
      "are shared by the ranks and one output file is written.\n"
      "Example: glint edges classify scan.ply -o scan_edges.ply --png scan_edges.png\n"
      "         glint edges classify survey.las -o survey_edges.las --memory-limit 2G\n"
      "         mpirun -n 4 glint edges classify survey.las -o survey_edges.las");
  command->add_option("input", options->input, "Input point cloud")->required();
  command->add_option("-o,--output", options->output, "Output PLY (or LAS for LAS input)")
      ->required()
      ->check(kOutputFile);
  command->add_option("--model", options->model,
                      "Model JSON (default: the shipped 3-class models/bounded-3c.json; "
                      "models/bounded-2c.json has no boundary class; "
                      "models/bounded-3c-cad-vertices.json is more accurate and slower on clean "
                      "CAD tessellations' vertices)");
  command
      ->add_option("--scales", options->scales,
                   "Override the model's neighbourhood sizes, largest first, e.g. 256,128,64,32 "
                   "for a cloud much denser than the training data")
      ->delimiter(',');
  command
      ->add_option("--method", options->method,
                   "bounded: the network; angle-gap: the boundary-only baseline of PCL and "
                   "Open3D (gap > 90 degrees among neighbours within 1.5 point spacings)")
      ->check(CLI::IsMember({"bounded", "angle-gap"}))
      ->capture_default_str();
  command->add_option("--memory-limit", options->memory_limit,
                      "LAS input: memory to stay within, e.g. 2G (default: 3/4 of the "
                      "machine's); a larger cloud is classified tile by tile");
  command->add_option("--tile-points", options->tile_points,
                      "LAS input: at most this many points per tile, halo included (default: "
                      "what --memory-limit allows)");
  command->add_flag("--no-gate", options->no_gate,
                    "A gated model's first network alone: skip the gate (e.g. for a survey "
                    "whose density varies so much that the shipped model's sampling gate "
                    "takes it for mesh vertices; docs/edges.md, \"gate\")");
  command->add_option("--png", options->png, "Also draw the labelled cloud to this PNG")
      ->check(kOutputFile);
  command->add_option("--report", options->report, "Write a JSON report (counts, timings)")
      ->check(kOutputFile);
  command->callback([options] { run_classify(*options); });
}

}  // namespace glint::app
