#include "render/scene_json.h"

#include <fmt/format.h>

#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/limits.h"
#include "io/json_report.h"
#include "io/trajectory.h"
#include "render/trajectories.h"

namespace glint::render {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kShapeNames[] = {"mesh", "box", "sphere", "plane"};
constexpr double kMaxOrbitFrames = 1e6;

// Reads typed values out of the parsed document; every failure names the file and the element
// path ("objects[2].material.alpha").
class SceneReader {
 public:
  explicit SceneReader(std::string path)
      : path_(std::move(path)), folder_(fs::path(path_).parent_path()) {}

  [[noreturn]] void fail(const std::string& element, const std::string& reason) const {
    throw Error(path_, element, reason);
  }
  const std::string& path() const { return path_; }

  // A number that must be an integer in [lowest, highest] (core/limits.h).
  int integer_in(double value, double lowest, double highest, const std::string& element) const {
    limits::check_integer(value, lowest, highest, path_, element);
    return static_cast<int>(value);
  }
  // A position in metres within the world extent (core/limits.h).
  Eigen::Vector3d position(const json& value, const std::string& element) const {
    const Eigen::Vector3d p = vector3(value, element);
    limits::check_position(p, path_, element);
    return p;
  }

  // Rejects keys outside `known` (catches typos that would silently fall back to defaults).
  void expect_object(const json& value, const std::string& element,
                     std::initializer_list<const char*> known) const {
    if (!value.is_object()) fail(element, "expected a JSON object");
    for (const auto& item : value.items()) {
      bool found = false;
      for (const char* key : known) found = found || item.key() == key;
      if (!found) fail(element, fmt::format("unknown key '{}'", item.key()));
    }
  }

  const json& required(const json& object, const char* key, const std::string& element) const {
    if (!object.contains(key)) fail(element, fmt::format("missing key '{}'", key));
    return object.at(key);
  }

  double number(const json& value, const std::string& element) const {
    if (!value.is_number()) fail(element, "expected a number");
    return value.get<double>();
  }
  double number_or(const json& object, const char* key, double fallback,
                   const std::string& element) const {
    return object.contains(key) ? number(object.at(key), element + "." + key) : fallback;
  }
  bool boolean_or(const json& object, const char* key, bool fallback,
                  const std::string& element) const {
    if (!object.contains(key)) return fallback;
    if (!object.at(key).is_boolean()) fail(element + "." + key, "expected true or false");
    return object.at(key).get<bool>();
  }
  std::string text(const json& value, const std::string& element) const {
    if (!value.is_string()) fail(element, "expected a string");
    return value.get<std::string>();
  }

  Eigen::VectorXd numbers(const json& value, int count, const std::string& element) const {
    if (!value.is_array() || static_cast<int>(value.size()) != count)
      fail(element, fmt::format("expected an array of {} numbers", count));
    Eigen::VectorXd out(count);
    for (int i = 0; i < count; ++i) out[i] = number(value[i], element);
    return out;
  }
  Eigen::Vector3d vector3(const json& value, const std::string& element) const {
    return numbers(value, 3, element);
  }
  // One number for all three components (grey, a cube) or [x, y, z].
  Eigen::Vector3d number_or_vector3(const json& value, const std::string& element) const {
    if (value.is_number()) return Eigen::Vector3d::Constant(value.get<double>());
    return vector3(value, element);
  }
  Eigen::Vector3f colour(const json& value, const std::string& element) const {
    return number_or_vector3(value, element).cast<float>();
  }

  // A file path, relative ones against the JSON file's folder; the file must exist.
  std::string existing_file(const json& value, const std::string& element) const {
    const fs::path file = text(value, element);
    const fs::path resolved = file.is_absolute() ? file : folder_ / file;
    if (!fs::is_regular_file(resolved))
      throw Error(resolved.string(), element, "no such file (referenced by " + path_ + ")");
    return resolved.lexically_normal().string();
  }

