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

// The same fusion for estimates of unequal reliability (glint's lobe fits): each enters with
// its weight w, and the weight of the past decays by 1 - 1/max_divisor per estimate, so with
// unit weights the weight sum grows to max_divisor and a new estimate's share falls to
// 1/max_divisor, as the clamp does; a reliable estimate outweighs many poor ones before it.
template <int N>
class WeightedRunningMean {
 public:
  using Vector = Eigen::Matrix<float, N, 1>;

  explicit WeightedRunningMean(int max_divisor = 60)
      : retained_(1.0f - 1.0f / float(std::max(1, max_divisor))) {}

  void add(const Vector& estimate, float weight) {
    if (!(weight > 0.0f)) return;
    weight_sum_ = retained_ * weight_sum_ + weight;
    mean_ += (estimate - mean_) * (weight / weight_sum_);
    ++count_;
  }
  const Vector& mean() const { return mean_; }
  float weight_sum() const { return weight_sum_; }
  int count() const { return count_; }
  bool empty() const { return count_ == 0; }

 private:
  float retained_;
  float weight_sum_ = 0.0f;
  int count_ = 0;
  Vector mean_ = Vector::Zero();
};

}  // namespace glint::reflectance
