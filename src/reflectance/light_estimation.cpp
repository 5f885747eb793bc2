#include "reflectance/light_estimation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "io/json_report.h"
#include "reflectance/light_capture.h"
#include "render/sensor.h"

namespace glint::reflectance {
namespace {

using nlohmann::json;

// One frame's measurement of one light.
struct LightView {
  LightSample sample;  // emitter centre (world), mean radiance, pixels
  Eigen::Vector3f intensity = Eigen::Vector3f::Zero();
  double radius_m = 0;
  double clipped_px = 0;
};

// Per-cluster sums over a frame's bright pixels.
struct ClusterSums {
  Eigen::Vector3d position_x_solid_angle = Eigen::Vector3d::Zero();
  double solid_angle = 0;  // sr
  Eigen::Vector3d radiance_x_solid_angle = Eigen::Vector3d::Zero();
  Eigen::Vector3d radiance_x_solid_angle_x_distance2 = Eigen::Vector3d::Zero();
  double pixels = 0;
  double clipped_px = 0;
  bool touches_border = false;
};

void validate(const LightEstimationParams& params) {
  auto require = [](bool ok, const char* name, const char* reason) {
    if (!ok) throw Error("light estimation", name, reason);
  };
  require(params.min_luminance > 0 && std::isfinite(params.min_luminance), "min_luminance",
          "must be > 0");
  require(!params.exposure || (*params.exposure > 0 && std::isfinite(*params.exposure)), "exposure",
          "must be > 0");
  require(params.min_cluster_px >= 1, "min_cluster_px", "must be >= 1");
  require(params.max_bright_fraction > 0 && params.max_bright_fraction <= 1, "max_bright_fraction",
          "must be in (0, 1]");
  require(params.clustering.bandwidth_m > 0, "bandwidth_m", "must be > 0");
  require(params.fusion.merge_radius_m > 0, "merge_radius_m", "must be > 0");
  require(params.fusion.min_frames >= 1, "min_frames", "must be >= 1");
}

// The lights one frame sees whole (clusters touching the image border are partial views).
std::vector<LightView> frame_views(const io::RgbdFrame& frame, const std::string& colour_path,
                                   const Intrinsics& intrinsics,
                                   const LightEstimationParams& params, float exposure) {
  LightCaptureParams capture;
  capture.min_luminance = params.min_luminance;
  capture.exposure = exposure;
  const Pose& camera_to_world = *frame.ground_truth;
  const std::vector<LightSample> samples =
      bright_samples(frame.colour, frame.depth_m, intrinsics, camera_to_world, capture);
  const double bright_fraction = double(samples.size()) / double(frame.colour.pixel_count());
  if (bright_fraction > params.max_bright_fraction)
    throw Error(colour_path, "",
                fmt::format("{:.0f} % of the pixels reach luminance {}: not a low-exposure light "
                            "capture, where lamps are a few bright spots (capture with a lower "
                            "exposure, or raise --min-luminance)",
                            100 * bright_fraction, params.min_luminance));
  const std::vector<LightSample> clusters = mean_shift(samples, params.clustering);

  // A channel at sRGB code 254 or above has (probably) clipped.
  const float clipped_radiance = render::srgb_to_linear(253.5f / 255.0f) / exposure;
  const Pose world_to_camera = camera_to_world.inverse();
  std::vector<ClusterSums> sums(clusters.size());
  for (const LightSample& s : samples) {
    std::size_t nearest = 0;
    for (std::size_t c = 1; c < clusters.size(); ++c)
      if ((clusters[c].position - s.position).squaredNorm() <
          (clusters[nearest].position - s.position).squaredNorm())
        nearest = c;
    ClusterSums& sum = sums[nearest];
    const Eigen::Vector3d in_camera = world_to_camera * s.position;
    const double distance2 = in_camera.squaredNorm();
    const double cos_theta = in_camera.z() / std::sqrt(distance2);
    const double solid_angle = std::pow(cos_theta, 3) / (intrinsics.fx * intrinsics.fy);
    const Eigen::Vector3d radiance = s.radiance.cast<double>();
    sum.position_x_solid_angle += solid_angle * s.position;
    sum.solid_angle += solid_angle;
    sum.radiance_x_solid_angle += solid_angle * radiance;
    sum.radiance_x_solid_angle_x_distance2 += solid_angle * distance2 * radiance;
    sum.pixels += s.weight;
    sum.clipped_px += s.radiance.maxCoeff() >= clipped_radiance ? s.weight : 0;
    const Eigen::Vector2d pixel = intrinsics.project(in_camera);
    const long u = std::lround(pixel.x()), v = std::lround(pixel.y());
    sum.touches_border = sum.touches_border || u <= 0 || v <= 0 || u >= intrinsics.width - 1 ||
                         v >= intrinsics.height - 1;
  }

  const Eigen::Vector3d eye = camera_to_world.translation();
  std::vector<LightView> views;
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const ClusterSums& sum = sums[c];
    if (sum.pixels < params.min_cluster_px || sum.touches_border) continue;
    const Eigen::Vector3d centroid = sum.position_x_solid_angle / sum.solid_angle;
    const double centroid_distance = (centroid - eye).norm();
    // Half-angle of the cone of solid angle Omega = 2 pi (1 - cos a).
    const double cos_half = std::max(-1.0, 1 - sum.solid_angle / (2 * M_PI));
    const double sin_half = std::sqrt(std::max(0.0, 1 - cos_half * cos_half));
    LightView view;
    view.sample.radiance = clusters[c].radiance;
    view.sample.weight = sum.pixels;
    view.clipped_px = sum.clipped_px;
    if (params.spherical_emitters) {
      // The seen cap lies on average 2r/3 in front of the centre at distance D, r = D sin(a).
      const double centre_distance = centroid_distance / (1 - 2 * sin_half / 3);
      view.sample.position = eye + (centroid - eye) * (centre_distance / centroid_distance);
      view.intensity =
          (sum.radiance_x_solid_angle * centre_distance * centre_distance).cast<float>();
      view.radius_m = centre_distance * sin_half;
    } else {
      view.sample.position = centroid;
      view.intensity = sum.radiance_x_solid_angle_x_distance2.cast<float>();
      view.radius_m = centroid_distance * sin_half;
    }
    views.push_back(view);
  }
  return views;
}

double median(std::vector<double> values) {
  const std::size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(half), values.end());
  const double upper = values[half];
  if (values.size() % 2) return upper;
  return (*std::max_element(values.begin(), values.begin() + std::ptrdiff_t(half)) + upper) / 2;
}