  Eigen::Quaterniond quaternion(const json& value, const std::string& element) const {
    const Eigen::VectorXd q = numbers(value, 4, element);
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (std::abs(rotation.norm() - 1.0) > 0.1)
      fail(element, "quaternion [qx, qy, qz, qw] is far from unit length");
    return rotation.normalized();
  }

 private:
  std::string path_;
  fs::path folder_;
};

Eigen::Isometry3d read_transform(const SceneReader& reader, const json& value,
                                 const std::string& element) {
  reader.expect_object(value, element, {"position", "rotation", "quaternion"});
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  if (value.contains("position"))
    transform.translation() = reader.position(value["position"], element + ".position");
  if (value.contains("rotation") && value.contains("quaternion"))
    reader.fail(element, "give either 'rotation' or 'quaternion', not both");
  if (value.contains("quaternion"))
    transform.linear() = reader.quaternion(value["quaternion"], element + ".quaternion").matrix();
  if (value.contains("rotation")) {
    const std::string at = element + ".rotation";
    const json& rotation = value["rotation"];
    reader.expect_object(rotation, at, {"axis", "angle_deg"});
    const Eigen::Vector3d axis =
        reader.vector3(reader.required(rotation, "axis", at), at + ".axis");
    if (!(axis.norm() > 0)) reader.fail(at + ".axis", "the axis must not be zero");
    const double angle = reader.number(reader.required(rotation, "angle_deg", at), at);
    transform.linear() = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()).matrix();
  }
  return transform;
}

Material read_material(const SceneReader& reader, const json& value, const std::string& element) {
  reader.expect_object(value, element, {"kd", "ks", "alpha", "kd_texture", "texture_scale_m"});
  Material material;
  WardMaterial& ward = material.ward;
  if (value.contains("kd")) ward.kd = reader.colour(value["kd"], element + ".kd");
  if (value.contains("ks")) ward.ks = reader.colour(value["ks"], element + ".ks");
  ward.alpha = static_cast<float>(reader.number_or(value, "alpha", ward.alpha, element));
  if (value.contains("kd_texture"))
    material.kd_texture = reader.existing_file(value["kd_texture"], element + ".kd_texture");
  material.texture_scale_m =
      static_cast<float>(reader.number_or(value, "texture_scale_m", 1.0, element));
  if (!(ward.alpha > 0)) reader.fail(element + ".alpha", "alpha must be > 0");
  if (!(material.texture_scale_m > 0)) reader.fail(element + ".texture_scale_m", "must be > 0");
  if (ward.kd.minCoeff() < 0 || ward.ks.minCoeff() < 0)
    reader.fail(element, "kd and ks must be >= 0");
  // With a texture kd varies per texel and the texture alone must respect the bound.
  const Eigen::Vector3f bound = material.kd_texture.empty() ? ward.kd + ward.ks : ward.ks;
  if (bound.maxCoeff() > 1.0f + 1e-6f)
    reader.fail(element, "kd + ks exceeds 1 in a channel (the surface would create energy)");
  return material;
}

Object read_object(const SceneReader& reader, const json& value, std::size_t index) {
  const std::string element = fmt::format("objects[{}]", index);
  reader.expect_object(value, element,
                       {"name", "id", "shape", "mesh", "size", "transform", "material"});
  Object object;
  object.name = value.contains("name") ? reader.text(value["name"], element + ".name")
                                       : fmt::format("object{}", index + 1);
  // Id 0 is the background of the gt/segment maps.
  object.id = reader.integer_in(reader.number_or(value, "id", double(index + 1), element), 1, 65535,
                                element + ".id");
  const std::string shape =
      reader.text(reader.required(value, "shape", element), element + ".shape");
  bool known = false;
  for (int s = 0; s < 4; ++s) {
    if (shape == kShapeNames[s]) {
      object.shape = static_cast<ShapeKind>(s);
      known = true;
    }
  }
  if (!known)
    reader.fail(element + ".shape",
                fmt::format("unknown shape '{}' (mesh, box, sphere, plane)", shape));
  if (object.shape == ShapeKind::mesh)
    object.mesh_path =
        reader.existing_file(reader.required(value, "mesh", element), element + ".mesh");
  if (value.contains("size"))  // one number: the same size on every axis
    object.size = reader.number_or_vector3(value["size"], element + ".size");
  if (!(object.size.minCoeff() > 0)) reader.fail(element + ".size", "sizes must be > 0");
  limits::check_position(object.size, reader.path(), element + ".size");
  if (value.contains("transform"))
    object.transform = read_transform(reader, value["transform"], element + ".transform");
  if (value.contains("material"))
    object.material = read_material(reader, value["material"], element + ".material");
  return object;
}

