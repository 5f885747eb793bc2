// glint edges label: ground-truth labels for a user's own CAD part (STEP in, labelled cloud out).
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "cad/sample.h"
#include "cad/step.h"
#include "cli_support.h"
#include "commands.h"
#include "io/json_report.h"
#include "io/ply.h"

namespace glint::app {
namespace {

struct LabelOptions {
  std::string input;
  std::string output;
  std::string sampling = "uniform";
  std::string report;
  cad::SampleParams params;
};

void run_label(LabelOptions options) {
  options.params.sampling = cad::parse_sampling(options.sampling);
  cad::check_sample_params(options.params);
  const TopoDS_Shape shape = cad::read_step(options.input);
  cad::LabelledCloud labelled = cad::sample_shape(shape, options.params);
  io::write_ply(options.output, labelled.cloud);
  const nlohmann::json& d = labelled.description;
  fmt::print(
      "{}: {} points ({} non-edge, {} sharp, {} boundary), median spacing {:.4g}; B-rep "
      "edges: {} sharp, {} smooth, {} boundary\n",
      options.output, d["points"].get<std::size_t>(), d["labels"]["non-edge"].get<std::size_t>(),
      d["labels"]["sharp-edge"].get<std::size_t>(), d["labels"]["boundary"].get<std::size_t>(),
      d["median_spacing"].get<double>(), d["brep_edges"]["sharp"].get<int>(),
      d["brep_edges"]["smooth"].get<int>(), d["brep_edges"]["boundary"].get<int>());
  if (!options.report.empty())
    io::write_json(options.report, {{"command_line", command_line()},
                                    {"input", options.input},
                                    {"output", options.output},
                                    {"seed", options.params.seed},
                                    {"cloud", d}});
}

}  // namespace

void register_edges_label(CLI::App& edges) {
  auto options = std::make_shared<LabelOptions>();
  cad::SampleParams& p = options->params;
  CLI::App* command = edges.add_subcommand(
      "label",
      "Make a labelled ground-truth cloud from a CAD part (STEP): sharp edges and open "
      "borders from the B-rep");
  command->footer(
      "Reads every shape of PART.step (OpenCASCADE), samples its surface and labels each point\n"
      "from the B-rep, never from the points: 1 (sharp) within --band local spacings of an edge\n"
      "whose two faces' normals turn by >= --sharp-angle degrees somewhere along it (fillets and\n"
      "other tangent blends are not sharp; a 45-degree chamfer edge is), 2 (boundary) within\n"
      "--boundary-band spacings of an edge with one face (open surfaces, removed faces), 0\n"
      "otherwise. The output PLY has x y z and uchar 'label', in the STEP file's coordinates\n"
      "(millimetres), ready for `glint edges eval` or `glint edges train`.\n"
      "Samplings: 'uniform' (--points random points on the surface), 'vertices' (the nodes of\n"
      "the kernel's tessellation with --deflection, as ABC clouds are), 'scan' (1..--viewpoints\n"
      "simulated scanners: scan lines, falling density, occlusion holes; what no scanner sees\n"
      "borders the cloud and is labelled boundary). --noise moves points along the normal.\n"
      "Examples:\n"
      "  glint edges label bracket.step -o bracket.ply\n"
      "  glint edges label bracket.step -o bracket-mesh.ply --sampling vertices --deflection "
      "0.001\n"
      "  glint edges label bracket.step -o bracket-scan.ply --sampling scan --viewpoints 2 "
      "--noise 0.5\n");
  command->add_option("part", options->input, "STEP file (.step / .stp)")->required();
  command->add_option("-o,--output", options->output, "Labelled PLY to write")
      ->required()
      ->check(kOutputFile);
  command->add_option("--sampling", options->sampling, "vertices, uniform or scan")
      ->check(CLI::IsMember(cad::sampling_names()))
      ->capture_default_str();
  command
      ->add_option("--points", p.points,
                   "uniform / scan: points to draw; vertices: most points kept")
      ->capture_default_str();
  command
      ->add_option("--deflection", p.linear_deflection,
                   "vertices: tessellation chord deflection, fraction of the bounding-box "
                   "diagonal")
      ->capture_default_str();
  command
      ->add_option("--angular-deflection", p.angular_deflection_deg,
                   "vertices: tessellation angular deflection, degrees")
      ->capture_default_str();
  command
      ->add_option("--plane-edge", p.plane_edge_fraction,
                   "vertices: split mesh edges longer than this fraction of the diagonal (0: "
                   "keep the kernel's mesh)")
      ->capture_default_str();
  command->add_option("--viewpoints", p.viewpoints, "scan: most scanner positions")
      ->capture_default_str();
  command->add_option("--band", p.band, "Sharp label half-width, local point spacings")
      ->capture_default_str();
  command
      ->add_option("--boundary-band", p.boundary_band,
                   "Boundary label half-width, local point spacings")
      ->capture_default_str();
  command
      ->add_option("--sharp-angle", p.sharp_angle_deg,
                   "Normal turn (degrees) along an edge from which it is sharp")
      ->capture_default_str();
  command->add_option("--noise", p.noise, "Gaussian noise along the normal, median spacings")
      ->capture_default_str();
  command->add_option("--outliers", p.outlier_share, "Share of points displaced 2-15 spacings")
      ->capture_default_str();
  command->add_option("--seed", p.seed, "Seed of the sampling and noise")->capture_default_str();
  command->add_option("--report", options->report, "JSON report (edge classes, label counts)");
  command->callback([options] { run_label(*options); });
}

}  // namespace glint::app
