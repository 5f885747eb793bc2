#include "render/builtin_scenes.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>

#include "core/error.h"

namespace glint::render {
namespace {

constexpr double kProxyRadius_m = 0.05;

Material ward(Eigen::Vector3f kd, Eigen::Vector3f ks, float alpha) {
  Material material;
  material.ward = {kd, ks, alpha};
  return material;
}
Material ward(Eigen::Vector3f kd, float ks, float alpha) {
  return ward(kd, Eigen::Vector3f::Constant(ks), alpha);
}

// A texture set's albedo map (DATA/textures/<set>/albedo.jpg, sRGB; README there). kd holds a
// representative colour for the kd + ks <= 1 check.
Material textured(const std::string& data_dir, const std::string& set, float repeat_m,
                  Eigen::Vector3f kd, float ks, float alpha) {
  Material material = ward(kd, ks, alpha);
  material.kd_texture =
      (std::filesystem::path(data_dir) / "textures" / set / "albedo.jpg").string();
  material.texture_scale_m = repeat_m;
  return material;
}

std::string mesh_file(const std::string& data_dir, const std::string& file) {
  return (std::filesystem::path(data_dir) / "meshes" / file).string();
}

Eigen::Isometry3d placed(const Eigen::Vector3d& position, double yaw_deg = 0) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.translate(position);
  transform.rotate(Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()));
  return transform;
}

// Appends the object with the next id (1, 2, ...).
void add(Scene& scene, Object object) {
  object.id = static_cast<int>(scene.objects.size()) + 1;
  scene.objects.push_back(std::move(object));
}

Object object(std::string name, ShapeKind shape, const Eigen::Vector3d& size,
              const Eigen::Isometry3d& transform, Material material) {
  Object result;
  result.name = std::move(name);
  result.shape = shape;
  result.size = size;
  result.transform = transform;
  result.material = std::move(material);
  return result;
}

Object box(std::string name, const Eigen::Vector3d& size, const Eigen::Vector3d& floor_centre,
           double yaw_deg, Material material) {
  return object(std::move(name), ShapeKind::box, size,
                placed(floor_centre + Eigen::Vector3d(0, size.y() / 2, 0), yaw_deg),
                std::move(material));
}

Object mesh(std::string name, std::string path, double height_m, const Eigen::Vector3d& base,
            double yaw_deg, Material material) {
  Object result = object(std::move(name), ShapeKind::mesh, Eigen::Vector3d::Constant(height_m),
                         placed(base, yaw_deg), std::move(material));
  result.mesh_path = std::move(path);
  return result;
}

// A plane of width_m (its x) by depth_m (its z), normal +y before `transform`.
Object plane(std::string name, double width_m, double depth_m, const Eigen::Isometry3d& transform,
             Material material) {
  return object(std::move(name), ShapeKind::plane, {width_m, 1, depth_m}, transform,
                std::move(material));
}

Object floor_plane(double side_m, Material material) {
  return plane("floor", side_m, side_m, Eigen::Isometry3d::Identity(), std::move(material));
}

// A vertical wall whose centre line on the floor is `floor_centre`, facing `inward` (unit,
// horizontal).
Object wall(std::string name, double width_m, double height_m, const Eigen::Vector3d& floor_centre,
            const Eigen::Vector3d& inward, Material material) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.translate(floor_centre + Eigen::Vector3d(0, height_m / 2, 0));
  // Turn the plane's +y normal to +z (its z extent becomes vertical), then yaw to `inward`.
  transform.rotate(Eigen::AngleAxisd(std::atan2(inward.x(), inward.z()), Eigen::Vector3d::UnitY()));
  transform.rotate(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  return plane(std::move(name), width_m, height_m, transform, std::move(material));
}

PointLight light(const Eigen::Vector3d& position, const Eigen::Vector3f& intensity) {
  return {position, intensity, kProxyRadius_m};
}

