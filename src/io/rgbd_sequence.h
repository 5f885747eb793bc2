#pragma once
// RGB-D sequences on disk: one streaming interface over the dataset layouts glint reads.
// Opening a folder parses its index files (lists, associations, poses, intrinsics) and checks
// that every listed image exists; frames are decoded one at a time by read_rgbd_frame().
//
// Layouts (open_rgbd_sequence() detects them in this order):
//  - glint synthetic: intrinsics.json (+ "depth_scale", default 1000) and associations.txt
//    ("t_rgb rgb/N.png t_depth depth/N.png"), groundtruth.txt (TUM) optional.
//  - TUM RGB-D (Sturm et al. 2012): associations.txt, or rgb.txt + depth.txt associated by
//    nearest timestamp (<= 0.02 s); depth scale 5000; groundtruth.txt matched by nearest
//    timestamp (<= 0.02 s; frames without a match have no ground truth). Intrinsics from
//    intrinsics.json when present, else the freiburg1/2/3 values when the folder name says
//    so, else the ROS default (525, 525, 319.5, 239.5).
//  - 7-Scenes / tsdf-fusion: frame-NNNNNN.{color.png,depth.png,pose.txt} in the folder or in
//    rgbd-frames/, camera-intrinsics.txt (3x3 K) in the folder or its parent, image size from
//    the first depth image; depth in mm;
//    pose.txt a 4x4 camera-to-world matrix (a frame without one has no ground truth).
//  - Redwood / Open3D: color/ and depth/ (paired in sorted order), depth in mm, intrinsics
//    from camera_primesense.json (Open3D PinholeCameraIntrinsic, column-major K) or the
//    PrimeSense default, poses from trajectory.log ("id id next_id" + 4 rows, camera-to-world).
// Depth: z along the optical axis in metres; 0 means no measurement (stored 0 and 65535 both
// read as 0). Colour: linear RGB in [0,1] (8-bit sRGB decoded), same size as the depth.
// Frames without a timestamp get index / 30 s.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/image.h"

namespace glint::io {

struct RgbdFrameFiles {
  std::string colour_path;
  std::string depth_path;
  double timestamp_s = 0;
  std::optional<Pose> ground_truth;  // camera-to-world
};

struct RgbdSequence {
  std::string folder;
  std::string format;  // "glint", "tum", "7scenes" or "redwood"
  Intrinsics intrinsics;
  double depth_units_per_metre = 1000;  // stored value / this = metres
  std::vector<RgbdFrameFiles> frames;

  bool has_ground_truth() const;
  // Throws glint::Error naming the folder and the first of frames [0, count) without a
  // ground-truth pose (its pose file has none for it), the reason ending in `needed_for`.
  void require_ground_truth(std::size_t count, const std::string& needed_for) const;
};

struct RgbdFrame {
  std::size_t index = 0;
  double timestamp_s = 0;
  ImageF colour;   // 3 channels, linear RGB
  ImageF depth_m;  // 1 channel, metres, 0 = no measurement
  std::optional<Pose> ground_truth;
};

// Detects the layout of `folder` and opens it. Throws glint::Error naming the folder when no
// layout matches, or naming the file that is missing or malformed.
RgbdSequence open_rgbd_sequence(const std::string& folder);

RgbdSequence open_glint_sequence(const std::string& folder);
RgbdSequence open_tum_sequence(const std::string& folder);
RgbdSequence open_7scenes_sequence(const std::string& folder);
RgbdSequence open_redwood_sequence(const std::string& folder);

// Decodes frame i. Throws glint::Error naming the image file when it is missing, unreadable,
// not 16-bit single-channel (depth), or not of the intrinsics' size (depth and colour).
RgbdFrame read_rgbd_frame(const RgbdSequence& sequence, std::size_t i);

}  // namespace glint::io
