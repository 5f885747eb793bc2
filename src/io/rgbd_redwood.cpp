// Redwood / Open3D RGB-D folders (redwood-data.org/indoor/fileformat.html).
#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/limits.h"
#include "io/json_report.h"
#include "io/rgbd_parsing.h"
#include "io/rgbd_sequence.h"

namespace glint::io {
namespace {

constexpr double kFramesPerSecond = 30;

std::vector<std::string> sorted_images(const std::string& folder) {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    if (entry.is_regular_file() &&
        (extension == ".png" || extension == ".jpg" || extension == ".jpeg"))
      paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

// Open3D's PinholeCameraIntrinsic JSON: width, height, intrinsic_matrix (3x3, column-major).
Intrinsics read_open3d_intrinsics(const std::string& path) {
  const nlohmann::json json = read_json(path);
  try {
    const auto k = json.at("intrinsic_matrix").get<std::vector<double>>();
    if (k.size() != 9) throw Error(path, "intrinsic_matrix", "expected 9 numbers");
    Intrinsics intrinsics{
        json.at("width").get<int>(), json.at("height").get<int>(), k[0], k[4], k[6], k[7]};
    limits::check_intrinsics(intrinsics, path, "intrinsic_matrix");
    return intrinsics;
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "", std::string("expected width, height, intrinsic_matrix: ") + e.what());
  }
}

// .log trajectory: per entry "id id next_id" then 4 rows of a camera-to-world matrix.
std::vector<Pose> read_log_trajectory(const std::string& path) {
  const std::vector<rgbd::TextRow> rows = rgbd::read_rows(path);
  if (rows.size() % 5 != 0)
    throw Error(path, "", "expected entries of 5 lines ('id id next_id' + 4 matrix rows)");
  std::vector<Pose> poses;
  for (std::size_t first = 0; first < rows.size(); first += 5) {
    if (rows[first].fields.size() != 3)
      throw Error(path, "line " + std::to_string(rows[first].line), "expected 'id id next_id'");
    const Eigen::Matrix4d matrix = rgbd::parse_matrix(path, rows, first + 1, 4, 4);
    poses.push_back(
        rgbd::pose_from_matrix(path, "line " + std::to_string(rows[first + 1].line), matrix));
  }
  return poses;
}

}  // namespace

RgbdSequence open_redwood_sequence(const std::string& folder) {
  const std::string colour_folder = rgbd::exists(rgbd::join(folder, "color"))
                                        ? rgbd::join(folder, "color")
                                        : rgbd::join(folder, "image");
  const std::vector<std::string> colours = sorted_images(colour_folder);
  const std::vector<std::string> depths = sorted_images(rgbd::join(folder, "depth"));
  if (depths.empty()) throw Error(rgbd::join(folder, "depth"), "", "no depth images");
  if (colours.size() != depths.size())
    throw Error(colour_folder, "",
                "holds " + std::to_string(colours.size()) + " images but depth/ holds " +
                    std::to_string(depths.size()));

  RgbdSequence sequence;
  sequence.folder = folder;
  sequence.format = "redwood";
  sequence.depth_units_per_metre = 1000;
  const std::string intrinsics_path = rgbd::join(folder, "camera_primesense.json");
  if (rgbd::exists(intrinsics_path)) {
    sequence.intrinsics = read_open3d_intrinsics(intrinsics_path);
  } else {  // PrimeSense defaults (Open3D's PinholeCameraIntrinsicParameters::PrimeSenseDefault)
    const cv::Mat first_depth = rgbd::decode_image(depths.front(), cv::IMREAD_UNCHANGED);
    sequence.intrinsics = {first_depth.cols, first_depth.rows, 525, 525, 319.5, 239.5};
  }
  const std::string log_path = rgbd::join(folder, "trajectory.log");
  const std::vector<Pose> poses =
      rgbd::exists(log_path) ? read_log_trajectory(log_path) : std::vector<Pose>{};
  if (!poses.empty() && poses.size() != depths.size())
    throw Error(log_path, "",
                "has " + std::to_string(poses.size()) + " poses for " +
                    std::to_string(depths.size()) + " frames");
  for (std::size_t i = 0; i < depths.size(); ++i) {
    RgbdFrameFiles frame{colours[i], depths[i], i / kFramesPerSecond, std::nullopt};
    if (!poses.empty()) frame.ground_truth = poses[i];
    sequence.frames.push_back(frame);
  }
  return sequence;
}

}  // namespace glint::io
