#include "io/rgbd_sequence.h"

#include <fmt/format.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/rgbd_parsing.h"

namespace glint::io {
namespace {

bool has_7scenes_frames(const std::string& folder) {
  for (const std::string& candidate : {folder, rgbd::join(folder, "rgbd-frames")}) {
    if (!std::filesystem::is_directory(candidate)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(candidate)) {
      const std::string name = entry.path().filename().string();
      if (name.starts_with("frame-") && name.ends_with(".depth.png")) return true;
    }
  }
  return false;
}

void require_size(const std::string& path, const cv::Mat& image, const Intrinsics& k) {
  if (image.cols != k.width || image.rows != k.height)
    throw Error(path, "",
                fmt::format("image is {}x{}, the intrinsics say {}x{}", image.cols, image.rows,
                            k.width, k.height));
}

// 8-bit sRGB -> linear (IEC 61966-2-1), one table entry per code value.
const std::array<float, 256>& srgb_to_linear_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> values{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      values[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return values;
  }();
  return table;
}

ImageF read_depth(const std::string& path, const RgbdSequence& sequence) {
  const cv::Mat raw = rgbd::decode_image(path, cv::IMREAD_ANYDEPTH);
  if (raw.type() != CV_16UC1) throw Error(path, "", "expected a 16-bit single-channel depth image");
  require_size(path, raw, sequence.intrinsics);
  ImageF depth(raw.cols, raw.rows, 1);
  const float metres_per_unit = static_cast<float>(1.0 / sequence.depth_units_per_metre);
  float* out = depth.plane(0);
  for (int y = 0; y < raw.rows; ++y) {
    const auto* row = raw.ptr<std::uint16_t>(y);
    for (int x = 0; x < raw.cols; ++x) {
      const std::uint16_t value = row[x];
      *out++ = (value == 0 || value == 65535) ? 0.0f : value * metres_per_unit;
    }
  }
  return depth;
}

ImageF read_colour(const std::string& path, const RgbdSequence& sequence) {
  const cv::Mat bgr = rgbd::decode_image(path, cv::IMREAD_COLOR);
  require_size(path, bgr, sequence.intrinsics);
  const auto& linear = srgb_to_linear_table();
  ImageF colour(bgr.cols, bgr.rows, 3);
  float* red = colour.plane(0);
  float* green = colour.plane(1);
  float* blue = colour.plane(2);
  for (int y = 0; y < bgr.rows; ++y) {
    const auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; ++x, ++red, ++green, ++blue) {
      *blue = linear[row[x][0]];
      *green = linear[row[x][1]];
      *red = linear[row[x][2]];
    }
  }
  return colour;
}

}  // namespace

bool RgbdSequence::has_ground_truth() const {
  for (const RgbdFrameFiles& frame : frames) {
    if (frame.ground_truth) return true;
  }
  return false;
}

void RgbdSequence::require_ground_truth(std::size_t count, const std::string& needed_for) const {
  for (std::size_t i = 0; i < std::min(count, frames.size()); ++i)
    if (!frames[i].ground_truth)
      throw Error(folder, "frame " + std::to_string(i) + " (" + frames[i].colour_path + ")",
                  "no ground-truth camera pose; " + needed_for);
}

RgbdSequence open_rgbd_sequence(const std::string& folder) {
  if (!std::filesystem::is_directory(folder))
    throw Error(folder, "", "not a folder (expected an RGB-D sequence folder)");
  const auto has = [&](const char* name) { return rgbd::exists(rgbd::join(folder, name)); };
  if (has("intrinsics.json") && has("associations.txt")) return open_glint_sequence(folder);
  if (has("associations.txt") || (has("rgb.txt") && has("depth.txt")))
    return open_tum_sequence(folder);
  if (has_7scenes_frames(folder)) return open_7scenes_sequence(folder);
  if (has("depth") && (has("color") || has("image"))) return open_redwood_sequence(folder);
  throw Error(folder, "",
              "unknown RGB-D layout: expected intrinsics.json + associations.txt (glint), "
              "rgb.txt + depth.txt or associations.txt (TUM), frame-*.depth.png (7-Scenes) or "
              "color/ + depth/ (Redwood)");
}

RgbdFrame read_rgbd_frame(const RgbdSequence& sequence, std::size_t i) {
  if (i >= sequence.frames.size())
    throw Error(sequence.folder, "frame " + std::to_string(i),
                fmt::format("the sequence has {} frames", sequence.frames.size()));
  const RgbdFrameFiles& files = sequence.frames[i];
  RgbdFrame frame;
  frame.index = i;
  frame.timestamp_s = files.timestamp_s;
  frame.ground_truth = files.ground_truth;
  // The two PNG decodes run side by side: reading was as long as a frame's fusion on 7-Scenes.
  tbb::parallel_invoke([&] { frame.depth_m = read_depth(files.depth_path, sequence); },
                       [&] { frame.colour = read_colour(files.colour_path, sequence); });
  return frame;
}

}  // namespace glint::io
