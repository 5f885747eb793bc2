// TUM RGB-D folders and glint's synthetic sequences (a TUM-like layout with intrinsics.json).
#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "io/json_report.h"
#include "io/rgbd_parsing.h"
#include "io/rgbd_sequence.h"

namespace glint::io {
namespace {

constexpr double kMaxTimeDifferenceS = 0.02;  // TUM associate.py's default

struct StampedFile {
  double timestamp_s = 0;
  std::string path;
};

std::vector<StampedFile> read_file_list(const std::string& folder, const std::string& name) {
  const std::string path = rgbd::join(folder, name);
  std::vector<StampedFile> files;
  for (const rgbd::TextRow& row : rgbd::read_rows(path)) {
    if (row.fields.size() < 2)
      throw Error(path, "line " + std::to_string(row.line), "expected 'timestamp filename'");
    files.push_back({rgbd::parse_number(path, row, 0), rgbd::join(folder, row.fields[1])});
  }
  return files;
}

// associations.txt: "t_rgb rgb_file t_depth depth_file" (depth first is accepted too).
std::vector<RgbdFrameFiles> read_associations(const std::string& folder) {
  const std::string path = rgbd::join(folder, "associations.txt");
  std::vector<RgbdFrameFiles> frames;
  for (const rgbd::TextRow& row : rgbd::read_rows(path)) {
    if (row.fields.size() < 4)
      throw Error(path, "line " + std::to_string(row.line),
                  "expected 't_rgb rgb_file t_depth depth_file'");
    const bool depth_first = row.fields[1].find("depth") != std::string::npos;
    const std::size_t colour = depth_first ? 2 : 0;
    const std::size_t depth = depth_first ? 0 : 2;
    RgbdFrameFiles frame;
    frame.colour_path = rgbd::join(folder, row.fields[colour + 1]);
    frame.depth_path = rgbd::join(folder, row.fields[depth + 1]);
    rgbd::parse_number(path, row, colour);
    frame.timestamp_s = rgbd::parse_number(path, row, depth);
    frames.push_back(frame);
  }
  return frames;
}

// rgb.txt + depth.txt: each depth image with the colour image nearest in time (<= 0.02 s);
// depth images without one are skipped.
std::vector<RgbdFrameFiles> associate_lists(const std::string& folder) {
  std::vector<StampedFile> colours = read_file_list(folder, "rgb.txt");
  const std::vector<StampedFile> depths = read_file_list(folder, "depth.txt");
  std::ranges::sort(colours, {}, &StampedFile::timestamp_s);
  std::vector<RgbdFrameFiles> frames;
  for (const StampedFile& depth : depths) {
    if (const StampedFile* colour = rgbd::nearest_in_time(colours, &StampedFile::timestamp_s,
                                                          depth.timestamp_s, kMaxTimeDifferenceS))
      frames.push_back({colour->path, depth.path, depth.timestamp_s, std::nullopt});
  }
  return frames;
}

void attach_ground_truth(const std::string& folder, std::vector<RgbdFrameFiles>& frames) {
  const std::string path = rgbd::join(folder, "groundtruth.txt");
  if (!rgbd::exists(path)) return;
  std::vector<StampedPose> poses = read_tum_trajectory(path);
  std::ranges::sort(poses, {}, &StampedPose::timestamp);
  for (RgbdFrameFiles& frame : frames) {
    if (const StampedPose* nearest = rgbd::nearest_in_time(poses, &StampedPose::timestamp,
                                                           frame.timestamp_s, kMaxTimeDifferenceS))
      frame.ground_truth = nearest->pose;
  }
}

void require_images(const std::vector<RgbdFrameFiles>& frames) {
  for (const RgbdFrameFiles& frame : frames) {
    rgbd::require_file(frame.colour_path, "colour image");
    rgbd::require_file(frame.depth_path, "depth image");
  }
}

// TUM's published calibrations (vision.in.tum.de, "Intrinsic Camera Calibration of the Kinect").
Intrinsics tum_intrinsics_for(const std::string& folder) {
  const std::string name = std::filesystem::absolute(folder).lexically_normal().string();
  if (name.find("freiburg1") != std::string::npos) return {640, 480, 517.3, 516.5, 318.6, 255.3};
  if (name.find("freiburg2") != std::string::npos) return {640, 480, 520.9, 521.0, 325.1, 249.7};
  if (name.find("freiburg3") != std::string::npos) return {640, 480, 535.4, 539.2, 320.1, 247.6};
  return {640, 480, 525.0, 525.0, 319.5, 239.5};
}

}  // namespace

RgbdSequence open_tum_sequence(const std::string& folder) {
  RgbdSequence sequence;
  sequence.folder = folder;
  sequence.format = "tum";
  sequence.depth_units_per_metre = 5000;
  const std::string intrinsics_path = rgbd::join(folder, "intrinsics.json");
  sequence.intrinsics = rgbd::exists(intrinsics_path) ? read_intrinsics_json(intrinsics_path)
                                                      : tum_intrinsics_for(folder);
  sequence.frames = rgbd::exists(rgbd::join(folder, "associations.txt")) ? read_associations(folder)
                                                                         : associate_lists(folder);
  require_images(sequence.frames);
  attach_ground_truth(folder, sequence.frames);
  return sequence;
}

RgbdSequence open_glint_sequence(const std::string& folder) {
  RgbdSequence sequence;
  sequence.folder = folder;
  sequence.format = "glint";
  const std::string intrinsics_path = rgbd::join(folder, "intrinsics.json");
  const nlohmann::json json = read_json(intrinsics_path);
  sequence.intrinsics = intrinsics_from_json(json, intrinsics_path);
  if (json.contains("depth_scale")) {
    if (!json["depth_scale"].is_number() || json["depth_scale"].get<double>() <= 0)
      throw Error(intrinsics_path, "depth_scale", "must be a positive number");
    sequence.depth_units_per_metre = json["depth_scale"].get<double>();
  }
  sequence.frames = read_associations(folder);
  require_images(sequence.frames);
  attach_ground_truth(folder, sequence.frames);
  return sequence;
}

}  // namespace glint::io
