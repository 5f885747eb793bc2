#include "denoise/noise_level.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "geometry/covariance.h"

namespace glint::denoise {
namespace {

using geometry::Moments;

// Patch positions per inner loop: their running sums stay in the L1 cache.
constexpr int kChunk = 256;

// The patch shape within one image and the positions it can take inside it.
struct Window {
  int width = 0, height = 0;  // patch sides, shrunk to the image where it is smaller
  int columns = 0, rows = 0;  // patch positions along x and y
  double count() const { return static_cast<double>(width) * height; }
  // Offsets of the patch's pixels from its centre, in pixels.
  double u(int dx) const { return dx - 0.5 * (width - 1); }
  double v(int dy) const { return dy - 0.5 * (height - 1); }
};

Window window_for(const ImageF& image, int patch) {
  Window window;
  window.width = std::min(patch, image.width());
  window.height = std::min(patch, image.height());
  window.columns = image.width() - window.width + 1;
  window.rows = image.height() - window.height + 1;
  return window;
}

void check_input(const ImageF& image, const NoiseLevelParams& params) {
  if (params.patch < 3 || params.patch % 2 == 0) {
    throw Error("--patch", std::to_string(params.patch), "must be odd and at least 3");
  }
  if (image.empty()) throw Error("input image", "", "has no pixels");
  for (int c = 0; c < image.channels(); ++c) {
    const float* plane = image.plane(c);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
      if (std::isfinite(plane[i])) continue;
      const auto x = static_cast<int>(i % image.width()), y = static_cast<int>(i / image.width());
      throw Error("input image",
                  "pixel (" + std::to_string(x) + ", " + std::to_string(y) + "), channel " +
                      std::to_string(c),
                  "is not finite");
    }
  }
}

// The pixels of one plane seen by patch row `top`, positions x0 .. x0 + n - 1.
struct PatchRun {
  const float* plane;
  int stride;  // the image width
  const Window& window;
  int top, x0, n;
  // Pixel (dx, dy) of every patch of the run, one after the other.
  const float* pixels(int dx, int dy) const {
    return plane + static_cast<std::size_t>(top + dy) * stride + x0 + dx;
  }
};

// eq. (6) for every patch of the run (summed in double: exact for equal values).
void patch_means(const PatchRun& run, float* mean) {
  double sum[kChunk] = {};
  for (int dy = 0; dy < run.window.height; ++dy) {
    for (int dx = 0; dx < run.window.width; ++dx) {
      const float* p = run.pixels(dx, dy);
      for (int i = 0; i < run.n; ++i) sum[i] += p[i];
    }
  }
  for (int i = 0; i < run.n; ++i) mean[i] = static_cast<float>(sum[i] / run.window.count());
}

// eq. (5), as the mean squared deviation from the patch mean (no cancellation).
void patch_variances(const PatchRun& run, const float* mean, float* level) {
  double sum[kChunk] = {};
  for (int dy = 0; dy < run.window.height; ++dy) {
    for (int dx = 0; dx < run.window.width; ++dx) {
      const float* p = run.pixels(dx, dy);
      for (int i = 0; i < run.n; ++i) {
        const double d = p[i] - mean[i];
        sum[i] += d * d;
      }
    }
  }
  for (int i = 0; i < run.n; ++i) level[i] = static_cast<float>(sum[i] / run.window.count());
}

// Smallest eigenvalue of a subset's covariance, eq. (11); +inf for a subset too small to tell.
double across_plane_variance(const Moments& subset) {
  if (subset.count() <= 3.5) return std::numeric_limits<double>::infinity();
  return geometry::eigenvalues_descending(subset.covariance())[2];
}

// eq. (7)-(12) for every patch of the run. Points are (u, v, d): offsets from the patch centre
// and intensity minus the patch mean; centred, they sum accurately in float (four lanes per
// SIMD instruction). The lower subset's moments are summed with 0/1 weights, the upper ones
// are the rest of the patch.
void patch_svd_levels(const PatchRun& run, const float* mean, float* level) {
  // Per patch: lower n, u, v, d, uu, uv, ud, vv, vd, dd (Moments' order), then the whole
  // patch's d, ud, vd, dd.
  enum { n_, u_, v_, d_, uu_, uv_, ud_, vv_, vd_, dd_, all_d, all_ud, all_vd, all_dd, kSums };
  float s[kSums][kChunk] = {};
  double all_u = 0, all_v = 0, all_uu = 0, all_uv = 0, all_vv = 0;
  for (int dy = 0; dy < run.window.height; ++dy) {
    const auto v = static_cast<float>(run.window.v(dy));
    for (int dx = 0; dx < run.window.width; ++dx) {
      const auto u = static_cast<float>(run.window.u(dx));
      all_u += u, all_v += v, all_uu += u * u, all_uv += u * v, all_vv += v * v;
      const float* p = run.pixels(dx, dy);
      for (int i = 0; i < run.n; ++i) {
        const float d = p[i] - mean[i];
        // 1 below the mean, else 0 (pixels at the mean give +0): the sign bit, which unlike a
        // comparison lets the compiler vectorise the loop.
        const auto w = static_cast<float>(std::bit_cast<std::uint32_t>(d) >> 31);
        const float wd = w * d;
        s[n_][i] += w, s[u_][i] += w * u, s[v_][i] += w * v, s[d_][i] += wd;
        s[uu_][i] += w * (u * u), s[uv_][i] += w * (u * v), s[ud_][i] += wd * u;
        s[vv_][i] += w * (v * v), s[vd_][i] += wd * v, s[dd_][i] += wd * d;
        s[all_d][i] += d, s[all_ud][i] += d * u, s[all_vd][i] += d * v, s[all_dd][i] += d * d;
      }
    }
  }
  for (int i = 0; i < run.n; ++i) {
    const Moments lower({s[n_][i], s[u_][i], s[v_][i], s[d_][i], s[uu_][i], s[uv_][i], s[ud_][i],
                         s[vv_][i], s[vd_][i], s[dd_][i]});
    const Moments all({run.window.count(), all_u, all_v, s[all_d][i], all_uu, all_uv, s[all_ud][i],
                       all_vv, s[all_vd][i], s[all_dd][i]});
    const double noise =
        std::min(across_plane_variance(lower), across_plane_variance(all.minus(lower)));
    level[i] = std::isinf(noise) ? 0.f : static_cast<float>(noise);
  }
}

// The noise of every pixel from that of every patch position: the nearest position whose
// patch is centred on the pixel, or shifted inside the image.
ImageF spread_to_pixels(const ImageF& positions, int width, int height, const Window& window) {
  ImageF noise(width, height, 1);
  const int rx = (window.width - 1) / 2, ry = (window.height - 1) / 2;
  for (int y = 0; y < height; ++y) {
    const int py = std::clamp(y - ry, 0, window.rows - 1);
    for (int x = 0; x < width; ++x) {
      noise.at(x, y, 0) = positions.at(std::clamp(x - rx, 0, window.columns - 1), py, 0);
    }
  }
  return noise;
}

}  // namespace

