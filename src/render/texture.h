#pragma once
// A kd texture: an 8/16-bit sRGB (or float, taken as linear) image held as linear RGB, looked up
// bilinearly with wrap-around. Texture coordinates count repeats: (0,0) is the image's
// bottom-left corner, (1,1) its top-right (OBJ convention, v up).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace glint::render {

class Texture {
 public:
  // Throws glint::Error naming the file when it cannot be read. Grey images are replicated to
  // RGB, an alpha channel is ignored.
  explicit Texture(const std::string& path);

  Eigen::Vector3f lookup(float u, float v) const;

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  const Eigen::Vector3f& texel(int x, int y) const { return texels_[std::size_t(y) * width_ + x]; }

  int width_ = 0;
  int height_ = 0;
  std::vector<Eigen::Vector3f> texels_;  // linear RGB, row-major, top row first
};

}  // namespace glint::render
