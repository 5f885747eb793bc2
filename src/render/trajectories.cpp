#include "render/trajectories.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"

namespace glint::render {
namespace {

double radians(double degrees) { return degrees * M_PI / 180.0; }

void require_frames(int frames, const char* what) {
  if (frames < 1) throw Error(what, "frames", fmt::format("{} frames; need at least 1", frames));
}

// pose(i) for every frame; a look_at failure names the trajectory and the frame.
template <class PoseOf>
std::vector<Pose> frame_poses(const char* what, int frames, PoseOf&& pose) {
  require_frames(frames, what);
  std::vector<Pose> poses;
  poses.reserve(static_cast<std::size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    try {
      poses.push_back(pose(i));
    } catch (const Error& e) {
      throw Error(e.file(), fmt::format("{} frame {}", what, i), e.reason());
    }
  }
  return poses;
}

}  // namespace

Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = target - eye;
  if (forward.norm() < 1e-12)
    throw Error("", "",
                fmt::format("the camera at ({:g}, {:g}, {:g}) and its target coincide", eye.x(),
                            eye.y(), eye.z()));
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x_unnormalised = z.cross(up);  // image right = forward x up
  if (x_unnormalised.norm() < 1e-9 * up.norm())
    throw Error("", "",
                fmt::format("the camera at ({:g}, {:g}, {:g}) looks at ({:g}, {:g}, {:g}), "
                            "parallel to the up vector ({:g}, {:g}, {:g}): its image has no "
                            "'up'; move the camera sideways (e.g. a larger orbit radius)",
                            eye.x(), eye.y(), eye.z(), target.x(), target.y(), target.z(), up.x(),
                            up.y(), up.z()));
  const Eigen::Vector3d x = x_unnormalised.normalized();
  const Eigen::Vector3d y = z.cross(x);  // image down
  Pose pose = Pose::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

Pose ring_pose(const CameraRing& ring, double azimuth_deg, double height_offset_m) {
  const double azimuth = radians(azimuth_deg);
  const Eigen::Vector3d eye = ring.centre + Eigen::Vector3d(ring.radius_m * std::sin(azimuth),
                                                            ring.height_m + height_offset_m,
                                                            ring.radius_m * std::cos(azimuth));
  return look_at(eye, ring.target);
}

std::vector<Pose> orbit_trajectory(const OrbitParams& params) {
  return frame_poses("orbit", params.frames, [&](int i) {
    return ring_pose(params.ring, params.start_deg + params.arc_deg * i / params.frames);
  });
}

std::vector<Pose> oscillation_trajectory(const OscillationParams& params) {
  return frame_poses("oscillation", params.frames, [&](int i) {
    const double phase = 2 * M_PI * params.periods * i / params.frames;
    return ring_pose(params.ring, params.centre_deg + params.amplitude_deg * std::sin(phase),
                     params.height_amplitude_m * std::sin(2 * phase));
  });
}

std::vector<Pose> light_capture_trajectory(const std::vector<Eigen::Vector3d>& light_positions,
                                           const LightCaptureParams& params) {
  const int lights = static_cast<int>(light_positions.size());
  if (lights == 0) throw Error("light capture", "", "the scene has no point lights");
  if (params.frames < lights)
    throw Error(
        "light capture", "frames",
        fmt::format("{} frames for {} lights; need at least one per light", params.frames, lights));
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : light_positions) centroid += p / lights;
  const CameraRing ring{
      {centroid.x(), 0, centroid.z()}, params.standoff_m, params.eye_height_m, centroid};

  std::vector<Pose> poses;
  poses.reserve(static_cast<std::size_t>(params.frames));
  for (int i = 0; i < params.frames; ++i) {
    const int light = i * lights / params.frames;  // equal consecutive blocks
    const int block_start = (light * params.frames + lights - 1) / lights;
    const int block_end = ((light + 1) * params.frames + lights - 1) / lights;
    const double phase = 2 * M_PI * (i - block_start) / (block_end - block_start);
    const double fraction = params.frames > 1 ? double(i) / (params.frames - 1) : 0.5;
    const Eigen::Vector3d eye = ring_pose(ring, params.arc_deg * (fraction - 0.5)).translation();
    const Eigen::Vector3d& target = light_positions[static_cast<std::size_t>(light)];
    const Pose towards_light = look_at(eye, target);
    const double offset = (target - eye).norm() * std::tan(radians(params.wobble_deg));
    const Eigen::Vector3d wobble = offset * (std::cos(phase) * towards_light.linear().col(0) +
                                             std::sin(phase) * towards_light.linear().col(1));
    poses.push_back(look_at(eye, target + wobble));
  }
  return poses;
}

}  // namespace glint::render