// A light's intensity and radius from its per-frame views (at least one): views further than a
// factor 2 from the median total intensity are gross outliers (a partly occluded lamp, a merged
// reflection) and dropped; the mean of the rest is unbiased for the pixel discretisation of
// small lamps (a median alone reads 12 % low on lamps of 5 px).
void robust_mean(const std::vector<const LightView*>& views, render::PointLight* light) {
  std::vector<double> totals;
  for (const LightView* view : views) totals.push_back(view->intensity.sum());
  const double typical = median(totals);
  Eigen::Vector3d intensity = Eigen::Vector3d::Zero();
  double radius_m = 0, used = 0;
  for (const LightView* view : views)
    if (view->intensity.sum() >= typical / 2 && view->intensity.sum() <= 2 * typical) {
      intensity += view->intensity.cast<double>();
      radius_m += view->radius_m;
      used += 1;
    }
  light->intensity = (intensity / used).cast<float>();
  light->proxy_radius_m = radius_m / used;
}

// --- lights.json ---------------------------------------------------------------------------

double tidy(double value) { return std::stod(fmt::format("{}", float(value))); }

[[noreturn]] void fail(const std::string& path, const std::string& element,
                       const std::string& reason) {
  throw Error(path, element, reason);
}

double read_number(const json& object, const std::string& key, double fallback,
                   const std::string& path, const std::string& element) {
  const auto it = object.find(key);
  if (it == object.end()) return fallback;
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    fail(path, element.empty() ? key : element + "." + key, "must be a finite number");
  return it->get<double>();
}

