#pragma once
// The kd atlas against a synthetic sequence's ground truth (`glint export --albedo-truth`,
// docs/reflectance.md "Export"): the true kd at a surface point is the mean of the gt/kd maps of
// the frames that see it (gt/depth within kDepthToleranceM of the point's depth), and the
// atlas's error is measured over its baked texels, split by how often their voxels were observed.
#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/image.h"

namespace glint::gltf {

class AlbedoTruth {
 public:
  // Every `stride`-th frame of the glint sequence in `folder` (gt/ maps and poses). Throws
  // glint::Error naming the folder when it has neither.
  explicit AlbedoTruth(const std::string& folder, int stride = 5);
  // The true kd at world point p; NaN where no loaded frame sees p.
  Eigen::Vector3f operator()(const Eigen::Vector3f& p) const;
  std::size_t views() const { return views_.size(); }

 private:
  struct View {
    Pose world_to_camera;
    ImageF kd, depth_m;
  };
  Intrinsics intrinsics_;
  std::vector<View> views_;
};

// L1 (mean absolute difference over the channels) and PSNR (peak 1) of `atlas` against `truth`
// over the baked texels (`baked`, row-major) where the truth is finite: "all", "well_observed"
// (observation count, channel 0 of `observations`, at least `well_observed`) and
// "poorly_observed" (the rest), each with its texel count.
nlohmann::json albedo_errors(const ImageF& atlas, const ImageF& truth, const ImageF& observations,
                             const std::vector<std::uint8_t>& baked, float well_observed);

}  // namespace glint::gltf