Scene cubes(const BuiltinOptions& options) {
  Scene scene;
  add(scene, floor_plane(6, ward({0.45f, 0.45f, 0.45f}, 0.05f, 0.3f)));
  const std::vector<std::pair<std::string, Material>> cube_materials = {
      {"red", ward({0.60f, 0.06f, 0.05f}, 0.25f, 0.05f)},
      {"green", ward({0.10f, 0.45f, 0.12f}, 0.12f, 0.12f)},
      {"blue", ward({0.08f, 0.12f, 0.55f}, 0.06f, 0.25f)},
      {"white", ward({0.75f, 0.75f, 0.72f}, 0.15f, 0.08f)},
      {"gold", ward({0.20f, 0.14f, 0.03f}, {0.65f, 0.50f, 0.20f}, 0.15f)},
      {"black", ward({0.04f, 0.04f, 0.04f}, 0.35f, 0.03f)}};
  const double edge_m = 0.4, ring_m = 0.9;
  for (std::size_t i = 0; i < cube_materials.size(); ++i) {
    const double azimuth = 2 * M_PI * double(i) / double(cube_materials.size());
    add(scene, box(cube_materials[i].first + " cube", {edge_m, edge_m, edge_m},
                   {ring_m * std::sin(azimuth), 0, ring_m * std::cos(azimuth)}, 17.0 * double(i),
                   cube_materials[i].second));
  }
  scene.lights = {light({1.5, 2.4, 2.0}, {10, 10, 10}), light({-1.8, 2.0, -1.2}, {7, 6, 5})};
  OrbitParams orbit;
  orbit.ring = {{0, 0, 0}, 3.8, 1.5, {0, 0.2, 0}};
  orbit.frames = options.frames;
  scene.trajectory = orbit_trajectory(orbit);
  return scene;
}

Scene bunnies(const BuiltinOptions& options) {
  Scene scene;
  add(scene, floor_plane(8, ward({0.5f, 0.5f, 0.5f}, 0.04f, 0.3f)));
  const std::string bunny = mesh_file(options.data_dir, "stanford-bunny.obj");
  const double height_m = 1.5, ring_m = 1.3;
  const std::vector<std::pair<std::string, Material>> bunny_materials = {
      {"yellow bunny", ward({0.75f, 0.55f, 0.04f}, 0.20f, 0.05f)},
      {"teal bunny", ward({0.03f, 0.40f, 0.38f}, 0.12f, 0.12f)},
      {"orange bunny", ward({0.80f, 0.25f, 0.03f}, 0.06f, 0.25f)}};
  for (std::size_t i = 0; i < bunny_materials.size(); ++i) {
    const double azimuth_deg = 90 + 120 * double(i);
    const double azimuth = azimuth_deg * M_PI / 180;
    add(scene, mesh(bunny_materials[i].first, bunny, height_m,
                    {ring_m * std::sin(azimuth), 0, ring_m * std::cos(azimuth)}, azimuth_deg,
                    bunny_materials[i].second));
  }
  scene.lights = {light({0, 2.6, 0}, {12, 12, 12}), light({2.2, 2.0, 1.6}, {8, 8, 8}),
                  light({-2.0, 1.7, -1.8}, {7, 6, 4.5})};
  OscillationParams oscillation;
  oscillation.ring = {{0, 0, 0}, 3.7, 1.6, {0, 0.6, 0}};
  oscillation.amplitude_deg = 60;
  oscillation.frames = options.frames;
  scene.trajectory = oscillation_trajectory(oscillation);
  return scene;
}

