#pragma once
// Renders a scene's trajectory into glint's on-disk RGB-D sequence format (docs/reflectance.md):
//   intrinsics.json (+ "depth_scale": 1000), rgb/NNNNNN.png (8-bit sRGB), depth/NNNNNN.png
//   (uint16 z-depth in mm, 0 = none), associations.txt, groundtruth.txt (TUM, camera-to-world),
//   gt/{depth,normal,kd,ks,alpha}/NNNNNN.exr and gt/segment/NNNNNN.png (uint16 ids), scene.json.
// Everything is written into "<out_dir>.partial-<pid>" and renamed onto out_dir at the end
// (an existing out_dir is replaced), so a failure never leaves a sequence that looks complete.
#include <string>

#include "render/scene.h"

namespace glint::render {

struct SequenceOptions {
  int first_frame = 0;       // first trajectory index rendered
  int frame_count = -1;      // frames from first_frame (clamped to the end), -1 = all
  bool ground_truth = true;  // write gt/
  bool progress = true;      // show a progress bar over the frames (core/progress.h)
};

struct SequenceStats {
  int frames = 0;
  double seconds = 0;           // wall-clock total, files included
  double median_render_ms = 0;  // per frame, rendering only (no sensor model, no files)
  double median_frame_ms = 0;   // per frame, everything
};

// Throws glint::Error for an empty frame range or unwritable output.
SequenceStats write_sequence(const Scene& scene, const std::string& out_dir,
                             const SequenceOptions& options = {});

}  // namespace glint::render
