#pragma once
// A quick look at a coloured point cloud as a PNG: orthographic view, z-buffered square
// splats, depth shading. For figures and sanity checks, not a renderer.
#include <cstdint>
#include <string>
#include <vector>

#include "core/point_cloud.h"

namespace glint::app {

struct PreviewParams {
  int width = 1200;
  int height = 900;
  double azimuth_deg = 35;    // rotation of the view around the up axis
  double elevation_deg = 25;  // angle above the horizontal plane
  char up_axis = 'z';         // 'y' or 'z'
};

// The picture as PNG bytes. Colours from the cloud's uchar red/green/blue attributes; `path`
// names the output in errors.
std::vector<std::uint8_t> encode_point_preview(const std::string& path, const PointCloud& cloud,
                                               const PreviewParams& params = {});
// Writes encode_point_preview's bytes atomically (io/atomic_file.h: missing folders are made).
void write_png_bytes(const std::string& path, const std::vector<std::uint8_t>& png);
void write_point_preview(const std::string& path, const PointCloud& cloud,
                         const PreviewParams& params = {});

}  // namespace glint::app
