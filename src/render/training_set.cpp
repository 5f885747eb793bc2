#include "render/training_set.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/timer.h"
#include "io/json_report.h"
#include "render/builtin_scenes.h"
#include "render/mesh_loader.h"
#include "render/perceptual.h"
#include "render/random.h"
#include "render/sequence_writer.h"
#include "render/trajectories.h"

namespace glint::render {
namespace fs = std::filesystem;
namespace {

// Training shapes that are meshes, and their files in DATA/meshes.
const std::map<std::string, std::string>& mesh_files() {
  static const std::map<std::string, std::string> files = {{"bunny", "stanford-bunny.obj"},
                                                           {"spot", "spot.obj"},
                                                           {"teapot", "teapot.obj"},
                                                           {"suzanne", "suzanne.obj"},
                                                           {"cow", "cow.obj"},
                                                           {"fandisk", "fandisk.obj"},
                                                           {"homer", "homer.obj"},
                                                           {"rocker-arm", "rocker-arm.obj"}};
  return files;
}

// Bounding-box extent of a mesh normalised to height 1 (scene.h), loaded once per file.
Eigen::Vector3d unit_height_extent(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, Eigen::Vector3d> cache;
  const std::lock_guard lock(mutex);
  const auto cached = cache.find(path);
  if (cached != cache.end()) return cached->second;
  TriangleMesh mesh = load_mesh(path);
  normalise_mesh(mesh, 1.0);
  Eigen::Vector3f low = mesh.vertices.front(), high = low;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  return cache[path] = (high - low).cast<double>();
}

std::vector<std::string> environment_maps(const std::string& data_dir) {
  std::vector<std::string> maps;
  const fs::path folder = fs::path(data_dir) / "envmaps";
  if (fs::is_directory(folder))
    for (const fs::directory_entry& entry : fs::directory_iterator(folder))
      if (entry.path().extension() == ".hdr") maps.push_back(entry.path().string());
  std::sort(maps.begin(), maps.end());
  return maps;
}

std::uint64_t sequence_seed(std::uint64_t seed, int index) {
  return mix64(mix64(seed) ^ static_cast<std::uint64_t>(index));
}

// The object (id 1), resting on y = 0 and centred on the y axis, and its bounding sphere.
struct PlacedObject {
  Object object;
  Eigen::Vector3d centre;
  double bounding_radius_m = 0;
};

PlacedObject training_object(const std::string& shape, const TrainingSetParams& params,
                             SeededDraw& draw) {
  const double height_m = draw.uniform(0.3, 0.8);
  PlacedObject placed;
  placed.centre = {0, height_m / 2, 0};
  Object& object = placed.object;
  object.name = shape;
  object.id = 1;
  if (shape == "sphere") {
    object.shape = ShapeKind::sphere;
    object.size = Eigen::Vector3d::Constant(height_m / 2);
    placed.bounding_radius_m = height_m / 2;
  } else if (shape == "box") {
    object.shape = ShapeKind::box;
    object.size = {height_m * draw.uniform(0.5, 1.2), height_m, height_m * draw.uniform(0.5, 1.2)};
    placed.bounding_radius_m = object.size.norm() / 2;
  } else {
    object.shape = ShapeKind::mesh;
    object.mesh_path = (fs::path(params.data_dir) / "meshes" / mesh_files().at(shape)).string();
    object.size = Eigen::Vector3d::Constant(height_m);
    placed.bounding_radius_m = height_m * unit_height_extent(object.mesh_path).norm() / 2;
  }
  if (object.shape != ShapeKind::mesh) object.transform.translate(placed.centre);
  object.transform.rotate(Eigen::AngleAxisd(draw.uniform(0, 2 * M_PI), Eigen::Vector3d::UnitY()));
  object.material.ward = sample_training_material(params.ranges, draw);
  return placed;
}

// Lights within +-110 deg (azimuth) of the camera's mean viewing direction, so most views see
// lit surfaces as a hand-held capture would, but grazing and back light also occur.
std::vector<PointLight> training_lights(const Eigen::Vector3d& centre, double bounding_radius_m,
                                        double camera_azimuth_rad, SeededDraw& draw) {
  std::vector<PointLight> lights(static_cast<std::size_t>(draw.integer(1, 3)));
  for (PointLight& light : lights) {
    const double distance = draw.uniform(std::max(1.0, bounding_radius_m + 0.3), 3.0);
    const double elevation = draw.uniform(10, 80) * M_PI / 180;
    const double azimuth = camera_azimuth_rad + draw.uniform(-110, 110) * M_PI / 180;
    light.position = centre + distance * Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth),
                                                         std::sin(elevation),
                                                         std::cos(elevation) * std::cos(azimuth));
    const double irradiance = draw.uniform(1.5, 4);
    for (int c = 0; c < 3; ++c)
      light.intensity[c] = float(irradiance * distance * distance * draw.uniform(0.85, 1.0));
  }
  return lights;
}

