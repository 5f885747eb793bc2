#include "render/environment_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "io/image_io.h"
#include "render/perceptual.h"

namespace glint::render {
namespace {

constexpr float kPi = float(M_PI);

// Index of the interval of a monotone CDF (size n+1, cdf[0]=0, cdf[n]=1) containing x.
int find_interval(const float* cdf, int n, float x) {
  const float* upper = std::upper_bound(cdf + 1, cdf + n + 1, x);
  return std::clamp(static_cast<int>(upper - cdf) - 1, 0, n - 1);
}

}  // namespace

EnvironmentMap::EnvironmentMap(const Environment& settings) : scale_(settings.scale) {
  const ImageF image = io::read_image(settings.path);
  width_ = image.width();
  height_ = image.height();
  const float angle = -settings.rotation_deg * kPi / 180.0f;
  world_to_map_ = Eigen::AngleAxisf(angle, Eigen::Vector3f::UnitY()).toRotationMatrix();
  texels_.resize(image.pixel_count());
  for (std::size_t i = 0; i < texels_.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      texels_[i][c] = std::max(0.0f, image.plane(image.channels() >= 3 ? c : 0)[i]);
  }
  // Texel weights luminance * sin(theta): the solid angle a texel covers.
  texel_probability_.resize(texels_.size());
  column_cdf_.assign(std::size_t(height_) * (width_ + 1), 0.0f);
  row_cdf_.assign(height_ + 1, 0.0f);
  double total = 0;
  std::vector<double> row_sums(height_, 0.0);
  for (int y = 0; y < height_; ++y) {
    const float sin_theta = std::sin((y + 0.5f) / height_ * kPi);
    float* cdf = column_cdf_.data() + std::size_t(y) * (width_ + 1);
    double sum = 0;
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = std::size_t(y) * width_ + x;
      texel_probability_[i] = luminance(texels_[i]) * sin_theta;
      sum += texel_probability_[i];
      cdf[x + 1] = static_cast<float>(sum);
    }
    for (int x = 1; x <= width_; ++x) cdf[x] = sum > 0 ? float(cdf[x] / sum) : float(x) / width_;
    row_sums[y] = sum;
    total += sum;
  }
  if (!(total > 0)) throw Error(settings.path, "", "the environment map holds no light");
  double running = 0;
  for (int y = 0; y < height_; ++y) {
    running += row_sums[y];
    row_cdf_[y + 1] = static_cast<float>(running / total);
  }
  row_cdf_[height_] = 1.0f;
  for (float& p : texel_probability_) p = static_cast<float>(p / total);
}

std::size_t EnvironmentMap::texel_of(const Eigen::Vector3f& direction) const {
  const Eigen::Vector3f d = world_to_map_ * direction;
  const float u = std::atan2(d.x(), -d.z()) / (2 * kPi) + 0.5f;
  const float v = std::acos(std::clamp(d.y(), -1.0f, 1.0f)) / kPi;
  const int x = std::clamp(static_cast<int>(u * width_), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(v * height_), 0, height_ - 1);
  return std::size_t(y) * width_ + x;
}

Eigen::Vector3f EnvironmentMap::radiance(const Eigen::Vector3f& direction) const {
  return scale_ * texels_[texel_of(direction)];
}

EnvironmentSample EnvironmentMap::sample(float u1, float u2) const {
  // Row, then column within the row; what is left of each number places the sample uniformly
  // inside the texel (piecewise-constant density over the (u, v) image square).
  const auto leftover = [](const float* cdf, int i, float x) {
    const float width = cdf[i + 1] - cdf[i];
    return width > 0 ? std::clamp((x - cdf[i]) / width, 0.0f, 1.0f) : 0.5f;
  };
  const int y = find_interval(row_cdf_.data(), height_, u1);
  const float* cdf = column_cdf_.data() + std::size_t(y) * (width_ + 1);
  const int x = find_interval(cdf, width_, u2);
  const float u = (x + leftover(cdf, x, u2)) / width_;
  const float v = (y + leftover(row_cdf_.data(), y, u1)) / height_;
  const float phi = (u - 0.5f) * 2 * kPi, theta = v * kPi;
  const float sin_theta = std::sin(theta);
  const Eigen::Vector3f in_map(sin_theta * std::sin(phi), std::cos(theta),
                               -sin_theta * std::cos(phi));
  EnvironmentSample sample;
  sample.direction = world_to_map_.transpose() * in_map;
  const std::size_t texel = std::size_t(y) * width_ + x;
  sample.radiance = scale_ * texels_[texel];
  // Density over (u, v) is p_texel W H; d(omega) = 2 pi^2 sin(theta) du dv.
  sample.pdf =
      texel_probability_[texel] * width_ * height_ / (2 * kPi * kPi * std::max(sin_theta, 1e-6f));
  return sample;
}

}  // namespace glint::render
