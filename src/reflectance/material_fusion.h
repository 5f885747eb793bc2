#pragma once
// Temporal material fusion (paper 1 §3.6, end): per segment, a running average of the per-frame
// estimates whose divisor is clamped (60 in the paper), so after `max_divisor` frames new
// estimates keep a fixed weight 1/max_divisor instead of vanishing.
#include <Eigen/Core>
#include <algorithm>

namespace glint::reflectance {

template <int N>
class ClampedRunningMean {
 public:
  using Vector = Eigen::Matrix<float, N, 1>;

  explicit ClampedRunningMean(int max_divisor = 60) : max_divisor_(std::max(1, max_divisor)) {}

  void add(const Vector& estimate) {
    count_ = std::min(count_ + 1, max_divisor_);
    mean_ += (estimate - mean_) / float(count_);
  }
  const Vector& mean() const { return mean_; }
  int count() const { return count_; }
  bool empty() const { return count_ == 0; }

 private:
  int max_divisor_;
  int count_ = 0;
  Vector mean_ = Vector::Zero();
};

}  // namespace glint::reflectance