Eigen::Vector3d read_vector3(const json& object, const std::string& key, const std::string& path,
                             const std::string& element) {
  const auto it = object.find(key);
  if (it == object.end()) fail(path, element, "missing \"" + key + "\"");
  if (!it->is_array() || it->size() != 3)
    fail(path, element + "." + key, "must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    const json& value = (*it)[std::size_t(i)];
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      fail(path, fmt::format("{}.{}[{}]", element, key, i), "must be a finite number");
    v[i] = value.get<double>();
  }
  return v;
}

}  // namespace

float capture_exposure(const std::string& folder) {
  const std::string path = (std::filesystem::path(folder) / "scene.json").string();
  if (!std::filesystem::exists(path)) return 1;
  const json scene = io::read_json(path);
  if (!scene.is_object()) fail(path, "", "must be a JSON object");
  const auto camera = scene.find("camera");
  if (camera == scene.end()) return 1;
  if (!camera->is_object()) fail(path, "camera", "must be an object");
  const double exposure = read_number(*camera, "exposure", 1.0, path, "camera");
  if (!(exposure > 0)) fail(path, "camera.exposure", "must be > 0");
  return float(exposure);
}

LightEstimate estimate_lights(const io::RgbdSequence& capture, const LightEstimationParams& params,
                              const std::function<void()>& on_frame) {
  validate(params);
  capture.require_ground_truth(capture.frames.size(),
                               "lighting estimation needs the pose of every capture frame");
  LightEstimate estimate;
  estimate.capture = capture.folder;
  estimate.exposure = params.exposure ? *params.exposure : capture_exposure(capture.folder);

  std::vector<std::vector<LightView>> views(capture.frames.size());
  parallel_for(capture.frames.size(), [&](std::size_t i) {
    views[i] = frame_views(io::read_rgbd_frame(capture, i), capture.frames[i].colour_path,
                           capture.intrinsics, params, estimate.exposure);
    if (on_frame) on_frame();
  });

  LightFuser fuser(params.fusion);
  for (const std::vector<LightView>& frame : views) {
    std::vector<LightSample> candidates;
    for (const LightView& view : frame) candidates.push_back(view.sample);
    fuser.add_frame(candidates);
  }
  const std::vector<FusedLight> fused = fuser.lights();

  // Each view goes to the nearest fused light within the merge radius.
  std::vector<std::vector<const LightView*>> views_of(fused.size());
  std::vector<double> squared_offsets(fused.size(), 0);
  for (const std::vector<LightView>& frame : views)
    for (const LightView& view : frame) {
      std::size_t nearest = fused.size();
      double nearest_distance = params.fusion.merge_radius_m;
      for (std::size_t l = 0; l < fused.size(); ++l) {
        const double distance = (fused[l].estimate.position - view.sample.position).norm();
        if (distance <= nearest_distance) {
          nearest_distance = distance;
          nearest = l;
        }
      }
      if (nearest == fused.size()) continue;
      views_of[nearest].push_back(&view);
      squared_offsets[nearest] += nearest_distance * nearest_distance;
    }

  for (std::size_t l = 0; l < fused.size(); ++l) {
    if (views_of[l].empty()) continue;  // its views all went to a nearer fused light
    render::PointLight light;
    light.position = fused[l].estimate.position;
    robust_mean(views_of[l], &light);
    double pixels = 0, clipped_px = 0;
    for (const LightView* view : views_of[l]) {
      pixels += view->sample.weight;
      clipped_px += view->clipped_px;
    }
    LightSupport support;
    support.frames = fused[l].frames;
    support.pixels = fused[l].estimate.weight;
    support.position_spread_m = std::sqrt(squared_offsets[l] / double(views_of[l].size()));
    support.clipped_fraction = clipped_px / pixels;
    if (support.clipped_fraction > 0)
      log().warn(
          "{}: light at ({:.2f}, {:.2f}, {:.2f}): {:.1f}% of its pixels are clipped, so its "
          "intensity is a lower bound; capture at a lower exposure",
          capture.folder, light.position.x(), light.position.y(), light.position.z(),
          100 * support.clipped_fraction);
    estimate.lights.push_back(light);
    estimate.support.push_back(support);
  }
  if (estimate.lights.empty())
    log().warn("{}: no light seen in {} or more frames (luminance >= {} at exposure {})",
               capture.folder, params.fusion.min_frames, params.min_luminance, estimate.exposure);
  return estimate;
}

