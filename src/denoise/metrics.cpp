#include "denoise/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
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

// Wang et al.'s window: 11×11 Gaussian, σ = 1.5, separable.
constexpr int kRadius = 5;
constexpr int kWindow = 2 * kRadius + 1;
constexpr double kSigma = 1.5;

std::array<double, kWindow> gaussian_taps() {
  std::array<double, kWindow> taps{};
  for (int i = 0; i < kWindow; ++i)
    taps[std::size_t(i)] = std::exp(-double((i - kRadius) * (i - kRadius)) / (2 * kSigma * kSigma));
  const double sum = std::accumulate(taps.begin(), taps.end(), 0.0);
  for (double& tap : taps) tap /= sum;
  return taps;
}

// The five windowed moments at a pixel: means of x, y, x², y², xy.
constexpr int kMoments = 5;

// Sum of the taps of the window centred on i that fall inside [0, n): dividing by it
// renormalises the window where it is cut by the border.
double inside_weight(const std::array<double, kWindow>& taps, int i, int n) {
  double weight = 0;
  for (int k = std::max(0, i - kRadius); k <= std::min(n - 1, i + kRadius); ++k)
    weight += taps[std::size_t(k - i + kRadius)];
  return weight;
}

// Sum of the SSIM map of one channel over the selected pixels. The moments are filtered
// row by row (horizontal pass into a ring of 11 rows, then the vertical pass), in doubles and
// without whole-image temporaries: with those, a frame's evaluation spent most of its time in
// page faults.
double ssim_sum(const float* x, const float* y, int width, int height, const ImageF* mask) {
  constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;  // (K1 L)², (K2 L)², L = 1
  static const std::array<double, kWindow> taps = gaussian_taps();
  std::vector<double> column_weight(std::size_t(width), 0.0);
  for (int c = 0; c < width; ++c) column_weight[std::size_t(c)] = inside_weight(taps, c, width);
  // ring[(row % kWindow)][moment][column]: a row's horizontally filtered moments.
  const std::size_t row_size = std::size_t(kMoments) * std::size_t(width);
  std::vector<double> ring(kWindow * row_size);
  const auto filter_row = [&](int row) {
    double* out = ring.data() + std::size_t(row % kWindow) * row_size;
    const float* xr = x + std::size_t(row) * std::size_t(width);
    const float* yr = y + std::size_t(row) * std::size_t(width);
    for (int c = 0; c < width; ++c) {
      double m[kMoments] = {};
      for (int k = std::max(0, c - kRadius); k <= std::min(width - 1, c + kRadius); ++k) {
        const double w = taps[std::size_t(k - c + kRadius)], a = xr[k], b = yr[k];
        m[0] += w * a, m[1] += w * b, m[2] += w * a * a, m[3] += w * b * b, m[4] += w * a * b;
      }
      for (int j = 0; j < kMoments; ++j)
        out[std::size_t(j) * std::size_t(width) + std::size_t(c)] =
            m[j] / column_weight[std::size_t(c)];
    }
  };
  std::vector<double> moments(row_size);
  double sum = 0;
  int next_filtered = 0;
  for (int row = 0; row < height; ++row) {
    const int first = std::max(0, row - kRadius), last = std::min(height - 1, row + kRadius);
    for (; next_filtered <= last; ++next_filtered) filter_row(next_filtered);
    const double row_weight = inside_weight(taps, row, height);
    std::fill(moments.begin(), moments.end(), 0.0);
    for (int k = first; k <= last; ++k) {
      const double w = taps[std::size_t(k - row + kRadius)] / row_weight;
      const double* in = ring.data() + std::size_t(k % kWindow) * row_size;
      for (std::size_t i = 0; i < row_size; ++i) moments[i] += w * in[i];
    }
    for (int c = 0; c < width; ++c) {
      if (!selected(mask, std::size_t(row) * std::size_t(width) + std::size_t(c))) continue;
      const auto moment = [&](int j) {
        return moments[std::size_t(j) * std::size_t(width) + std::size_t(c)];
      };
      const double mx = moment(0), my = moment(1);
      const double vx = moment(2) - mx * mx, vy = moment(3) - my * my, cxy = moment(4) - mx * my;
      sum += (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
    }
  }
  return sum;
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
  std::size_t count = 0;
  for (std::size_t i = 0; i < reference.pixel_count(); ++i) count += selected(mask, i);
  double total = 0;
  for (int c = 0; c < reference.channels(); ++c)
    total +=
        ssim_sum(reference.plane(c), test.plane(c), reference.width(), reference.height(), mask) /
        static_cast<double>(count);
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
