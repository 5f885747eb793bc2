#include "denoise/nlm.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/photo.hpp>
#include <string>
#include <vector>

#include "core/error.h"

namespace glint::denoise {
namespace {

void check_window(const char* flag, int side) {
  if (side < 1 || side % 2 == 0) throw Error(flag, std::to_string(side), "must be odd and >= 1");
}

// One channel as 8-bit samples (clamped to [0,1], rounded).
cv::Mat to_bytes(const ImageF& image, int c) {
  cv::Mat bytes(image.height(), image.width(), CV_8U);
  const float* plane = image.plane(c);
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    if (std::isnan(plane[i])) {
      throw Error("noisy image", "channel " + std::to_string(c), "has NaN values");
    }
    bytes.data[i] = static_cast<std::uint8_t>(std::clamp(plane[i], 0.f, 1.f) * 255.f + 0.5f);
  }
  return bytes;
}

void from_bytes(const cv::Mat& bytes, ImageF& image, int c) {
  float* plane = image.plane(c);
  for (std::size_t i = 0; i < image.pixel_count(); ++i) plane[i] = bytes.data[i] / 255.f;
}

}  // namespace

ImageF nlm_denoise(const ImageF& noisy, const NlmParams& params) {
  if (!(params.h > 0)) throw Error("--h", std::to_string(params.h), "must be > 0");
  if (!(params.h_color > 0))
    throw Error("--h-color", std::to_string(params.h_color), "must be > 0");
  check_window("--template-window", params.template_window);
  check_window("--search-window", params.search_window);
  if (noisy.empty()) throw Error("noisy image", "", "has no pixels");

  ImageF denoised(noisy.width(), noisy.height(), noisy.channels());
  if (noisy.channels() == 3) {
    // OpenCV's colour variant expects B, G, R (it denoises in CIELAB).
    std::vector<cv::Mat> bgr{to_bytes(noisy, 2), to_bytes(noisy, 1), to_bytes(noisy, 0)};
    cv::Mat interleaved, result;
    cv::merge(bgr, interleaved);
    cv::fastNlMeansDenoisingColored(interleaved, result, params.h, params.h_color,
                                    params.template_window, params.search_window);
    cv::split(result, bgr);
    for (int c = 0; c < 3; ++c) from_bytes(bgr[2 - c], denoised, c);
    return denoised;
  }
  for (int c = 0; c < noisy.channels(); ++c) {
    cv::Mat result;
    cv::fastNlMeansDenoising(to_bytes(noisy, c), result, params.h, params.template_window,
                             params.search_window);
    from_bytes(result, denoised, c);
  }
  return denoised;
}

}  // namespace glint::denoise