std::vector<Pose> training_arc(const Intrinsics& intrinsics, const Eigen::Vector3d& centre,
                               double bounding_radius_m, int frames, SeededDraw& draw) {
  const double half_fov = std::atan(intrinsics.height / 2.0 / intrinsics.fy);
  const double distance = bounding_radius_m / std::sin(draw.uniform(0.6, 0.9) * half_fov);
  const double elevation = draw.uniform(5, 45) * M_PI / 180;
  OrbitParams orbit;
  orbit.ring = {Eigen::Vector3d::Zero(), distance * std::cos(elevation),
                centre.y() + distance * std::sin(elevation), centre};
  orbit.start_deg = draw.uniform(0, 360);
  orbit.arc_deg = draw.uniform(40, 120);
  orbit.frames = frames;
  return orbit_trajectory(orbit);
}

nlohmann::json sequence_json(const Scene& scene, const std::string& folder) {
  const Object& object = scene.objects.front();
  const WardMaterial& ward = object.material.ward;
  const PerceptualWard perceptual = to_perceptual(ward);
  nlohmann::json lights = nlohmann::json::array();
  for (const PointLight& light : scene.lights)
    lights.push_back({{"position", io::vector_json(light.position)},
                      {"intensity", io::vector_json(light.intensity)}});
  nlohmann::json environment = nullptr;
  if (scene.environment)
    environment = {{"path", scene.environment->path},
                   {"scale", scene.environment->scale},
                   {"rotation_deg", scene.environment->rotation_deg}};
  return {{"folder", folder},
          {"shape", object.name},
          {"size", io::vector_json(object.size)},
          {"material",
           {{"kd", io::vector_json(ward.kd)},
            {"ks", io::vector_json(ward.ks)},
            {"alpha", ward.alpha},
            {"lab", io::vector_json(perceptual.lab)},
            {"c", io::vector_json(perceptual.c)},
            {"d", perceptual.d}}},
          {"lights", lights},
          {"environment", environment}};
}

std::string sequence_folder(int index) { return fmt::format("seq_{:05d}", index); }

// Leftovers of an interrupted write_sequence ("seq_00012.partial-<pid>").
void remove_partial_sequences(const fs::path& out_dir) {
  std::vector<fs::path> partial;
  for (const fs::directory_entry& entry : fs::directory_iterator(out_dir))
    if (entry.path().filename().string().find(".partial-") != std::string::npos)
      partial.push_back(entry.path());
  for (const fs::path& path : partial) fs::remove_all(path);
}

void check_resumable(const fs::path& index_path, const nlohmann::json& parameters) {
  if (!fs::exists(index_path)) return;
  const nlohmann::json previous = io::read_json(index_path.string());
  if (previous.value("parameters", nlohmann::json()) != parameters)
    throw Error(index_path.string(), "parameters",
                "the folder holds a training set made with other parameters; use another "
                "folder or the same options");
}

}  // namespace

double SeededDraw::uniform() {
  state_ += 0x9e3779b97f4a7c15ull;
  return static_cast<double>(mix64(state_) >> 11) * 0x1.0p-53;
}
double SeededDraw::uniform(double low, double high) { return low + (high - low) * uniform(); }
int SeededDraw::integer(int low, int high) {
  return std::min(high, low + static_cast<int>(uniform() * (high - low + 1)));
}
double SeededDraw::log_uniform(double low, double high) {
  return std::exp(uniform(std::log(low), std::log(high)));
}

const std::vector<std::string>& training_shape_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = {"sphere", "box"};
    for (const auto& [name, file] : mesh_files()) all.push_back(name);
    return all;
  }();
  return names;
}

WardMaterial sample_training_material(const MaterialRanges& ranges, SeededDraw& draw) {
  WardMaterial material;
  const bool chroma_by_radius =
      ranges.near_grey_share > 0 && draw.uniform(0, 1) < ranges.near_grey_share;
  do {
    const float lightness = float(draw.uniform(25, 96));
    Eigen::Vector2f ab;
    if (chroma_by_radius) {
      const double chroma = draw.uniform(0, 80), hue = draw.uniform(0, 2 * M_PI);
      ab = {float(chroma * std::cos(hue)), float(chroma * std::sin(hue))};
    } else {
      ab = {float(draw.uniform(-80, 80)), float(draw.uniform(-80, 80))};
    }
    material.kd = lab_to_linear_rgb({lightness, ab.x(), ab.y()});
  } while (material.kd.minCoeff() < ranges.kd_min || material.kd.maxCoeff() > ranges.kd_max);
  const float c = float(draw.uniform(0, ranges.c_max));
  for (int i = 0; i < 3; ++i) {
    const float half_kd_root = std::cbrt(material.kd[i] / 2);
    const float c_limit = std::cbrt(1 - material.kd[i] / 2) - half_kd_root;  // kd + ks = 1
    const float ks = std::pow(std::min(c, c_limit) + half_kd_root, 3.0f) - material.kd[i] / 2;
    material.ks[i] = std::clamp(ks, 0.0f, 1 - material.kd[i]);
  }
  material.alpha = float(draw.log_uniform(ranges.alpha_min, ranges.alpha_max));
  return material;
}

