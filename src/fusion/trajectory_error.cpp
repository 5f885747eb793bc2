#include "fusion/trajectory_error.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace glint::fusion {

TrajectoryError absolute_trajectory_error(const std::vector<Pose>& estimated,
                                          const std::vector<Pose>& ground_truth) {
  if (estimated.size() != ground_truth.size() || estimated.size() < 3)
    throw Error("trajectory", "",
                "the absolute trajectory error needs >= 3 matched poses, got " +
                    std::to_string(estimated.size()) + " and " +
                    std::to_string(ground_truth.size()));
  const Eigen::Index n = static_cast<Eigen::Index>(estimated.size());
  Eigen::Matrix3Xd from(3, n), to(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    from.col(i) = estimated[i].translation();
    to.col(i) = ground_truth[i].translation();
  }
  const Eigen::Matrix4d alignment = Eigen::umeyama(from, to, false);
  std::vector<double> errors(n);
  double squared = 0, sum = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d aligned =
        alignment.topLeftCorner<3, 3>() * from.col(i) + alignment.topRightCorner<3, 1>();
    errors[i] = (aligned - to.col(i)).norm();
    squared += errors[i] * errors[i];
    sum += errors[i];
  }
  TrajectoryError result;
  result.poses = static_cast<std::size_t>(n);
  result.rmse_m = std::sqrt(squared / n);
  result.mean_m = sum / n;
  result.max_m = *std::max_element(errors.begin(), errors.end());
  std::nth_element(errors.begin(), errors.begin() + n / 2, errors.end());
  result.median_m = errors[n / 2];
  return result;
}

}  // namespace glint::fusion
