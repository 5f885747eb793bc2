#pragma once
// Point-light candidates from bright 3D samples (paper 1 §3.2): back-projected pixels of the
// low-exposure light-capture frames are grouped per frame by flat-kernel mean shift, and the
// per-frame candidates are fused over the sequence into point lights.
#include <Eigen/Core>
#include <vector>

namespace glint::reflectance {

// A weighted 3D sample, or a cluster of them.
struct LightSample {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world, metres
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();  // mean linear RGB (pixel / exposure)
  double weight = 1;                                   // pixels represented
};

struct MeanShiftParams {
  double bandwidth_m = 0.2;  // flat-kernel radius
  int max_iterations = 300;
  double tolerance_m = 1e-4;  // a seed has converged when it moves less than this
};

// Flat-kernel mean shift with grid seeding (one seed per occupied bandwidth cell, as
// scikit-learn's bin_seeding): modes closer than the bandwidth merge (the better-supported one
// stays); every sample joins its nearest mode. Returns clusters ordered by decreasing weight,
// each with the weighted mean position and radiance of its samples.
std::vector<LightSample> mean_shift(const std::vector<LightSample>& samples,
                                    const MeanShiftParams& params = {});

struct LightFusionParams {
  double merge_radius_m = 0.3;  // a candidate within this of a fused light updates it
  int min_frames = 3;           // a fused light must be seen in this many frames to count
};

struct FusedLight {
  LightSample estimate;  // weighted means of the candidates merged into it
  int frames = 0;        // distinct frames that saw it
  int last_frame = -1;
};

// Online fusion of per-frame candidates: each candidate updates the nearest fused light within
// merge_radius_m (pixel-weighted mean of position and radiance) or starts a new one.
class LightFuser {
 public:
  explicit LightFuser(LightFusionParams params = {}) : params_(params) {}

  void add_frame(const std::vector<LightSample>& candidates);
  // Lights seen in at least min_frames frames, by decreasing support.
  std::vector<FusedLight> lights() const;

 private:
  LightFusionParams params_;
  std::vector<FusedLight> tracked_;
  int frame_ = -1;
};

}  // namespace glint::reflectance
