// glint edges synth: procedural labelled point clouds for training and testing BoundED.
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "cad/synth.h"
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
  std::string kind = "procedural";
  int count = 100;
  std::uint64_t first = 0;
  std::vector<std::string> shapes;
  std::vector<std::string> exclude_shapes;
  edges::SynthParams params;
  // --kind cad
  std::vector<std::string> recipes;
  std::vector<std::string> samplings{"vertices", "uniform", "scan"};
  cad::CadSynthParams cad;
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

// --kind cad takes the shared flags (points, noise, outliers, bands, angle, seed) from the
// procedural parameters.
cad::CadSynthParams cad_params(const SynthOptions& options) {
  cad::CadSynthParams c = options.cad;
  const edges::SynthParams& p = options.params;
  c.part.seed = p.seed;
  for (const std::string& name : options.recipes)
    c.part.recipes.push_back(cad::parse_part_recipe(name));
  c.samplings.clear();
  for (const std::string& name : options.samplings)
    c.samplings.push_back(cad::parse_sampling(name));
  c.min_points = p.min_points;
  c.max_points = p.max_points;
  c.noise_levels = p.noise_levels;
  c.outlier_probability = p.outlier_probability;
  c.band = p.band;
  c.boundary_band = p.boundary_band;
  c.sharp_angle_deg = p.sharp_angle_deg;
  cad::check_cad_synth_params(c);
  return c;
}

