#pragma once
// Covariance-analysis (CA) edge baseline of Bazazian et al., DICTA 2015: a point is a sharp
// edge when the surface variation lambda_min / (lambda_1 + lambda_2 + lambda_3) of its k
// nearest neighbours' covariance exceeds a threshold. Defaults: threshold 0.025 is the value
// the thesis tuned on Default (§5.5.3); k = 16 is our choice (the thesis does not state it).
#include <cstdint>
#include <vector>

#include "core/point_cloud.h"

namespace glint::edges {

struct CovarianceBaselineParams {
  int k = 16;
  double threshold = 0.025;
};

// Surface variation of every point (in [0, 1/3]).
std::vector<float> surface_variation(const PointCloud& cloud, int k);

// Labels: 1 (sharp) where surface variation > threshold, else 0.
std::vector<std::uint8_t> classify_covariance_baseline(const PointCloud& cloud,
                                                       const CovarianceBaselineParams& params = {});

}  // namespace glint::edges