PointLight read_light(const SceneReader& reader, const json& value, std::size_t index) {
  const std::string element = fmt::format("lights[{}]", index);
  reader.expect_object(value, element, {"position", "intensity", "proxy_radius_m"});
  PointLight light;
  light.position =
      reader.position(reader.required(value, "position", element), element + ".position");
  if (value.contains("intensity"))
    light.intensity = reader.colour(value["intensity"], element + ".intensity");
  light.proxy_radius_m = reader.number_or(value, "proxy_radius_m", light.proxy_radius_m, element);
  if (light.intensity.minCoeff() < 0) reader.fail(element + ".intensity", "must be >= 0");
  if (light.proxy_radius_m < 0) reader.fail(element + ".proxy_radius_m", "must be >= 0");
  return light;
}

Environment read_environment(const SceneReader& reader, const json& value) {
  const std::string element = "environment";
  reader.expect_object(value, element, {"path", "scale", "rotation_deg", "samples"});
  Environment environment;
  environment.path =
      reader.existing_file(reader.required(value, "path", element), element + ".path");
  environment.scale = static_cast<float>(reader.number_or(value, "scale", 1.0, element));
  environment.rotation_deg =
      static_cast<float>(reader.number_or(value, "rotation_deg", 0.0, element));
  environment.samples =
      reader.integer_in(reader.number_or(value, "samples", environment.samples, element), 1,
                        limits::kMaxSamplesPerPixel, element + ".samples");
  if (environment.scale < 0) reader.fail(element + ".scale", "must be >= 0");
  return environment;
}

CameraSettings read_camera(const SceneReader& reader, const json& value) {
  const std::string element = "camera";
  reader.expect_object(value, element, {"intrinsics", "exposure", "sensor_noise", "depth_noise"});
  CameraSettings camera;
  if (value.contains("intrinsics")) {
    const std::string at = element + ".intrinsics";
    const json& k = value["intrinsics"];
    reader.expect_object(k, at, {"width", "height", "fx", "fy", "cx", "cy"});
    Intrinsics& in = camera.intrinsics;
    in.width = static_cast<int>(reader.number(reader.required(k, "width", at), at + ".width"));
    in.height = static_cast<int>(reader.number(reader.required(k, "height", at), at + ".height"));
    in.fx = reader.number(reader.required(k, "fx", at), at + ".fx");
    in.fy = reader.number(reader.required(k, "fy", at), at + ".fy");
    in.cx = reader.number(reader.required(k, "cx", at), at + ".cx");
    in.cy = reader.number(reader.required(k, "cy", at), at + ".cy");
    limits::check_intrinsics(in, reader.path(), at);
  }
  camera.exposure = static_cast<float>(reader.number_or(value, "exposure", 1.0, element));
  camera.sensor_noise = static_cast<float>(reader.number_or(value, "sensor_noise", 0.0, element));
  camera.depth_noise = reader.boolean_or(value, "depth_noise", false, element);
  if (!(camera.exposure > 0)) reader.fail(element + ".exposure", "must be > 0");
  if (camera.sensor_noise < 0) reader.fail(element + ".sensor_noise", "must be >= 0");
  return camera;
}

