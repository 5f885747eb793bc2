#pragma once
// Camera paths for the synthetic sequences (paper 1 §4.2: "a camera moving around [the
// objects] in an oscillating manner"; Fig. 3: the camera 4 m from the scene's centre).
// Every pose is camera-to-world with OpenCV camera axes (x right, y down in the image, z
// forward), in a world with +y up, metres.
#include <Eigen/Core>
#include <vector>

#include "core/camera.h"

namespace glint::render {

// The pose of a camera at `eye` looking at `target`: camera z points at the target, world `up`
// appears up in the image (camera y is the image's down direction). Throws glint::Error when
// eye and target coincide or the view direction is parallel to `up`.
Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
             const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

// A horizontal circle of camera positions around a vertical axis, all looking at one point.
struct CameraRing {
  Eigen::Vector3d centre{0, 0, 0};  // a point on the vertical axis, usually on the floor
  double radius_m = 4;              // horizontal distance of the camera from the axis
  double height_m = 1.5;            // camera height above centre.y()
  Eigen::Vector3d target{0, 0.5, 0};
};

// The camera on `ring` at azimuth `azimuth_deg` about +y: 0 deg lies on the +z side of the
// axis, 90 deg on the +x side. Height offsets the camera vertically from ring.height_m.
Pose ring_pose(const CameraRing& ring, double azimuth_deg, double height_offset_m = 0);

// Orbit: frame i sits at azimuth start_deg + arc_deg * i / frames, so a 360 deg orbit closes
// without repeating its first pose and a shorter arc stops one step before start + arc.
struct OrbitParams {
  CameraRing ring;
  double start_deg = 0;
  double arc_deg = 360;
  int frames = 300;
};
std::vector<Pose> orbit_trajectory(const OrbitParams& params);

// Oscillation: the camera swings back and forth around centre_deg,
//   azimuth_i = centre_deg + amplitude_deg * sin(2 pi periods i / frames),
// and bobs vertically by height_amplitude_m * sin(4 pi periods i / frames), so surfaces are
// seen again from changing elevations (as a hand-held scan does).
struct OscillationParams {
  CameraRing ring;
  double centre_deg = 0;
  double amplitude_deg = 45;
  double periods = 2;  // full back-and-forth swings over the sequence
  double height_amplitude_m = 0.3;
  int frames = 300;
};
std::vector<Pose> oscillation_trajectory(const OscillationParams& params);

// The light-capture path (paper 1 §3.2): the camera stands `standoff_m` (horizontally) from
// the lights' centroid at eye_height_m, walks arc_deg around it and points at each light in
// turn (an equal block of frames each), the target circling the light by wobble_deg so the
// light crosses different parts of the image.
struct LightCaptureParams {
  double standoff_m = 2.5;
  double eye_height_m = 1.2;
  double arc_deg = 60;
  double wobble_deg = 8;
  int frames = 60;
};
// Throws glint::Error for no lights or fewer frames than lights.
std::vector<Pose> light_capture_trajectory(const std::vector<Eigen::Vector3d>& light_positions,
                                           const LightCaptureParams& params);

}  // namespace glint::render
