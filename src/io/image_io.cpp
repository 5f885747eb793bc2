#include "io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/atomic_file.h"
#include "io/codec.h"
#include "io/image_decode.h"
#include "io/npy.h"

namespace glint::io {
namespace {

// OpenCV 4.6 decodes and encodes OpenEXR only when this variable is set, and looks at it once,
// on the first EXR access: set it (leaving a user's own setting alone) before any codec runs.
void enable_openexr() {
  static const bool enabled = [] { return ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0) == 0; }();
  (void)enabled;
}

// OpenCV stores colour as B, G, R(, A): the channel of `c` on the other side (either way).
int swap_red_blue(int c, int channels) { return channels >= 3 && c < 3 ? 2 - c : c; }

// Scale from a decoded sample type to [0,1] (floats as they are).
double sample_scale(const std::string& path, int depth) {
  switch (depth) {
    case CV_8U:
      return 1.0 / 255.0;
    case CV_16U:
      return 1.0 / 65535.0;
    case CV_32F:
    case CV_64F:
      return 1.0;
    default:
      throw Error(path, "", "unsupported sample type (only 8/16-bit unsigned and float)");
  }
}

ImageF to_image(const std::string& path, const cv::Mat& decoded) {
  const int channels = decoded.channels();
  const double scale = sample_scale(path, decoded.depth());
  std::vector<cv::Mat> planes;
  cv::split(decoded, planes);
  ImageF image(decoded.cols, decoded.rows, channels);
  for (int c = 0; c < channels; ++c) {
    cv::Mat target(image.height(), image.width(), CV_32F, image.plane(c));
    planes[swap_red_blue(c, channels)].convertTo(target, CV_32F, scale);
  }
  return image;
}

// Interleaved B, G, R(, A) samples of `Sample`, values clamped to [0,1] and rounded to `max`.
template <class Sample>
cv::Mat quantise(const std::string& path, const ImageF& image, double max) {
  const int width = image.width(), height = image.height(), channels = image.channels();
  cv::Mat samples(height, width, CV_MAKETYPE(cv::DataType<Sample>::depth, channels));
  for (int c = 0; c < channels; ++c) {
    const float* plane = image.plane(c);
    const int k = swap_red_blue(c, channels);
    for (int y = 0; y < height; ++y) {
      Sample* row = samples.ptr<Sample>(y);
      for (int x = 0; x < width; ++x) {
        const float value = plane[static_cast<std::size_t>(y) * width + x];
        if (std::isnan(value)) {
          throw Error(path,
                      "pixel (" + std::to_string(x) + ", " + std::to_string(y) + "), channel " +
                          std::to_string(c),
                      "NaN cannot be written to PNG");
        }
        row[x * channels + k] =
            static_cast<Sample>(std::clamp(static_cast<double>(value), 0.0, 1.0) * max + 0.5);
      }
    }
  }
  return samples;
}

cv::Mat interleave_float(const ImageF& image) {
  const int channels = image.channels();
  std::vector<cv::Mat> planes(channels);
  for (int c = 0; c < channels; ++c) {
    // cv::merge only reads its inputs.
    planes[swap_red_blue(c, channels)] =
        cv::Mat(image.height(), image.width(), CV_32F, const_cast<float*>(image.plane(c)));
  }
  cv::Mat samples;
  cv::merge(planes, samples);
  return samples;
}

// .npy images are (height, width) or (height, width, channels), the NumPy convention.
ImageF read_npy_image(const std::string& path) {
  const NpyArray array = read_npy(path);
  if (array.shape.size() != 2 && array.shape.size() != 3)
    throw Error(path, "", "an image array must be (height, width) or (height, width, channels)");
  const std::size_t channels = array.shape.size() == 3 ? array.shape[2] : 1;
  if (array.values.empty()) throw Error(path, "", "the image has no pixels");
  limits::check_image_size(std::int64_t(array.shape[1]), std::int64_t(array.shape[0]), path,
                           "shape");
  ImageF image(static_cast<int>(array.shape[1]), static_cast<int>(array.shape[0]),
               static_cast<int>(channels));
  const std::size_t pixels = image.pixel_count();
  for (std::size_t c = 0; c < channels; ++c)
    for (std::size_t p = 0; p < pixels; ++p)
      image.plane(static_cast<int>(c))[p] = array.values[p * channels + c];
  return image;
}

void write_npy_image(const std::string& path, const ImageF& image) {
  const auto channels = static_cast<std::size_t>(image.channels());
  std::vector<float> interleaved(image.values().size());
  for (std::size_t c = 0; c < channels; ++c)
    for (std::size_t p = 0; p < image.pixel_count(); ++p)
      interleaved[p * channels + c] = image.plane(static_cast<int>(c))[p];
  std::vector<std::size_t> shape{static_cast<std::size_t>(image.height()),
                                 static_cast<std::size_t>(image.width())};
  if (channels > 1) shape.push_back(channels);
  write_npy(path, shape, interleaved.data());
}

}  // namespace

ImageF read_image(const std::string& path) {
  if (lowercase(std::filesystem::path(path).extension().string()) == ".npy")
    return read_npy_image(path);
  enable_openexr();
  const cv::Mat decoded = decode_image_file(path, cv::IMREAD_UNCHANGED);
  return to_image(path, decoded);
}

void write_image(const std::string& path, const ImageF& image, PngDepth depth) {
  enable_openexr();
  const std::string extension = lowercase(std::filesystem::path(path).extension().string());
  if (extension != ".png" && extension != ".exr" && extension != ".npy") {
    throw Error(path, "", "unknown image extension '" + extension + "' (use .png, .exr or .npy)");
  }
  if (image.empty()) throw Error(path, "", "the image has no pixels");
  if (extension == ".npy") return write_npy_image(path, image);
  const int channels = image.channels();
  if (channels != 1 && channels != 3 && channels != 4) {
    throw Error(path, "",
                "cannot write " + std::to_string(channels) +
                    " channels as PNG or EXR (1, 3 or 4; use .npy for any count)");
  }
  cv::Mat samples;
  std::vector<int> options;
  if (extension == ".exr") {
    samples = interleave_float(image);
    options = {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT};
  } else if (depth == PngDepth::sixteen) {
    samples = quantise<std::uint16_t>(path, image, 65535.0);
  } else {
    samples = quantise<std::uint8_t>(path, image, 255.0);
  }
  std::vector<std::uint8_t> encoded;
  try {
    if (!cv::imencode(extension, samples, encoded, options)) {
      throw Error(path, "", "OpenCV could not encode the image");
    }
  } catch (const cv::Exception& e) {
    throw Error(path, "", "cannot encode the image: " + e.err);
  }
  AtomicFile file(path);
  file.stream().write(reinterpret_cast<const char*>(encoded.data()),
                      static_cast<std::streamsize>(encoded.size()));
  file.commit();
}

}  // namespace glint::io
