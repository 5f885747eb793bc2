#pragma once
// Absolute trajectory error (Sturm et al. 2012, TUM RGB-D benchmark): the RMSE of the camera
// positions after the rigid alignment of the estimate onto the ground truth that minimises it
// (Horn 1987 / Umeyama 1991, no scale).
#include <vector>

#include "core/camera.h"

namespace glint::fusion {

struct TrajectoryError {
  double rmse_m = 0;
  double mean_m = 0;
  double median_m = 0;
  double max_m = 0;
  std::size_t poses = 0;
};

// estimated[i] and ground_truth[i] are the same frame's camera-to-world poses. Needs at least
// 3 pairs (glint::Error otherwise).
TrajectoryError absolute_trajectory_error(const std::vector<Pose>& estimated,
                                          const std::vector<Pose>& ground_truth);

}  // namespace glint::fusion
