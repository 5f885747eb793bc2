#include "io/trajectory.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/limits.h"
#include "io/atomic_file.h"
#include "io/json_report.h"
#include "io/rgbd_parsing.h"

namespace glint::io {

std::vector<StampedPose> read_tum_trajectory(const std::string& path) {
  std::vector<StampedPose> poses;
  for (const rgbd::TextRow& row : rgbd::read_rows(path)) {
    const std::string element = "line " + std::to_string(row.line);
    if (row.fields.size() < 8)
      throw Error(path, element, "expected 8 finite numbers 'timestamp tx ty tz qx qy qz qw'");
    double v[8];
    for (std::size_t i = 0; i < 8; ++i) v[i] = rgbd::parse_number(path, row, i);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (norm < 0.9 || norm > 1.1)
      throw Error(path, element, fmt::format("quaternion has length {:.4g}, not 1", norm));
    StampedPose stamped;
    stamped.timestamp = v[0];
    stamped.pose.linear() = q.normalized().toRotationMatrix();
    stamped.pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    limits::check_position(stamped.pose.translation(), path, element + " (tx ty tz)");
    poses.push_back(stamped);
  }
  return poses;
}

void write_tum_trajectory(const std::string& path, const std::vector<StampedPose>& poses) {
  AtomicFile file(path, false);
  file.stream() << "# timestamp tx ty tz qx qy qz qw (camera-to-world, metres)\n";
  for (const StampedPose& p : poses) {
    const Eigen::Quaterniond q(p.pose.rotation());
    const Eigen::Vector3d t = p.pose.translation();
    file.stream() << fmt::format("{:.6f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n",
                                 p.timestamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  file.commit();
}

Intrinsics read_intrinsics_json(const std::string& path) {
  return intrinsics_from_json(read_json(path), path);
}

Intrinsics intrinsics_from_json(const nlohmann::json& json, const std::string& path) {
  Intrinsics k;
  try {
    k.width = json.at("width").get<int>();
    k.height = json.at("height").get<int>();
    k.fx = json.at("fx").get<double>();
    k.fy = json.at("fy").get<double>();
    k.cx = json.at("cx").get<double>();
    k.cy = json.at("cy").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "",
                std::string("intrinsics need width, height, fx, fy, cx, cy: ") + e.what());
  }
  limits::check_intrinsics(k, path, "");
  return k;
}

void write_intrinsics_json(const std::string& path, const Intrinsics& k) {
  write_json(path, {{"width", k.width},
                    {"height", k.height},
                    {"fx", k.fx},
                    {"fy", k.fy},
                    {"cx", k.cx},
                    {"cy", k.cy}});
}

}  // namespace glint::io
