#include "render/texture.h"

#include <cctype>
#include <cmath>
#include <filesystem>

#include "io/image_io.h"
#include "render/sensor.h"

namespace glint::render {

Texture::Texture(const std::string& path) {
  const ImageF image = io::read_image(path);
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool encoded = extension != ".exr" && extension != ".hdr" && extension != ".npy";
  width_ = image.width();
  height_ = image.height();
  texels_.resize(image.pixel_count());
  for (std::size_t i = 0; i < texels_.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float value = image.plane(image.channels() >= 3 ? c : 0)[i];
      texels_[i][c] = encoded ? srgb_to_linear(value) : value;
    }
  }
}

Eigen::Vector3f Texture::lookup(float u, float v) const {
  // Continuous texel coordinates with texel centres at integers, v flipped to image rows; the
  // fractional parts keep them in [-0.5, size - 0.5), so neighbours wrap by one step at most.
  const float x = (u - std::floor(u)) * width_ - 0.5f;
  const float y = (1.0f - (v - std::floor(v))) * height_ - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float wx = x - fx, wy = y - fy;
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const int x0 = ix < 0 ? width_ - 1 : ix, x1 = ix + 1 >= width_ ? 0 : ix + 1;
  const int y0 = iy < 0 ? height_ - 1 : iy, y1 = iy + 1 >= height_ ? 0 : iy + 1;
  return (1 - wy) * ((1 - wx) * texel(x0, y0) + wx * texel(x1, y0)) +
         wy * ((1 - wx) * texel(x0, y1) + wx * texel(x1, y1));
}

}  // namespace glint::render
