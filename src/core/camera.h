#pragma once
// Pinhole camera model and rigid poses shared by the renderer, fusion and the reflectance
// pipeline. Camera axes follow OpenCV: x right, y down, z forward (into the scene); pixel
// (u, v) has its centre at integer coordinates, so the image spans [-0.5, width - 0.5].
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace glint {

// Axial depth noise of a Kinect-like time-of-flight sensor at depth z (metres): sigma(z) =
// 0.0012 + 0.0019 (z - 0.4)^2 (Nguyen, Izadi and Lovell 2012). Float, or a vector of floats.
template <class Float>
inline Float kinect_axial_noise_m(Float z) {
  return 0.0012f + 0.0019f * (z - 0.4f) * (z - 0.4f);
}

// Rigid transform; by convention a camera pose maps camera coordinates to world coordinates
// (camera-to-world), as in TUM groundtruth.txt and 7-Scenes pose.txt files.
using Pose = Eigen::Isometry3d;

struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0;  // focal lengths, pixels
  double cx = 0, cy = 0;  // principal point, pixels

  bool valid() const { return width > 0 && height > 0 && fx != 0 && fy != 0; }

  // Pixel (u, v) at depth z (metres along the optical axis) -> camera-space point.
  Eigen::Vector3d back_project(double u, double v, double z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
  // Camera-space point -> pixel (u, v); the caller checks p.z() > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  // Camera-space direction of the ray through pixel (u, v), z component 1 (not normalised).
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }

  // The same camera at another resolution (pyramids, thumbnails): pixel centres stay aligned.
  Intrinsics scaled(double factor) const {
    return {static_cast<int>(width * factor + 0.5),
            static_cast<int>(height * factor + 0.5),
            fx * factor,
            fy * factor,
            (cx + 0.5) * factor - 0.5,
            (cy + 0.5) * factor - 0.5};
  }
  // The same camera at another image size, each axis scaled on its own (the aspect ratio may
  // change): pixel centres stay aligned.
  Intrinsics resized(int new_width, int new_height) const {
    const double sx = double(new_width) / width, sy = double(new_height) / height;
    return {new_width, new_height, fx * sx, fy * sy, (cx + 0.5) * sx - 0.5, (cy + 0.5) * sy - 0.5};
  }
};

// Kinect v2 depth camera, registered RGB-D at 512x424 (the thesis's sensor; typical factory
// calibration values, libfreenect2's defaults).
inline Intrinsics kinect_v2_intrinsics() { return {512, 424, 365.0, 365.0, 255.5, 211.5}; }

}  // namespace glint
