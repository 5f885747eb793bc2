#include "reflectance/light_capture.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "render/perceptual.h"

namespace glint::reflectance {

std::vector<LightSample> bright_samples(const ImageF& linear_rgb, const ImageF& depth,
                                        const Intrinsics& intrinsics, const Pose& camera_to_world,
                                        const LightCaptureParams& params) {
  if (linear_rgb.channels() != 3 || depth.channels() != 1 || !linear_rgb.same_size(depth))
    throw Error("light capture", "",
                "needs a 3-channel colour and a 1-channel depth image of one size");
  std::vector<LightSample> samples;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const Eigen::Vector3f rgb(linear_rgb.at(x, y, 0), linear_rgb.at(x, y, 1),
                                linear_rgb.at(x, y, 2));
      const float luminance = render::luminance(rgb);
      const float z = depth.at(x, y, 0);
      if (luminance < params.min_luminance || !(z > 0) || !std::isfinite(z)) continue;
      LightSample s;
      s.position = camera_to_world * intrinsics.back_project(x, y, z);
      s.radiance = rgb / params.exposure;
      samples.push_back(s);
    }
  return samples;
}

std::vector<LightSample> light_candidates(const ImageF& linear_rgb, const ImageF& depth,
                                          const Intrinsics& intrinsics, const Pose& camera_to_world,
                                          const LightCaptureParams& params) {
  std::vector<LightSample> clusters = mean_shift(
      bright_samples(linear_rgb, depth, intrinsics, camera_to_world, params), params.clustering);
  clusters.erase(
      std::remove_if(clusters.begin(), clusters.end(),
                     [&](const LightSample& c) { return c.weight < params.min_cluster_px; }),
      clusters.end());
  return clusters;
}

}  // namespace glint::reflectance
