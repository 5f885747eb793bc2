// glint edges label: ground-truth labels for a user's own CAD part (STEP) or triangle mesh (OBJ,
// PLY), labelled cloud out.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "cad/abc_features.h"
#include "cad/part.h"
#include "cad/sample.h"
#include "cad/step.h"
#include "cad/surface_mesh.h"
#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "io/codec.h"
#include "io/json_report.h"
#include "io/ply.h"
#include "render/mesh_loader.h"

namespace glint::app {
namespace {

struct LabelOptions {
  std::string input;
  std::string output;
  std::string sampling = "uniform";
  std::string report;
  std::vector<double> cut_plane;  // normal x, y, z and an optional offset in diagonals
  std::string cut_mode = "clip";
  std::string abc_features;  // an ABC features YAML whose sharp curves replace the angle
  bool deflection_given = false;
  bool cut_mode_given = false;
  cad::SampleParams params;
};

// Whether the input is a STEP part (else a mesh); throws for any other extension.
bool is_step(const std::string& path) {
  const std::string extension = io::lowercase(std::filesystem::path(path).extension().string());
  if (extension == ".step" || extension == ".stp") return true;
  if (extension == ".obj" || extension == ".ply") return false;
  throw Error(path, "", "unknown format (expected .step, .stp, .obj or .ply)");
}

// The plane of --cut-plane: through the bounding box's centre moved `offset` diagonals along
// the normal.
struct CutPlane {
  Eigen::Vector3d point, normal;

