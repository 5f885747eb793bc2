#pragma once
// Camera trajectories and intrinsics on disk.
//  - TUM RGB-D trajectory: one pose per line, "timestamp tx ty tz qx qy qz qw" (camera-to-world,
//    metres, unit quaternion), '#' comment lines ignored (Sturm et al. 2012).
//  - intrinsics.json: {"width", "height", "fx", "fy", "cx", "cy"} (glint's sequence format),
//    extra keys (e.g. "depth_scale") are left to the caller.
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "core/camera.h"

namespace glint::io {

struct StampedPose {
  double timestamp = 0;  // seconds
  Pose pose = Pose::Identity();
};

// Throws glint::Error naming the file and line on a malformed line, a non-finite value or a
// quaternion far from unit length (|q| outside [0.9, 1.1]); q is normalised on read.
std::vector<StampedPose> read_tum_trajectory(const std::string& path);
// Written atomically, 9 significant digits, with a header comment.
void write_tum_trajectory(const std::string& path, const std::vector<StampedPose>& poses);

Intrinsics read_intrinsics_json(const std::string& path);
// The same from an already parsed file (`path` names it in errors).
Intrinsics intrinsics_from_json(const nlohmann::json& json, const std::string& path);
void write_intrinsics_json(const std::string& path, const Intrinsics& intrinsics);

}  // namespace glint::io
