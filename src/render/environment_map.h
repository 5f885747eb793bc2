#pragma once
// Distant environment lighting from an equirectangular HDR image (linear RGB radiance).
// Direction <-> image: world +y is up (row 0 is the zenith); a direction d, rotated about +y
// by -rotation_deg, maps to column u = (atan2(d.x, -d.z) / 2pi + 0.5) * width and row
// v = acos(d.y) / pi * height, so the image centre is seen looking along -z.
// Importance sampling picks texels with probability proportional to luminance * sin(theta)
// (inverse CDFs over rows, then columns) and returns the solid-angle pdf.
#include <Eigen/Core>
#include <vector>

#include "render/scene.h"

namespace glint::render {

struct EnvironmentSample {
  Eigen::Vector3f direction;  // unit, world space, pointing away from the shaded point
  Eigen::Vector3f radiance;   // scaled by Environment::scale
  float pdf = 0;              // per steradian, > 0
};

class EnvironmentMap {
 public:
  // Loads settings.path (.hdr or .exr); throws glint::Error naming it when it cannot be read or
  // holds no light at all.
  explicit EnvironmentMap(const Environment& settings);

  // Radiance arriving from direction `direction` (unit, world space).
  Eigen::Vector3f radiance(const Eigen::Vector3f& direction) const;

  // Importance sample from two uniform numbers in [0, 1).
  EnvironmentSample sample(float u1, float u2) const;

 private:
  std::size_t texel_of(const Eigen::Vector3f& direction) const;

  int width_ = 0;
  int height_ = 0;
  float scale_ = 1;
  Eigen::Matrix3f world_to_map_;          // rotation about +y by -rotation_deg
  std::vector<Eigen::Vector3f> texels_;   // row-major, row 0 = zenith
  std::vector<float> row_cdf_;            // height_ + 1 entries, 0 .. 1
  std::vector<float> column_cdf_;         // per row width_ + 1 entries, 0 .. 1
  std::vector<float> texel_probability_;  // discrete probability of each texel
};

}  // namespace glint::render