  nlohmann::json json() const {
    return {{"point", io::vector_json(point)}, {"normal", io::vector_json(normal)}};
  }
};

CutPlane cut_plane(const std::vector<double>& values, const Eigen::Vector3d& low,
                   const Eigen::Vector3d& high) {
  const Eigen::Vector3d normal(values[0], values[1], values[2]);
  if (!(normal.norm() > 0) || !normal.allFinite())
    throw Error("--cut-plane", fmt::format("{}", fmt::join(values, ",")),
                "the normal must be finite and non-zero");
  const double offset = values.size() > 3 ? values[3] : 0.0;
  return {0.5 * (low + high) + offset * (high - low).norm() * normal.normalized(),
          normal.normalized()};
}

cad::LabelledCloud label_mesh(const LabelOptions& options, nlohmann::json& cut) {
  if (options.deflection_given)
    throw Error(options.input, "--deflection",
                "applies to STEP parts, whose surfaces glint tessellates; a mesh is sampled as "
                "it is (--plane-edge splits its long edges)");
  const render::TriangleMesh loaded = render::load_mesh(options.input);
  cad::SurfaceMesh mesh;
  mesh.vertices.reserve(loaded.vertices.size());
  for (const Eigen::Vector3f& v : loaded.vertices) mesh.vertices.push_back(v.cast<double>());
  for (const Eigen::Vector3i& t : loaded.triangles) mesh.triangles.push_back({t[0], t[1], t[2]});
  std::optional<cad::EdgeClasses> sharp_curves;
  if (!options.abc_features.empty())
    sharp_curves = cad::read_abc_sharp_curves(options.abc_features, mesh.vertices);
  if (!options.cut_plane.empty()) {
    Eigen::Vector3d low = mesh.vertices.front(), high = low;
    for (const Eigen::Vector3d& v : mesh.vertices) low = low.cwiseMin(v), high = high.cwiseMax(v);
    const CutPlane plane = cut_plane(options.cut_plane, low, high);
    try {
      mesh = cad::cut_mesh(mesh, plane.point, plane.normal,
                           options.cut_mode == "drop" ? cad::CutMode::drop : cad::CutMode::clip);
    } catch (const Error& e) {
      throw Error(options.input, "--cut-plane", e.reason());
    }
    if (sharp_curves) cad::cut_segments(sharp_curves->segments, plane.point, plane.normal);
    cut = plane.json();
    cut["mode"] = options.cut_mode;
  }
  return cad::sample_mesh(std::move(mesh), options.params, options.input,
                          sharp_curves ? &*sharp_curves : nullptr);
}

cad::LabelledCloud label_step(const LabelOptions& options, nlohmann::json& cut) {
  if (!options.abc_features.empty())
    throw Error(options.input, "--abc-features",
                "applies to an ABC mesh (.obj); a STEP part's sharp edges come from its B-rep");
  if (options.cut_mode_given)
    throw Error(options.input, "--cut-mode",
                "applies to meshes; a STEP part is cut on its B-rep, where the cut is exact");
  TopoDS_Shape shape = cad::read_step(options.input);
  if (!options.cut_plane.empty()) {
    const auto [low, high] = cad::shape_bounds(shape);
    const CutPlane plane = cut_plane(options.cut_plane, low, high);
    try {
      shape = cad::cut_open(shape, plane.point.data(), plane.normal.data());
    } catch (const Error& e) {
      throw Error(options.input, "--cut-plane", e.reason());
    }
    cut = plane.json();
  }
  return cad::sample_shape(shape, options.params);
}

void run_label(LabelOptions options) {
  options.params.sampling = cad::parse_sampling(options.sampling);
  cad::check_sample_params(options.params);
  nlohmann::json cut;
  const bool step = is_step(options.input);
  cad::LabelledCloud labelled = step ? label_step(options, cut) : label_mesh(options, cut);
  io::write_ply(options.output, labelled.cloud);
  const nlohmann::json& d = labelled.description;
  const nlohmann::json& feature_edges = d[step ? "brep_edges" : "mesh_edges"];
  fmt::print(
      "{}: {} points ({} non-edge, {} sharp, {} boundary), median spacing {:.4g}; {} edges: {} "
      "sharp, {} smooth, {} boundary\n",
      options.output, d["points"].get<std::size_t>(), d["labels"]["non-edge"].get<std::size_t>(),
      d["labels"]["sharp-edge"].get<std::size_t>(), d["labels"]["boundary"].get<std::size_t>(),
      d["median_spacing"].get<double>(), step ? "B-rep" : "mesh", feature_edges["sharp"].get<int>(),
      feature_edges["smooth"].get<int>(), feature_edges["boundary"].get<int>());
  if (!options.report.empty())
    io::write_json(options.report, {{"command_line", command_line()},
                                    {"input", options.input},
                                    {"output", options.output},
                                    {"seed", options.params.seed},
                                    {"cut_plane", cut},
                                    {"cloud", d}});
}

}  // namespace

void register_edges_label(CLI::App& edges) {
  auto options = std::make_shared<LabelOptions>();
  cad::SampleParams& p = options->params;
  CLI::App* command = edges.add_subcommand(
      "label",
      "Make a labelled ground-truth cloud from a CAD part (STEP) or a triangle mesh (OBJ, PLY): "
      "sharp edges and open borders from the B-rep or the mesh's edges");
  command->footer(
      "Reads every shape of PART.step (OpenCASCADE), samples its surface and labels each point\n"
      "from the B-rep, never from the points: 1 (sharp) within --band local spacings of an edge\n"
      "whose two faces' normals turn by >= --sharp-angle degrees somewhere along it (fillets and\n"
      "other tangent blends are not sharp; a 45-degree chamfer edge is), 2 (boundary) within\n"
      "--boundary-band spacings of an edge with one face (open surfaces, removed faces), 0\n"
      "otherwise. The output PLY has x y z and uchar 'label', in the input's coordinates\n"
      "(a STEP file's in millimetres), ready for `glint edges eval` or `glint edges train`.\n"
      "A mesh (.obj, .ply with faces; an ABC model's OBJ, say) is labelled the same way from its\n"
      "own edges: an edge is sharp where its two triangles' normals turn by >= --sharp-angle, a\n"
      "boundary where it has one triangle. That suits meshes whose curved parts are finely\n"
      "tessellated (a few degrees between neighbouring triangles); on a coarse mesh, creases of\n"
      "the tessellation itself pass the angle. For an ABC model, --abc-features takes the\n"
      "sharp flags of its features file instead (a vertex on a sharp curve is sharp), the\n"
      "ground truth ABC-trained detectors use.\n"
      "Samplings: 'uniform' (--points random points on the surface), 'vertices' (the nodes of\n"
      "the kernel's tessellation with --deflection, as ABC clouds are, or the mesh's own\n"
      "vertices), 'scan' (1..--viewpoints simulated scanners: scan lines, falling density,\n"
      "occlusion holes; what no scanner sees borders the cloud and is labelled boundary).\n"
      "--noise moves points along the normal. --cut-plane opens the surface (no cap), as real\n"
      "data is open: the cut's border is labelled boundary.\n"
      "Examples:\n"
      "  glint edges label bracket.step -o bracket.ply\n"
      "  glint edges label bracket.step -o bracket-mesh.ply --sampling vertices --deflection "
      "0.001\n"
      "  glint edges label bracket.step -o bracket-scan.ply --sampling scan --viewpoints 2 "
      "--noise 0.5\n"
      "  glint edges label part.obj -o part-open.ply --sampling vertices --cut-plane 0,0,1,0.1\n"
      "  glint edges label 00000050_..._trimesh_000.obj --abc-features "
      "00000050_..._features_000.yml "
      "-o abc.ply --sampling vertices\n");
  command->add_option("part", options->input, "STEP file (.step / .stp) or mesh (.obj / .ply)")
      ->required();
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
  CLI::Option* deflection =
      command
          ->add_option("--deflection", p.linear_deflection,
                       "STEP, vertices: tessellation chord deflection, fraction of the "
                       "bounding-box diagonal")
          ->capture_default_str();
  CLI::Option* angular_deflection =
      command
          ->add_option("--angular-deflection", p.angular_deflection_deg,
                       "STEP, vertices: tessellation angular deflection, degrees")
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
  command
      ->add_option("--cut-plane", options->cut_plane,
                   "NX,NY,NZ[,OFFSET]: keep the surface on the normal's side of the plane through "
                   "the bounding box's centre moved OFFSET box diagonals along the normal")
      ->delimiter(',')
      ->expected(3, 4);
  CLI::Option* cut_mode =
      command
          ->add_option("--cut-mode", options->cut_mode,
                       "mesh: 'clip' the triangles the plane crosses at the plane, or 'drop' them "
                       "(a jagged border, as deleting the points on one side leaves)")
          ->check(CLI::IsMember({"clip", "drop"}))
          ->capture_default_str();
  command->add_option("--abc-features", options->abc_features,
                      "mesh: an ABC features file (.yml) whose curves flagged sharp are the sharp "
                      "edges (instead of --sharp-angle); boundaries stay the mesh's open borders");
  command->add_option("--report", options->report, "JSON report (edge classes, label counts)");
  command->callback([options, deflection, angular_deflection, cut_mode] {
    options->deflection_given = deflection->count() + angular_deflection->count() > 0;
    options->cut_mode_given = cut_mode->count() > 0;
    run_label(*options);
  });
}

}  // namespace glint::app