std::vector<Pose> read_trajectory(const SceneReader& reader, const json& value) {
  const std::string element = "trajectory";
  std::vector<Pose> poses;
  if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string at = fmt::format("{}[{}]", element, i);
      const Eigen::VectorXd p = reader.numbers(value[i], 7, at);
      Pose pose = Pose::Identity();
      pose.translation() = p.head<3>();
      pose.linear() = reader.quaternion(json{p[3], p[4], p[5], p[6]}, at).matrix();
      poses.push_back(pose);
    }
  } else {
    reader.expect_object(value, element, {"orbit", "tum"});
    if (value.contains("tum")) {
      for (const io::StampedPose& stamped :
           io::read_tum_trajectory(reader.existing_file(value["tum"], element + ".tum")))
        poses.push_back(stamped.pose);
    } else {
      const std::string at = element + ".orbit";
      const json& orbit = reader.required(value, "orbit", element);
      reader.expect_object(orbit, at,
                           {"center", "radius", "height", "frames", "revolutions", "start_deg"});
      OrbitParams params;
      params.ring.centre = reader.position(reader.required(orbit, "center", at), at + ".center");
      params.ring.target = params.ring.centre;
      params.ring.radius_m = reader.number(reader.required(orbit, "radius", at), at + ".radius");
      params.ring.height_m = reader.number_or(orbit, "height", 0.0, at);
      params.frames =
          reader.integer_in(reader.number(reader.required(orbit, "frames", at), at + ".frames"), 1,
                            kMaxOrbitFrames, at + ".frames");
      if (!(params.ring.radius_m > 0)) reader.fail(at + ".radius", "must be > 0");
      params.arc_deg = 360.0 * reader.number_or(orbit, "revolutions", 1.0, at);
      params.start_deg = reader.number_or(orbit, "start_deg", 0.0, at);
      try {
        poses = orbit_trajectory(params);
      } catch (const Error& e) {  // e.g. a camera looking straight down: name it here
        reader.fail(element + (e.element().empty() ? "" : "." + e.element()), e.reason());
      }
    }
  }
  if (poses.empty()) reader.fail(element, "the trajectory has no poses");
  for (std::size_t i = 0; i < poses.size(); ++i)
    limits::check_position(poses[i].translation(), reader.path(),
                           fmt::format("{}[{}] position", element, i));
  return poses;
}

// Paths are written absolute, so the copy of scene.json inside a sequence folder still finds
// its meshes, textures and environment map.
std::string absolute(const std::string& path) {
  return path.empty() ? path : fs::absolute(path).lexically_normal().string();
}

// Shortest decimal that reads back to the same float (0.1f is written 0.1).
double tidy(float value) { return std::stod(fmt::format("{}", value)); }
json tidy(const Eigen::Vector3f& v) { return {tidy(v.x()), tidy(v.y()), tidy(v.z())}; }
json to_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
json quaternion_json(const Eigen::Matrix3d& rotation) {
  const Eigen::Quaterniond q(rotation);
  return {q.x(), q.y(), q.z(), q.w()};
}

json object_json(const Object& object) {
  const Material& material = object.material;
  json m = {{"kd", tidy(material.ward.kd)},
            {"ks", tidy(material.ward.ks)},
            {"alpha", tidy(material.ward.alpha)},
            {"texture_scale_m", tidy(material.texture_scale_m)}};
  if (!material.kd_texture.empty()) m["kd_texture"] = absolute(material.kd_texture);
  json o = {{"name", object.name},
            {"id", object.id},
            {"shape", kShapeNames[static_cast<int>(object.shape)]},
            {"size", to_json(object.size)},
            {"transform",
             {{"position", to_json(object.transform.translation())},
              {"quaternion", quaternion_json(object.transform.linear())}}},
            {"material", m}};
  if (object.shape == ShapeKind::mesh) o["mesh"] = absolute(object.mesh_path);
  return o;
}

}  // namespace