void run_synth(SynthOptions options) {
  const bool cad_kind = options.kind == "cad";
  cad::CadSynthParams cad;
  if (cad_kind) {
    cad = cad_params(options);
  } else {
    options.params.shapes = chosen_shapes(options);
    edges::check_synth_params(options.params);
  }
  std::filesystem::create_directories(options.output);

  std::vector<nlohmann::json> descriptions(static_cast<std::size_t>(options.count));
  ProgressBar progress("synth", descriptions.size());
  parallel_for(descriptions.size(), [&](std::size_t i) {
    const std::uint64_t index = options.first + i;
    edges::SynthCloud cloud = cad_kind ? cad::synthesize_cad_cloud(cad, index)
                                       : edges::synthesize_cloud(options.params, index);
    const std::string file =
        fmt::format("{}-s{}-{:05d}-{}.ply", cad_kind ? "cad" : "synth", options.params.seed, index,
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
  nlohmann::json kind_parameters;
  if (cad_kind) {
    std::vector<std::string> recipes;
    for (cad::PartRecipe r : cad.part.recipes)
      recipes.push_back(cad::part_recipe_names()[static_cast<std::size_t>(r)]);
    if (recipes.empty()) recipes = cad::part_recipe_names();
    kind_parameters = {{"recipes", recipes},
                       {"samplings", options.samplings},
                       {"max_features", cad.part.max_features},
                       {"fillet_probability", cad.part.fillet_probability},
                       {"chamfer_probability", cad.part.chamfer_probability},
                       {"shell_probability", cad.part.shell_probability},
                       {"plane_cut_probability", cad.part.plane_cut_probability},
                       {"faces_removed_probability", cad.part.faces_removed_probability},
                       {"max_viewpoints", cad.max_viewpoints}};
  } else {
    kind_parameters = {{"shapes", shape_names},
                       {"abc_probability", p.abc_probability},
                       {"gradient_probability", p.gradient_probability}};
  }
  io::write_json(
      (std::filesystem::path(options.output) / "manifest.json").string(),
      {{"command_line", command_line()},
       {"kind", options.kind},
       {"seed", p.seed},
       {"first_index", options.first},
       {"count", options.count},
       {"kind_parameters", kind_parameters},
       {"points_range", {p.min_points, p.max_points}},
       {"noise_levels", p.noise_levels},
       {"outlier_probability", p.outlier_probability},
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
      "Generate labelled point clouds for training and testing: procedural shapes (creases, "
      "boxes, fractal cubes, cylinders, sheets with holes, ...) or CAD-kernel parts (--kind cad)");
  command->footer(fmt::format(
      "--kind procedural (default): each cloud is one random shape ({}), scaled to a unit\n"
      "diagonal and rotated at random, written as binary PLY with a uchar 'label' (0 non-edge,\n"
      "1 sharp edge, 2 boundary) to DIR/synth-s<seed>-<index>-<shape>.ply, plus\n"
      "DIR/manifest.json describing every cloud. Labels are exact: a point within --band point\n"
      "spacings of a crease whose normals turn by >= --sharp-angle is sharp; within\n"
      "--boundary-band of an open rim or a hole it is boundary.\n"
      "\n"
      "--kind cad: each cloud is a random part built on the OpenCASCADE kernel (recipes: {}):\n"
      "a block, plate, extruded or turned (revolved) random profile or cylinder, with holes,\n"
      "pockets, slots and bosses (booleans), fillets and chamfers of random sizes, sometimes\n"
      "hollowed; --plane-cut / --faces-removed open it. It is tessellated by BRepMesh with random\n"
      "deflections and sampled one of --sampling ways: 'vertices' (the mesh nodes, as ABC and\n"
      "PCEDNet clouds are: dense on curved faces, sparse on planes), 'uniform' (on the surface)\n"
      "or 'scan' (1..--viewpoints scanners casting scan lines: density falls with range, "
      "occlusion\n"
      "holes). Labels come from the B-rep: an edge whose two faces' normals turn by >=\n"
      "--sharp-angle is sharp (fillets' tangent edges are not), an edge of one face is an open\n"
      "border; scans add the borders of what no scanner sees. --noise is along the normal, in\n"
      "the cloud's median spacing. Files are DIR/cad-s<seed>-<index>-cad-<recipe>-<sampling>.ply;\n"
      "manifest.json holds every part's recipe (operations done and skipped) and sampling.\n"
      "\n"
      "Cloud i of seed S is always the same, so a held-out set is another seed, --shapes or\n"
      "--recipes. Examples:\n"
      "  glint edges synth -o data/train --count 400 --seed 1\n"
      "  glint edges synth -o data/heldout --count 100 --seed 2 --shapes annulus,hemisphere\n"
      "  glint edges synth --kind cad -o data/cad --count 200 --seed 3 --noise 0,0.5,1\n"
      "  glint edges synth --kind cad -o data/cut --count 50 --seed 9 --plane-cut 1 \\\n"
      "      --sampling uniform\n",
      fmt::join(edges::synth_shape_names(), ", "), fmt::join(cad::part_recipe_names(), ", ")));
  command->add_option("--kind", options->kind, "procedural or cad")
      ->check(CLI::IsMember({"procedural", "cad"}))
      ->capture_default_str();
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
                   "Share of clouds with outliers displaced 2-15 spacings (2-15 % of the points; "
                   "cad: 1-5 %)")
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
  cad::CadSynthParams& c = options->cad;
  command
      ->add_option("--recipes", options->recipes, "cad: part recipes to draw from (default: all)")
      ->delimiter(',');
  command->add_option("--sampling", options->samplings, "cad: samplings drawn per cloud")
      ->delimiter(',')
      ->capture_default_str();
  command
      ->add_option("--max-features", c.part.max_features,
                   "cad: most holes / pockets / slots / bosses per part")
      ->capture_default_str();
  command
      ->add_option("--fillets", c.part.fillet_probability,
                   "cad: share of parts with filleted edges")
      ->capture_default_str();
  command
      ->add_option("--chamfers", c.part.chamfer_probability,
                   "cad: share of parts with chamfered edges")
      ->capture_default_str();
  command
      ->add_option("--shells", c.part.shell_probability,
                   "cad: share of parts hollowed out (top face removed)")
      ->capture_default_str();
  command
      ->add_option("--plane-cut", c.part.plane_cut_probability,
                   "cad: share of parts cut open by a random plane (no cap)")
      ->capture_default_str();
  command
      ->add_option("--faces-removed", c.part.faces_removed_probability,
                   "cad: share of parts with 1-2 faces removed")
      ->capture_default_str();
  command->add_option("--viewpoints", c.max_viewpoints, "cad scan: most scanner positions")
      ->capture_default_str();
  command
      ->add_option("--time-limit", c.part.operation_time_limit_s,
                   "cad: seconds one kernel operation may take before it is skipped")
      ->capture_default_str();
  command->callback([options] { run_synth(*options); });
}

}  // namespace glint::app
