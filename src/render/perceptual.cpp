#include "render/perceptual.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace glint::render {
namespace {

// D65 reference white and the sRGB primaries' RGB -> XYZ matrix (IEC 61966-2-1).
const Eigen::Vector3f kWhite(0.95047f, 1.0f, 1.08883f);

Eigen::Matrix3f rgb_to_xyz() {
  Eigen::Matrix3f m;
  m << 0.4124f, 0.3576f, 0.1805f, 0.2126f, 0.7152f, 0.0722f, 0.0193f, 0.1192f, 0.9505f;
  return m;
}

constexpr float kDelta = 6.0f / 29.0f;

float lab_f(float t) {
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0f / 29.0f;
}
float lab_f_inverse(float f) {
  return f > kDelta ? f * f * f : 3 * kDelta * kDelta * (f - 4.0f / 29.0f);
}

}  // namespace

Eigen::Vector3f linear_rgb_to_lab(const Eigen::Vector3f& rgb) {
  const Eigen::Vector3f xyz = (rgb_to_xyz() * rgb).cwiseQuotient(kWhite);
  const float fx = lab_f(xyz.x()), fy = lab_f(xyz.y()), fz = lab_f(xyz.z());
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

Eigen::Vector3f lab_to_linear_rgb(const Eigen::Vector3f& lab) {
  const float fy = (lab.x() + 16.0f) / 116.0f;
  const float fx = fy + lab.y() / 500.0f;
  const float fz = fy - lab.z() / 200.0f;
  const Eigen::Vector3f xyz =
      Eigen::Vector3f(lab_f_inverse(fx), lab_f_inverse(fy), lab_f_inverse(fz)).cwiseProduct(kWhite);
  return rgb_to_xyz().inverse() * xyz;
}

PerceptualWard to_perceptual(const WardMaterial& m) {
  PerceptualWard p;
  p.lab = linear_rgb_to_lab(m.kd);
  for (int i = 0; i < 3; ++i) {
    const float half_kd = std::max(0.0f, m.kd[i]) / 2;
    p.c[i] = std::cbrt(std::max(0.0f, m.ks[i]) + half_kd) - std::cbrt(half_kd);
  }
  p.d = 1.0f - m.alpha;
  return p;
}

WardMaterial from_perceptual(const PerceptualWard& p) {
  WardMaterial m;
  m.kd = lab_to_linear_rgb(p.lab).cwiseMax(0.0f);
  for (int i = 0; i < 3; ++i) {
    const float root_half_kd = std::cbrt(m.kd[i] / 2);
    const float root = p.c[i] + root_half_kd;
    m.ks[i] = root * root * root - root_half_kd * root_half_kd * root_half_kd;
  }
  m.alpha = 1.0f - p.d;
  return m;
}

}  // namespace glint::render