Scene office(const BuiltinOptions& options) {
  const std::string& data = options.data_dir;
  const double room_m = 6, wall_height_m = 2.8, table_top_m = 0.75;
  const Material wall_paint = ward({0.70f, 0.68f, 0.62f}, 0.02f, 0.3f);
  Scene scene;
  add(scene, floor_plane(room_m, ward({0.35f, 0.25f, 0.18f}, 0.08f, 0.15f)));
  add(scene, wall("back wall", room_m, wall_height_m, {0, 0, -3}, {0, 0, 1}, wall_paint));
  add(scene, wall("left wall", room_m, wall_height_m, {-3, 0, 0}, {1, 0, 0}, wall_paint));
  add(scene, wall("right wall", room_m, wall_height_m, {3, 0, 0}, {-1, 0, 0}, wall_paint));
  add(scene, box("table", {1.6, table_top_m, 0.8}, {0, 0, -1}, 0,
                 textured(data, "onyx", 0.5f, {0.6f, 0.6f, 0.6f}, 0.05f, 0.04f)));
  Material spot_skin = ward({0.6f, 0.6f, 0.6f}, 0.05f, 0.2f);
  spot_skin.kd_texture = mesh_file(data, "spot_texture.png");
  add(scene,
      mesh("spot", mesh_file(data, "spot.obj"), 0.35, {-0.45, table_top_m, -1.0}, 30, spot_skin));
  add(scene, mesh("teapot", mesh_file(data, "teapot.obj"), 0.25, {0.4, table_top_m, -0.9}, -20,
                  ward({0.80f, 0.80f, 0.78f}, 0.15f, 0.04f)));
  add(scene, mesh("suzanne", mesh_file(data, "suzanne.obj"), 0.3, {0.0, table_top_m, -1.2}, 0,
                  ward({0.50f, 0.05f, 0.05f}, 0.30f, 0.10f)));
  add(scene, box("crate", {0.5, 0.5, 0.5}, {-1.8, 0, -2.0}, 25,
                 textured(data, "bark", 0.5f, {0.3f, 0.2f, 0.12f}, 0.02f, 0.3f)));
  add(scene, object("ball", ShapeKind::sphere, Eigen::Vector3d::Constant(0.25),
                    placed({1.6, 0.25, -1.6}), ward({0.05f, 0.10f, 0.45f}, 0.3f, 0.06f)));
  add(scene, box("cabinet", {0.8, 1.2, 0.5}, {2.2, 0, -2.4}, 0,
                 textured(data, "rustymetal", 1.0f, {0.3f, 0.2f, 0.15f}, 0.1f, 0.3f)));
  scene.lights = {light({-1.0, 2.6, -0.8}, {10, 10, 10}), light({1.2, 2.6, -1.6}, {8, 8, 8}),
                  light({0, 2.6, 0.8}, {6, 6, 5})};
  OscillationParams oscillation;
  oscillation.ring = {{0, 0, -1}, 2.6, 1.7, {0, 0.85, -1.2}};
  oscillation.amplitude_deg = 40;
  oscillation.height_amplitude_m = 0.2;
  oscillation.frames = options.frames;
  scene.trajectory = oscillation_trajectory(oscillation);
  return scene;
}

}  // namespace

std::string default_data_dir() {
  const char* data = std::getenv("GLINT_DATA");
  return data && *data ? data : "../shared/data";
}

Intrinsics sensor_intrinsics(int width, int height) {
  if (width < 1 || height < 1)
    throw Error("camera", "", fmt::format("image size {}x{} is empty", width, height));
  const Intrinsics kinect = kinect_v2_intrinsics();
  Intrinsics intrinsics = kinect.scaled(double(width) / kinect.width);
  intrinsics.width = width;
  intrinsics.height = height;
  intrinsics.cy = (kinect.cy + 0.5) * height / kinect.height - 0.5;
  return intrinsics;
}

const std::vector<std::string>& builtin_scene_names() {
  static const std::vector<std::string> names = {"cubes", "bunnies", "office"};
  return names;
}

Scene make_builtin_scene(const std::string& name, const BuiltinOptions& options) {
  static const std::map<std::string, std::function<Scene(const BuiltinOptions&)>> builders = {
      {"cubes", cubes}, {"bunnies", bunnies}, {"office", office}};
  const auto builder = builders.find(name);
  if (builder == builders.end())
    throw Error(name, "", "unknown built-in scene (cubes, bunnies, office)");
  Scene scene = builder->second(options);
  scene.camera.intrinsics = sensor_intrinsics(options.width, options.height);
  scene.seed = options.seed;
  return scene;
}

Scene make_light_capture(const Scene& scene, const LightCaptureParams& path, float exposure) {
  std::vector<Eigen::Vector3d> positions;
  for (const PointLight& light : scene.lights) positions.push_back(light.position);
  Scene capture = scene;
  capture.camera.exposure = exposure;
  capture.trajectory = light_capture_trajectory(positions, path);
  return capture;
}

}  // namespace glint::render