void write_lights_json(const std::string& path, const LightEstimate& estimate) {
  json lights = json::array();
  for (std::size_t l = 0; l < estimate.lights.size(); ++l) {
    const render::PointLight& light = estimate.lights[l];
    const LightSupport support = l < estimate.support.size() ? estimate.support[l] : LightSupport{};
    lights.push_back(
        {{"position", {light.position.x(), light.position.y(), light.position.z()}},
         {"intensity",
          {tidy(light.intensity.x()), tidy(light.intensity.y()), tidy(light.intensity.z())}},
         {"radius_m", light.proxy_radius_m},
         {"frames", support.frames},
         {"pixels", std::llround(support.pixels)},
         {"position_spread_m", support.position_spread_m},
         {"clipped_fraction", support.clipped_fraction}});
  }
  io::write_json(
      path,
      {{"lights", lights}, {"capture", estimate.capture}, {"exposure", tidy(estimate.exposure)}});
}

LightEstimate read_lights_json(const std::string& path) {
  const json root = io::read_json(path);
  if (!root.is_object()) fail(path, "", "must be a JSON object");
  const auto lights = root.find("lights");
  if (lights == root.end()) fail(path, "", "missing \"lights\"");
  if (!lights->is_array()) fail(path, "lights", "must be an array");
  LightEstimate estimate;
  for (std::size_t l = 0; l < lights->size(); ++l) {
    const json& entry = (*lights)[l];
    const std::string element = fmt::format("lights[{}]", l);
    if (!entry.is_object()) fail(path, element, "must be an object");
    render::PointLight light;
    light.position = read_vector3(entry, "position", path, element);
    const Eigen::Vector3d intensity = read_vector3(entry, "intensity", path, element);
    if (intensity.minCoeff() < 0) fail(path, element + ".intensity", "must be >= 0");
    light.intensity = intensity.cast<float>();
    light.proxy_radius_m = read_number(entry, "radius_m", light.proxy_radius_m, path, element);
    if (!(light.proxy_radius_m > 0)) fail(path, element + ".radius_m", "must be > 0");
    LightSupport support;
    const double frames = read_number(entry, "frames", 0, path, element);
    if (frames < 0 || frames != std::floor(frames))
      fail(path, element + ".frames", "must be a whole number >= 0");
    support.frames = int(frames);
    support.pixels = read_number(entry, "pixels", 0, path, element);
    support.position_spread_m = read_number(entry, "position_spread_m", 0, path, element);
    support.clipped_fraction = read_number(entry, "clipped_fraction", 0, path, element);
    if (support.pixels < 0 || support.position_spread_m < 0 || support.clipped_fraction < 0 ||
        support.clipped_fraction > 1)
      fail(path, element, "pixels and position_spread_m must be >= 0, clipped_fraction in [0, 1]");
    estimate.lights.push_back(light);
    estimate.support.push_back(support);
  }
  if (const auto capture = root.find("capture"); capture != root.end()) {
    if (!capture->is_string()) fail(path, "capture", "must be a string");
    estimate.capture = capture->get<std::string>();
  }
  estimate.exposure = float(read_number(root, "exposure", 1.0, path, ""));
  if (!(estimate.exposure > 0)) fail(path, "exposure", "must be > 0");
  return estimate;
}

}  // namespace glint::reflectance