Scene read_scene_json(const std::string& path) {
  const json document = io::read_json(path);
  const SceneReader reader(path);
  reader.expect_object(document, "",
                       {"objects", "lights", "environment", "camera", "trajectory", "fps",
                        "shadows", "bounces", "indirect_samples", "seed"});
  Scene scene;
  const json& objects = reader.required(document, "objects", "");
  if (!objects.is_array()) reader.fail("objects", "expected an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    scene.objects.push_back(read_object(reader, objects[i], i));
    for (std::size_t j = 0; j < i; ++j)  // ids name the objects in gt/segment: one each
      if (scene.objects[j].id == scene.objects[i].id)
        reader.fail(fmt::format("objects[{}].id", i),
                    fmt::format("{} is already the id of objects[{}]; ids must be unique",
                                scene.objects[i].id, j));
  }
  if (document.contains("lights")) {
    if (!document["lights"].is_array()) reader.fail("lights", "expected an array");
    for (std::size_t i = 0; i < document["lights"].size(); ++i)
      scene.lights.push_back(read_light(reader, document["lights"][i], i));
  }
  if (document.contains("environment") && !document["environment"].is_null())
    scene.environment = read_environment(reader, document["environment"]);
  if (document.contains("camera")) scene.camera = read_camera(reader, document["camera"]);
  scene.trajectory = read_trajectory(reader, reader.required(document, "trajectory", ""));
  scene.frames_per_second = reader.number_or(document, "fps", scene.frames_per_second, "");
  if (!(scene.frames_per_second > 0)) reader.fail("fps", "must be > 0");
  scene.shadows = reader.boolean_or(document, "shadows", scene.shadows, "");
  scene.bounces = reader.integer_in(reader.number_or(document, "bounces", scene.bounces, ""), 0,
                                    limits::kMaxBounces, "bounces");
  scene.indirect_samples =
      reader.integer_in(reader.number_or(document, "indirect_samples", scene.indirect_samples, ""),
                        1, limits::kMaxSamplesPerPixel, "indirect_samples");
  if (document.contains("seed")) {
    const json& seed = document["seed"];
    if (!seed.is_number_unsigned()) reader.fail("seed", "expected a non-negative integer");
    scene.seed = seed.get<std::uint64_t>();
  }
  return scene;
}

void write_scene_json(const std::string& path, const Scene& scene) {
  json document;
  document["objects"] = json::array();
  for (const Object& object : scene.objects) document["objects"].push_back(object_json(object));
  document["lights"] = json::array();
  for (const PointLight& light : scene.lights)
    document["lights"].push_back({{"position", to_json(light.position)},
                                  {"intensity", tidy(light.intensity)},
                                  {"proxy_radius_m", light.proxy_radius_m}});
  if (scene.environment)
    document["environment"] = {{"path", absolute(scene.environment->path)},
                               {"scale", tidy(scene.environment->scale)},
                               {"rotation_deg", tidy(scene.environment->rotation_deg)},
                               {"samples", scene.environment->samples}};
  const Intrinsics& k = scene.camera.intrinsics;
  document["camera"] = {{"intrinsics",
                         {{"width", k.width},
                          {"height", k.height},
                          {"fx", k.fx},
                          {"fy", k.fy},
                          {"cx", k.cx},
                          {"cy", k.cy}}},
                        {"exposure", tidy(scene.camera.exposure)},
                        {"sensor_noise", tidy(scene.camera.sensor_noise)},
                        {"depth_noise", scene.camera.depth_noise}};
  document["trajectory"] = json::array();
  for (const Pose& pose : scene.trajectory) {
    const Eigen::Quaterniond q(pose.linear());
    const Eigen::Vector3d t = pose.translation();
    document["trajectory"].push_back({t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
  }
  document["fps"] = scene.frames_per_second;
  document["shadows"] = scene.shadows;
  document["bounces"] = scene.bounces;
  document["indirect_samples"] = scene.indirect_samples;
  document["seed"] = scene.seed;
  io::write_json(path, document);
}

}  // namespace glint::render