NoiseMethod parse_noise_method(const std::string& name) {
  if (name == "svd") return NoiseMethod::svd;
  if (name == "var" || name == "variance") return NoiseMethod::variance;
  throw Error("--method", name, "unknown noise level method (use svd or variance)");
}

ImageF noise_level(const ImageF& image, const NoiseLevelParams& params) {
  check_input(image, params);
  const Window window = window_for(image, params.patch);
  ImageF positions(window.columns, window.rows, 1);  // noise >= 0: the maximum starts at 0
  parallel_for_chunks(window.rows, 4, [&](std::size_t begin, std::size_t end) {
    float mean[kChunk];
    float level[kChunk];
    for (auto top = static_cast<int>(begin); top < static_cast<int>(end); ++top) {
      for (int x0 = 0; x0 < window.columns; x0 += kChunk) {
        const int n = std::min(kChunk, window.columns - x0);
        float* out = &positions.at(x0, top, 0);
        for (int c = 0; c < image.channels(); ++c) {
          const PatchRun run{image.plane(c), image.width(), window, top, x0, n};
          patch_means(run, mean);
          if (params.method == NoiseMethod::variance) {
            patch_variances(run, mean, level);
          } else {
            patch_svd_levels(run, mean, level);
          }
          for (int i = 0; i < n; ++i) out[i] = std::max(out[i], level[i]);  // §3.1
        }
      }
    }
  });
  return spread_to_pixels(positions, image.width(), image.height(), window);
}

Guidance guidance_from_noise(const ImageF& noise, const GuidanceParams& params) {
  if (params.bins < 1) throw Error("--bins", std::to_string(params.bins), "must be at least 1");
  if (!(params.upper_quantile > 0 && params.upper_quantile <= 1)) {
    throw Error("--upper-quantile", std::to_string(params.upper_quantile), "must be in (0, 1]");
  }
  if (noise.empty()) throw Error("noise level map", "", "has no pixels");
  if (noise.channels() != 1) {
    throw Error("noise level map", "",
                "must have one channel, not " + std::to_string(noise.channels()));
  }
  const std::vector<float>& levels = noise.values();
  for (const float n : levels) {
    if (!(n >= 0) || std::isinf(n)) {
      throw Error("noise level map", "", "values must be finite and >= 0");
    }
  }
  Guidance guidance;
  guidance.map = ImageF(noise.width(), noise.height(), 1, 1.f);
  const double top = std::sqrt(*std::max_element(levels.begin(), levels.end()));
  if (top == 0) return guidance;  // a noise-free image: nothing to denoise

  // Histogram of the standard deviations sqrt(n) over [0, top]; its fullest bin is the peak.
  std::vector<std::size_t> histogram(params.bins, 0);
  for (const float n : levels) {
    const auto bin = static_cast<int>(std::sqrt(n) / top * params.bins);
    ++histogram[std::min(bin, params.bins - 1)];
  }
  const auto peak = std::max_element(histogram.begin(), histogram.end()) - histogram.begin();
  const double peak_deviation = (static_cast<double>(peak) + 0.5) * top / params.bins;
  guidance.n_peak = peak_deviation * peak_deviation;
  guidance.lower = 4 * guidance.n_peak;  // (2 sqrt(n_peak))²

  std::vector<float> sorted = levels;
  const auto rank = static_cast<std::size_t>(
      std::max(0.0, std::ceil(params.upper_quantile * static_cast<double>(sorted.size())) - 1));
  std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.end());
  guidance.upper = sorted[rank];
  if (guidance.upper <= guidance.lower) return guidance;

  const double range = guidance.upper - guidance.lower;
  std::vector<float>& map = guidance.map.values();
  for (std::size_t i = 0; i < levels.size(); ++i) {  // eq. (13)
    map[i] = static_cast<float>(std::clamp(1 - (levels[i] - guidance.lower) / range, 0.0, 1.0));
  }
  return guidance;
}

}  // namespace glint::denoise
