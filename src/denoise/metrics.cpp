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

// A mask value above one half selects its pixel.
bool selects(float mask_value) { return mask_value > 0.5f; }

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
  if (std::none_of(values.begin(), values.end(), selects)) {
    throw Error("mask", "", "selects no pixel (none is > 0.5)");
  }
}

bool selected(const ImageF* mask, std::size_t i) {
  return mask == nullptr || selects(mask->values()[i]);
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

// Normalised to sum 1: where the border does not cut the window, no renormalising is needed.
const std::array<double, kWindow> kTaps = gaussian_taps();

// The five moments that the window averages: x, y, x², y², xy.
constexpr int kMoments = 5;

// Sum of the taps of the window centred on i that fall inside [0, n): dividing by it
// renormalises the window where it is cut by the border.
double inside_weight(int i, int n) {
  double weight = 0;
  for (int k = std::max(0, i - kRadius); k <= std::min(n - 1, i + kRadius); ++k)
    weight += kTaps[std::size_t(k - i + kRadius)];
  return weight;
}

// The two passes of the filter, each a function of its own cloned for AVX2 (the baseline build
// is plain x86-64). With the 11 taps unrolled, GCC vectorises over i (restrict: out aliases no
// input). Inlined into ssim_sum, their pointers and weights were reloaded from the stack for
// every vector.

// Horizontal: out[i] = Σ_k kTaps[k] · in[i + k].
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void filter_row(const double* in, std::size_t count, double* __restrict out) {
  for (std::size_t i = 0; i < count; ++i) {
    double sum = 0;
    for (int k = 0; k < kWindow; ++k) sum += kTaps[std::size_t(k)] * in[i + std::size_t(k)];
    out[i] = sum;
  }
}

// Vertical: out[i] = Σ_k weights[k] · rows[k][i].
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void filter_column(const std::array<const double*, kWindow>& rows,
                   const std::array<double, kWindow>& weights, std::size_t count,
                   double* __restrict out) {
  for (std::size_t i = 0; i < count; ++i) {
    double sum = 0;
    for (int k = 0; k < kWindow; ++k) sum += weights[std::size_t(k)] * rows[std::size_t(k)][i];
    out[i] = sum;
  }
}

// Columns per strip at most. The image is filtered in strips of columns, each row by row
// (horizontal pass into a ring of 11 rows, then the vertical pass), in doubles and without
// whole-image temporaries: with those, a frame's evaluation spent most of its time in page
// faults. A strip's ring (11 rows of 5 moments, 28 KB) stays in the L1 cache; with whole rows
// of a 512-pixel image it came from L2, and the vertical pass ran 3-4 times slower.
constexpr int kMaxStrip = 64;

// The buffers of one image size, shared by its channels.
struct SsimRows {
  SsimRows(int width, int height)
      : width(width),
        height(height),
        strip((width + strip_count(width) - 1) / strip_count(width)),
        column_scale(std::size_t(width)),
        products(kMoments * padded_size(), 0.0),
        ring(kWindow * row_size(), 0.0),
        zeros(row_size(), 0.0),
        moments(row_size()),
        map(std::size_t(strip)),
        column_sum(std::size_t(strip)) {
    for (int c = 0; c < width; ++c) column_scale[std::size_t(c)] = 1 / inside_weight(c, width);
  }
  // Strips of equal width: a narrow last strip would pay the per-row overhead for few columns.
  static int strip_count(int width) { return (width + kMaxStrip - 1) / kMaxStrip; }
  std::size_t padded_size() const { return std::size_t(strip) + 2 * kRadius; }
  std::size_t row_size() const { return std::size_t(kMoments) * std::size_t(strip); }

  int width, height;
  int strip;                         // columns per strip (the last may have fewer)
  std::vector<double> column_scale;  // 1 / inside_weight() of each column
  // products[moment][kRadius + column in strip]: one row's x, y, x², y², xy, with the kRadius
  // columns either side of the strip; zeros beyond the image's border, so that the horizontal
  // pass treats the border columns like the others.
  std::vector<double> products;
  std::vector<double> ring;        // ring[row % kWindow][moment][column in strip]: filtered rows
  std::vector<double> zeros;       // stands in the vertical pass for rows beyond the border
  std::vector<double> moments;     // [moment][column in strip]: the current row's windowed moments
  std::vector<double> map;         // the current row's SSIM map in the strip
  std::vector<double> column_sum;  // [column in strip]: sum of the SSIM map over the rows
};

// Sum of the SSIM map of one channel over the selected pixels (mask: one value per pixel, or
// null for all). Cloned for AVX2 too, for the products and the SSIM map.
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
double
ssim_sum(const float* x, const float* y, const float* mask, SsimRows& rows) {
  constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;  // (K1 L)², (K2 L)², L = 1
  const int height = rows.height;
  const std::size_t padded = rows.padded_size(), row_size = rows.row_size();
  double sum = 0;
  for (int begin = 0; begin < rows.width; begin += rows.strip) {
    const int end = std::min(rows.width, begin + rows.strip);
    const std::size_t n = std::size_t(end - begin);
    // The strip's columns and kRadius more either side, as far as the image reaches.
    const int first = std::max(0, begin - kRadius), last = std::min(rows.width, end + kRadius);
    const std::size_t lead = std::size_t(first - (begin - kRadius));
    const auto filter = [&](int row) {
      const float* xr = x + std::size_t(row) * std::size_t(rows.width) + first;
      const float* yr = y + std::size_t(row) * std::size_t(rows.width) + first;
      double* p = rows.products.data() + lead;
      for (std::size_t c = 0; c < std::size_t(last - first); ++c) {
        const double a = xr[c], b = yr[c];
        p[c] = a, p[padded + c] = b, p[2 * padded + c] = a * a, p[3 * padded + c] = b * b,
        p[4 * padded + c] = a * b;
      }
      double* out = rows.ring.data() + std::size_t(row % kWindow) * row_size;
      for (std::size_t j = 0; j < kMoments; ++j)
        filter_row(rows.products.data() + j * padded, n, out + j * n);
      // Only the columns within kRadius of the border have a cut window.
      const auto renormalise = [&](int c) {
        for (int j = 0; j < kMoments; ++j)
          out[std::size_t(j) * n + std::size_t(c - begin)] *= rows.column_scale[std::size_t(c)];
      };
      for (int c = begin; c < std::min(end, kRadius); ++c) renormalise(c);
      for (int c = std::max({begin, kRadius, rows.width - kRadius}); c < end; ++c) renormalise(c);
    };
    // Zeros beyond the border for the horizontal pass (a previous strip may have left values).
    for (int j = 0; j < kMoments; ++j) {
      double* p = rows.products.data() + std::size_t(j) * padded;
      std::fill(p, p + lead, 0.0);
      std::fill(p + lead + std::size_t(last - first), p + n + 2 * kRadius, 0.0);
    }
    double* column_sum = rows.column_sum.data();
    std::fill(column_sum, column_sum + n, 0.0);
    int next_filtered = 0;
    for (int row = 0; row < height; ++row) {
      for (; next_filtered <= std::min(height - 1, row + kRadius); ++next_filtered)
        filter(next_filtered);
      const double row_weight = inside_weight(row, height);
      std::array<const double*, kWindow> in;
      std::array<double, kWindow> weights;
      for (int k = 0; k < kWindow; ++k) {
        const int r = row + k - kRadius;
        in[std::size_t(k)] = r < 0 || r >= height
                                 ? rows.zeros.data()
                                 : rows.ring.data() + std::size_t(r % kWindow) * row_size;
        weights[std::size_t(k)] = kTaps[std::size_t(k)] / row_weight;
      }
      double* m = rows.moments.data();
      filter_column(in, weights, kMoments * n, m);
      // The SSIM map at all the strip's pixels in the row, selected or not, so that this loop
      // vectorises; then the selected values are added per column, which vectorises too (a
      // single running sum would not). Two loops there: with the null test inside, GCC made
      // masked loads of the mask, slow even when they load nothing.
      double* map = rows.map.data();
      for (std::size_t c = 0; c < n; ++c) {
        const double mx = m[c], my = m[n + c];
        const double vx = m[2 * n + c] - mx * mx, vy = m[3 * n + c] - my * my,
                     cxy = m[4 * n + c] - mx * my;
        map[c] = (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
      }
      if (mask == nullptr) {
        for (std::size_t c = 0; c < n; ++c) column_sum[c] += map[c];
      } else {
        const float* mask_row = mask + std::size_t(row) * std::size_t(rows.width) + begin;
        for (std::size_t c = 0; c < n; ++c) column_sum[c] += selects(mask_row[c]) ? map[c] : 0.0;
      }
    }
    sum += std::accumulate(column_sum, column_sum + n, 0.0);
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
  SsimRows rows(reference.width(), reference.height());
  const float* mask_values = mask == nullptr ? nullptr : mask->values().data();
  double total = 0;
  for (int c = 0; c < reference.channels(); ++c)
    total +=
        ssim_sum(reference.plane(c), test.plane(c), mask_values, rows) / static_cast<double>(count);
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
