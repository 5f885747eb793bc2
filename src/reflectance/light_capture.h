#pragma once
// Light candidates from one frame of the low-exposure light-capture sequence (paper 1 §3.2):
// pixels whose luminance reaches a threshold are back-projected with their depth and the
// camera pose, then clustered by mean shift. Pixels without depth (a real sensor often has
// none on a lamp) are skipped.
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "reflectance/light_clustering.h"

namespace glint::reflectance {

struct LightCaptureParams {
  // Linear luminance (Rec. 709 weights) of a pixel in [0, 1]; the built-in captures
  // (render::kLightCaptureExposure) read >= 0.29 on light proxies, < 0.02 on lit surfaces.
  float min_luminance = 0.05f;
  float exposure = 1.0f;  // the capture's exposure: sample radiance = pixel / exposure
  MeanShiftParams clustering;
  double min_cluster_px = 10;  // smaller clusters are noise or glints
};

// linear_rgb: 3 channels in [0, 1]; depth: metres (0 = none), same size.
std::vector<LightSample> bright_samples(const ImageF& linear_rgb, const ImageF& depth,
                                        const Intrinsics& intrinsics, const Pose& camera_to_world,
                                        const LightCaptureParams& params);

// bright_samples, clustered; clusters smaller than min_cluster_px are dropped.
std::vector<LightSample> light_candidates(const ImageF& linear_rgb, const ImageF& depth,
                                          const Intrinsics& intrinsics, const Pose& camera_to_world,
                                          const LightCaptureParams& params = {});

}  // namespace glint::reflectance
