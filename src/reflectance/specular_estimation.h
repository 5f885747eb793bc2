#pragma once
// Per-segment Ward parameters (paper 1 §3.6): every frame, each segment seen in it samples
// voxels_per_estimate (25) of its voxels from its ring buffer (repeating them where it has
// fewer, but at least min_distinct_voxels), turns their observations into
// HemiImages, and the HemiCNN predicts one material from the set. The per-frame estimates are
// fused over time by a running mean whose divisor is clamped (60), per Ward parameter.
// With fit_lobe (glint's addition, reflectance/specular_fit.h) a photometric fit of the Ward
// lobe to the same voxels' observations also runs; where it explains them, its ks and alpha
// are fused separately, each weighted by how well it explains the observations, and replace
// the network's once the segment has min_fits of them. kd is always the network's; the albedo
// stage's refined kd per segment is fused beside it (fuse_refined_albedo), for the
// re-renderings to fall back on.
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "reflectance/hemi_image.h"
#include "reflectance/hemicnn.h"
#include "reflectance/material_fusion.h"
#include "reflectance/observation_grid.h"
#include "reflectance/segment_map.h"
#include "reflectance/specular_fit.h"
#include "render/ward.h"

namespace glint::reflectance {

struct SpecularParams {
  int voxels_per_estimate = 25;
  int min_observations = 5;  // a sampled voxel needs this many observations
  // A segment with fewer qualifying voxels than voxels_per_estimate, but at least this many,
  // repeats them in turn to fill the network's branches (its mean pooling then weighs each about
  // equally; the lobe fit likewise), so that small segments get a material; the paper's
  // sampling is silent on them. Equal to voxels_per_estimate: only segments with enough distinct
  // voxels.
  int min_distinct_voxels = 8;
  int fusion_divisor = 60;  // clamp of the running mean's divisor
  bool fit_lobe = true;     // false: the paper's HemiCNN-only estimate
  int min_fits = 10;        // frames with a lobe fit before the fits replace the network
  SpecularFitParams fit;
  std::uint64_t seed = 1;
};

// Fused estimate of one segment.
struct SegmentMaterial {
  render::WardMaterial ward;    // the fused (kd, ks, alpha)
  render::WardMaterial latest;  // the latest frame's estimate
  int estimates = 0;            // frames that produced an estimate
  int fitted = 0;               // of those, frames whose ks, alpha came from the lobe fit
  int last_frame = -1;
  // The segment's refined diffuse albedo (§3.7): per frame the mean refined kd of its voxels
  // solved reliably in it, fused over frames like the estimates. The re-rendering's albedo where
  // no voxel around a point has a refined one (reflectance/material_maps.h); unset before then.
  std::optional<Eigen::Vector3f> kd_refined;
};

class SpecularEstimator {
 public:
  // The network's projection (parabolic or orthographic) is used for the HemiImages.
  SpecularEstimator(const HemiCnn& network, const SpecularParams& params = {});

  // Estimates every segment in `segments` that has enough sampled voxels, and fuses. `lights`
  // are those of the scene, for the lobe fit.
  void update(const ObservationGrid& grid, const SegmentMap& segment_map,
              const std::vector<int>& segments, const std::vector<render::PointLight>& lights,
              int frame);

  // Fuses one frame's refined albedo of `segment` into its SegmentMaterial::kd_refined; ignored
  // for a segment without a material yet.
  void fuse_refined_albedo(int segment, const Eigen::Vector3f& kd);

  // The fused material of a segment, or nullptr before its first estimate.
  const SegmentMaterial* material(int segment) const;
  const std::map<int, SegmentMaterial>& materials() const { return materials_; }

 private:
  const HemiCnn& network_;
  SpecularParams params_;
  HemiImageParams hemi_;
  std::map<int, SegmentMaterial> materials_;
  std::map<int, ClampedRunningMean<7>> fused_;             // the network's (kd, ks, alpha)
  std::map<int, WeightedRunningMean<4>> fused_lobe_;       // the fits' (ks, alpha)
  std::map<int, ClampedRunningMean<3>> fused_refined_kd_;  // the albedo stage's per-frame means
};

}  // namespace glint::reflectance
