// glint edges synth: procedural labelled point clouds for training and testing BoundED.
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "edges/synth.h"
#include "io/json_report.h"
#include "io/ply.h"

namespace glint::app {
namespace {

struct SynthOptions {
  std::string output;
  int count = 100;
  std::uint64_t first = 0;
  std::vector<std::string> shapes;
  std::vector<std::string> exclude_shapes;
  edges::SynthParams params;
};

std::vector<edges::SynthShape> chosen_shapes(const SynthOptions& options) {
  const std::vector<std::string>& names =
      options.shapes.empty() ? edges::synth_shape_names() : options.shapes;
  for (const std::string& name : options.exclude_shapes) edges::parse_synth_shape(name);
  std::vector<edges::SynthShape> shapes;
  for (const std::string& name : names)
    if (std::find(options.exclude_shapes.begin(), options.exclude_shapes.end(), name) ==
        options.exclude_shapes.end())
      shapes.push_back(edges::parse_synth_shape(name));
  if (shapes.empty()) throw Error("--exclude-shapes", "", "every shape is excluded");
  return shapes;
}

void run_synth(SynthOptions options) {
  options.params.shapes = chosen_shapes(options);
  edges::check_synth_params(options.params);
  std::filesystem::create_directories(options.output);

  std::vector<nlohmann::json> descriptions(static_cast<std::size_t>(options.count));
  ProgressBar progress("synth", descriptions.size());
  parallel_for(descriptions.size(), [&](std::size_t i) {
    const std::uint64_t index = options.first + i;
    edges::SynthCloud cloud = edges::synthesize_cloud(options.params, index);
    const std::string file = fmt::format("synth-s{}-{:05d}-{}.ply", options.params.seed, index,
                                         cloud.description["shape"].get<std::string>());
    io::write_ply((std::filesystem::path(options.output) / file).string(), cloud.cloud);
    cloud.description["file"] = file;
    descriptions[i] = std::move(cloud.description);
    progress.advance();
  });
  progress.finish();

  std::size_t counts[3] = {0, 0, 0}, points = 0;
  for (const nlohmann::json& d : descriptions) {
    points += d["points"].get<std::size_t>();
    counts[0] += d["labels"]["non-edge"].get<std::size_t>();
    counts[1] += d["labels"]["sharp-edge"].get<std::size_t>();
    counts[2] += d["labels"]["boundary"].get<std::size_t>();
  }
  std::vector<std::string> shape_names;
  for (edges::SynthShape s : options.params.shapes)
    shape_names.push_back(edges::synth_shape_names()[static_cast<std::size_t>(s)]);
  const edges::SynthParams& p = options.params;
  io::write_json(
      (std::filesystem::path(options.output) / "manifest.json").string(),
      {{"command_line", command_line()},
       {"seed", p.seed},
       {"first_index", options.first},
       {"count", options.count},
       {"shapes", shape_names},
       {"points_range", {p.min_points, p.max_points}},
       {"noise_levels", p.noise_levels},
       {"outlier_probability", p.outlier_probability},
       {"abc_probability", p.abc_probability},
       {"gradient_probability", p.gradient_probability},
       {"band_spacings", p.band},
       {"boundary_band_spacings", p.boundary_band},
       {"sharp_angle_degrees", p.sharp_angle_deg},
       {"labels", {{"non-edge", counts[0]}, {"sharp-edge", counts[1]}, {"boundary", counts[2]}}},
       {"clouds", descriptions}});
  fmt::print("{}: {} clouds, {} points ({} non-edge, {} sharp, {} boundary), manifest.json\n",
             options.output, options.count, points, counts[0], counts[1], counts[2]);
}

}  // namespace

void register_edges_synth(CLI::App& edges) {
  auto options = std::make_shared<SynthOptions>();
  edges::SynthParams& p = options->params;
  CLI::App* command = edges.add_subcommand(
      "synth",
      "Generate labelled point clouds (creases, boxes, fractal cubes, cylinders, "
      "cones, sheets with holes, ...) for training and testing");
  command->footer(fmt::format(
      "Each cloud is one random shape ({}), scaled to a unit diagonal and rotated at random,\n"
      "written as binary PLY with a uchar 'label' (0 non-edge, 1 sharp edge, 2 boundary) to\n"
      "DIR/synth-s<seed>-<index>-<shape>.ply, plus DIR/manifest.json describing every cloud.\n"
      "Labels are exact: a point within --band point spacings of a crease whose normals turn by\n"
      ">= --sharp-angle is sharp; within --boundary-band of an open rim or a hole it is boundary.\n"
      "Cloud i of seed S is always the same, so a held-out set is another seed or --shapes.\n"
      "Examples:\n"
      "  glint edges synth -o data/train --count 400 --seed 1\n"
      "  glint edges synth -o data/heldout --count 100 --seed 2 --shapes annulus,hemisphere\n",
      fmt::join(edges::synth_shape_names(), ", ")));
  command->add_option("-o,--output", options->output, "Output folder (created)")->required();
  command->add_option("--count", options->count, "Number of clouds")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  command->add_option("--seed", p.seed, "Seed of the cloud stream")->capture_default_str();
  command->add_option("--first", options->first, "Index of the first cloud (to extend a set)")
      ->capture_default_str();
  command->add_option("--shapes", options->shapes, "Shapes to draw from (default: all)")
      ->delimiter(',');
  command->add_option("--exclude-shapes", options->exclude_shapes, "Shapes never drawn")
      ->delimiter(',');
  command->add_option("--min-points", p.min_points, "Fewest points per cloud")
      ->capture_default_str();
  command->add_option("--max-points", p.max_points, "Most points per cloud (log-uniform between)")
      ->capture_default_str();
  command
      ->add_option("--noise", p.noise_levels,
                   "Gaussian noise levels (sigma in point spacings); one is drawn per cloud")
      ->delimiter(',')
      ->capture_default_str();
  command
      ->add_option("--outliers", p.outlier_probability,
                   "Share of clouds with 2-15 % outliers displaced 2-15 spacings")
      ->capture_default_str();
  command
      ->add_option("--abc", p.abc_probability,
                   "Share of clouds sampled ABC-like (points exactly on the feature edges)")
      ->capture_default_str();
  command
      ->add_option("--gradient", p.gradient_probability,
                   "Share of clouds whose density varies across the shape")
      ->capture_default_str();
  command->add_option("--band", p.band, "Sharp label band half-width in point spacings")
      ->capture_default_str();
  command
      ->add_option("--boundary-band", p.boundary_band,
                   "Boundary label band half-width in point spacings")
      ->capture_default_str();
  command
      ->add_option("--sharp-angle", p.sharp_angle_deg,
                   "Normal change (degrees) from which a crease is a sharp edge")
      ->capture_default_str();
  command->callback([options] { run_synth(*options); });
}

}  // namespace glint::app
