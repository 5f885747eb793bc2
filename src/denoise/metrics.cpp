#include "denoise/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/error.h"

namespace glint::denoise {
namespace {

std::string size_text(const ImageF& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height()) + "x" +
         std::to_string(image.channels());
}

void check_finite(const ImageF& image, const char* name) {
  const auto& values = image.values();
  if (!std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); })) {
    throw Error(name, "", "has non-finite values");
  }
}

void check_pair(const ImageF& reference, const ImageF& test, const ImageF* mask) {
  if (reference.empty()) throw Error("reference image", "", "has no pixels");
  if (!reference.same_size(test) || reference.channels() != test.channels()) {
    throw Error("test image", "",
                "is " + size_text(test) + ", the reference " + size_text(reference));
  }
  check_finite(reference, "reference image");
  check_finite(test, "test image");
  if (mask == nullptr) return;
  if (!mask->same_size(reference) || mask->channels() != 1) {
    throw Error("mask", "",
                "is " + size_text(*mask) + ", needs one channel of " +
                    std::to_string(reference.width()) + "x" + std::to_string(reference.height()));
  }
  const auto& values = mask->values();
  if (std::none_of(values.begin(), values.end(), [](float m) { return m > 0.5f; })) {
    throw Error("mask", "", "selects no pixel (none is > 0.5)");
  }
}

bool selected(const ImageF* mask, std::size_t i) {
  return mask == nullptr || mask->values()[i] > 0.5f;
}

// Wang et al.'s window: 11×11 Gaussian, σ = 1.5.
constexpr int kWindow = 11;
constexpr double kSigma = 1.5;

// Windowed mean of `plane` at every pixel; at the borders over the part of the window inside
// the image, renormalised (zero padding divided by the window weight inside the image).
class WindowMean {
 public:
  WindowMean(int width, int height)
      : kernel_(cv::getGaussianKernel(kWindow, kSigma, CV_64F)),
        weight_(filter(cv::Mat::ones(height, width, CV_64F))) {}
  cv::Mat operator()(const cv::Mat& plane) const { return filter(plane) / weight_; }

 private:
  cv::Mat filter(const cv::Mat& plane) const {
    cv::Mat out;
    cv::sepFilter2D(plane, out, CV_64F, kernel_, kernel_, cv::Point(-1, -1), 0,
                    cv::BORDER_CONSTANT);
    return out;
  }
  cv::Mat kernel_;
  cv::Mat weight_;
};

// The SSIM map of one channel (Wang et al. 2004).
cv::Mat ssim_map(const cv::Mat& x, const cv::Mat& y, const WindowMean& mean) {
  constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;  // (K1 L)², (K2 L)², L = 1
  const cv::Mat mx = mean(x), my = mean(y);
  const cv::Mat mxx = mx.mul(mx), myy = my.mul(my), mxy = mx.mul(my);
  const cv::Mat vx = mean(x.mul(x)) - mxx, vy = mean(y.mul(y)) - myy;
  const cv::Mat cxy = mean(x.mul(y)) - mxy;
  cv::Mat numerator = (2 * mxy + c1).mul(2 * cxy + c2);
  cv::Mat denominator = (mxx + myy + c1).mul(vx + vy + c2);
  return numerator / denominator;
}

}  // namespace

double psnr(const ImageF& reference, const ImageF& test, const ImageF* mask) {
  check_pair(reference, test, mask);
  double squared = 0;
  std::size_t count = 0;
  for (int c = 0; c < reference.channels(); ++c) {
    const float* r = reference.plane(c);
    const float* t = test.plane(c);
    for (std::size_t i = 0; i < reference.pixel_count(); ++i) {
      if (!selected(mask, i)) continue;
      const double d = static_cast<double>(r[i]) - t[i];
      squared += d * d;
      ++count;
    }
  }
  if (squared == 0) return std::numeric_limits<double>::infinity();
  return -10 * std::log10(squared / static_cast<double>(count));  // 10 log10(1² / MSE)
}

double ssim(const ImageF& reference, const ImageF& test, const ImageF* mask) {
  check_pair(reference, test, mask);
  const int width = reference.width(), height = reference.height();
  const WindowMean mean(width, height);
  double total = 0;
  for (int c = 0; c < reference.channels(); ++c) {
    cv::Mat x, y;
    cv::Mat(height, width, CV_32F, const_cast<float*>(reference.plane(c))).convertTo(x, CV_64F);
    cv::Mat(height, width, CV_32F, const_cast<float*>(test.plane(c))).convertTo(y, CV_64F);
    const cv::Mat map = ssim_map(x, y, mean);
    const auto* values = map.ptr<double>();  // continuous: a fresh result
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < reference.pixel_count(); ++i) {
      if (!selected(mask, i)) continue;
      sum += values[i];
      ++count;
    }
    total += sum / static_cast<double>(count);
  }
  return total / reference.channels();
}

double roc_auc(const ImageF& score, const ImageF& truth) {
  if (score.empty() || score.channels() != 1) {
    throw Error("score map", "", "must be a non-empty one-channel image");
  }
  if (!truth.same_size(score) || truth.channels() != 1) {
    throw Error("truth mask", "",
                "is " + size_text(truth) + ", needs one channel of " +
                    std::to_string(score.width()) + "x" + std::to_string(score.height()));
  }
  check_finite(score, "score map");
  const std::vector<float>& scores = score.values();
  std::vector<std::size_t> order(scores.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return scores[a] < scores[b]; });
  // Mann-Whitney U: the rank sum of the positives, tied scores sharing their mean rank.
  double positive_rank_sum = 0, positives = 0;
  for (std::size_t first = 0; first < order.size();) {
    std::size_t last = first;
    while (last + 1 < order.size() && scores[order[last + 1]] == scores[order[first]]) ++last;
    const double mean_rank = 0.5 * static_cast<double>(first + last) + 1;
    for (std::size_t k = first; k <= last; ++k) {
      if (truth.values()[order[k]] > 0.5f) {
        positive_rank_sum += mean_rank;
        ++positives;
      }
    }
    first = last + 1;
  }
  const double negatives = static_cast<double>(order.size()) - positives;
  if (positives == 0) throw Error("truth mask", "", "has no positive pixel (none is > 0.5)");
  if (negatives == 0) throw Error("truth mask", "", "has no negative pixel (all are > 0.5)");
  return (positive_rank_sum - positives * (positives + 1) / 2) / (positives * negatives);
}

}  // namespace glint::denoise
