#pragma once
// Per-segment Ward parameters (paper 1 §3.6): every frame, each segment seen in it samples
// voxels_per_estimate (25) of its voxels from its ring buffer, turns their observations into
// HemiImages, and the HemiCNN predicts one material from the set. The per-frame estimates are
// fused over time by a running mean whose divisor is clamped (60), per Ward parameter.
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "reflectance/hemi_image.h"
#include "reflectance/hemicnn.h"
#include "reflectance/material_fusion.h"
#include "reflectance/observation_grid.h"
#include "reflectance/segment_map.h"
#include "render/ward.h"

namespace glint::reflectance {

struct SpecularParams {
  int voxels_per_estimate = 25;
  int min_observations = 5;  // a sampled voxel needs this many observations
  int fusion_divisor = 60;   // clamp of the running mean's divisor
  std::uint64_t seed = 1;
};

// Fused estimate of one segment.
struct SegmentMaterial {
  render::WardMaterial ward;    // the fused (kd, ks, alpha)
  render::WardMaterial latest;  // the latest frame's estimate
  int estimates = 0;            // frames that produced an estimate
  int last_frame = -1;
};

class SpecularEstimator {
 public:
  // The network's projection (parabolic or orthographic) is used for the HemiImages.
  SpecularEstimator(const HemiCnn& network, const SpecularParams& params = {});

  // Estimates every segment in `segments` that has enough sampled voxels, and fuses.
  void update(const ObservationGrid& grid, const SegmentMap& segment_map,
              const std::vector<int>& segments, int frame);

  // The fused material of a segment, or nullptr before its first estimate.
  const SegmentMaterial* material(int segment) const;
  const std::map<int, SegmentMaterial>& materials() const { return materials_; }

 private:
  const HemiCnn& network_;
  SpecularParams params_;
  HemiImageParams hemi_;
  std::map<int, SegmentMaterial> materials_;
  std::map<int, ClampedRunningMean<7>> fused_;
};

}  // namespace glint::reflectance
