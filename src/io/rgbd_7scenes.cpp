// 7-Scenes / tsdf-fusion frame folders (Shotton et al. 2013; github.com/andyzeng/tsdf-fusion).
#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/limits.h"
#include "io/rgbd_parsing.h"
#include "io/rgbd_sequence.h"

namespace glint::io {
namespace {

constexpr double kFramesPerSecond = 30;  // Kinect v1; the folders carry no timestamps

std::string frames_folder(const std::string& folder) {
  const std::string nested = rgbd::join(folder, "rgbd-frames");
  return std::filesystem::is_directory(nested) ? nested : folder;
}

Intrinsics read_camera_intrinsics(const std::string& folder, const std::string& frames, int width,
                                  int height) {
  std::string path = rgbd::join(folder, "camera-intrinsics.txt");
  if (!rgbd::exists(path)) path = rgbd::join(frames, "camera-intrinsics.txt");
  if (!rgbd::exists(path))
    path = (std::filesystem::path(folder).parent_path() / "camera-intrinsics.txt").string();
  rgbd::require_file(path, "camera-intrinsics.txt (3x3 K)");
  const Eigen::MatrixXd k = rgbd::parse_matrix(path, rgbd::read_rows(path), 0, 3, 3);
  Intrinsics intrinsics{width, height, k(0, 0), k(1, 1), k(0, 2), k(1, 2)};
  limits::check_intrinsics(intrinsics, path, "K");
  return intrinsics;
}

}  // namespace

RgbdSequence open_7scenes_sequence(const std::string& folder) {
  const std::string frames = frames_folder(folder);
  std::vector<std::string> stems;  // "frame-000150"
  for (const auto& entry : std::filesystem::directory_iterator(frames)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("frame-") && name.ends_with(".depth.png"))
      stems.push_back(name.substr(0, name.size() - std::string(".depth.png").size()));
  }
  // Frames are listed by their depth images: a colour image without one would be dropped.
  for (const auto& entry : std::filesystem::directory_iterator(frames)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("frame-") && name.ends_with(".color.png"))
      rgbd::require_file(
          rgbd::join(frames,
                     name.substr(0, name.size() - std::string(".color.png").size()) + ".depth.png"),
          "the depth image of " + name);
  }
  std::sort(stems.begin(), stems.end());
  if (stems.empty()) throw Error(frames, "", "no frame-*.depth.png files");

  RgbdSequence sequence;
  sequence.folder = folder;
  sequence.format = "7scenes";
  sequence.depth_units_per_metre = 1000;
  // The K file has no image size: it is the first depth image's.
  const cv::Mat first_depth =
      rgbd::decode_image(rgbd::join(frames, stems.front() + ".depth.png"), cv::IMREAD_UNCHANGED);
  sequence.intrinsics = read_camera_intrinsics(folder, frames, first_depth.cols, first_depth.rows);
  for (const std::string& stem : stems) {
    RgbdFrameFiles frame;
    frame.depth_path = rgbd::join(frames, stem + ".depth.png");
    frame.colour_path = rgbd::join(frames, stem + ".color.png");
    rgbd::require_file(frame.colour_path, "colour image");
    const std::string number = stem.substr(std::string("frame-").size());
    frame.timestamp_s = std::strtod(number.c_str(), nullptr) / kFramesPerSecond;
    const std::string pose_path = rgbd::join(frames, stem + ".pose.txt");
    if (rgbd::exists(pose_path)) {
      const Eigen::Matrix4d matrix =
          rgbd::parse_matrix(pose_path, rgbd::read_rows(pose_path), 0, 4, 4);
      frame.ground_truth = rgbd::pose_from_matrix(pose_path, "", matrix);
    }
    sequence.frames.push_back(frame);
  }
  return sequence;
}

}  // namespace glint::io