Scene make_training_scene(const TrainingSetParams& params, int index) {
  const std::vector<std::string>& shapes =
      params.shapes.empty() ? training_shape_names() : params.shapes;
  for (const std::string& shape : shapes)
    if (std::find(training_shape_names().begin(), training_shape_names().end(), shape) ==
        training_shape_names().end())
      throw Error(
          shape, "",
          fmt::format("unknown training shape ({})", fmt::join(training_shape_names(), ", ")));
  SeededDraw draw(sequence_seed(params.seed, index));
  Scene scene;
  scene.seed = sequence_seed(params.seed, index);
  scene.camera.intrinsics = sensor_intrinsics(params.width, params.height);
  const std::string& shape =
      shapes[static_cast<std::size_t>(draw.integer(0, int(shapes.size()) - 1))];
  const PlacedObject placed = training_object(shape, params, draw);
  scene.objects.push_back(placed.object);
  scene.trajectory = training_arc(scene.camera.intrinsics, placed.centre, placed.bounding_radius_m,
                                  params.frames, draw);
  const Eigen::Vector3d middle_view =
      scene.trajectory[scene.trajectory.size() / 2].translation() - placed.centre;
  scene.lights = training_lights(placed.centre, placed.bounding_radius_m,
                                 std::atan2(middle_view.x(), middle_view.z()), draw);
  if (draw.uniform() < params.environment_probability) {
    const std::vector<std::string> maps = environment_maps(params.data_dir);
    if (maps.empty())
      throw Error((fs::path(params.data_dir) / "envmaps").string(), "",
                  "no .hdr environment maps (set --data, or the environment probability to 0)");
    Environment environment;
    environment.path = maps[static_cast<std::size_t>(draw.integer(0, int(maps.size()) - 1))];
    environment.rotation_deg = float(draw.uniform(0, 360));
    environment.scale = float(draw.uniform(0.1, 0.4));
    environment.samples = 32;
    scene.environment = environment;
  }
  return scene;
}

nlohmann::json training_set_parameters_json(const TrainingSetParams& params) {
  const MaterialRanges& r = params.ranges;
  nlohmann::json parameters = {
      {"seed", params.seed},
      {"frames", params.frames},
      {"width", params.width},
      {"height", params.height},
      {"shapes", params.shapes.empty() ? training_shape_names() : params.shapes},
      {"environment_probability", params.environment_probability},
      {"ground_truth", params.ground_truth},
      {"ranges",
       {{"kd", {r.kd_min, r.kd_max}},
        {"c", {0.0f, r.c_max}},
        {"alpha", {r.alpha_min, r.alpha_max}}}}};
  // Only when used, so that folders made before the option still resume (check_resumable).
  if (r.near_grey_share > 0) parameters["ranges"]["near_grey_share"] = r.near_grey_share;
  return parameters;
}

TrainingSetStats write_training_set(const TrainingSetParams& params, const std::string& out_dir,
                                    const std::function<void()>& on_sequence) {
  if (params.sequences < 1)
    throw Error("training set", "sequences", fmt::format("{} sequences", params.sequences));
  const Stopwatch watch;
  const fs::path out(out_dir);
  fs::create_directories(out);
  const nlohmann::json parameters = training_set_parameters_json(params);
  check_resumable(out / "index.json", parameters);
  remove_partial_sequences(out);

  std::vector<Scene> scenes;
  nlohmann::json sequences = nlohmann::json::array();
  for (int i = 0; i < params.sequences; ++i) {
    scenes.push_back(make_training_scene(params, i));
    sequences.push_back(sequence_json(scenes.back(), sequence_folder(i)));
  }
  io::write_json(
      (out / "index.json").string(),
      {{"parameters", parameters}, {"count", params.sequences}, {"sequences", sequences}});

  TrainingSetStats stats;
  SequenceOptions options;
  options.ground_truth = params.ground_truth;
  options.progress = false;  // the caller follows the set through on_sequence
  for (int i = 0; i < params.sequences; ++i) {
    const fs::path folder = out / sequence_folder(i);
    if (fs::is_directory(folder)) {
      ++stats.skipped;
    } else {
      write_sequence(scenes[static_cast<std::size_t>(i)], folder.string(), options);
      ++stats.rendered;
    }
    if (on_sequence) on_sequence();
  }
  stats.seconds = watch.elapsed_s();
  return stats;
}

}  // namespace glint::render
