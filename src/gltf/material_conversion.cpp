#include "gltf/material_conversion.h"

#include <algorithm>
#include <cmath>

namespace glint::gltf {
namespace {

constexpr int kThetaSteps = 4096;

// Integral over the hemisphere (d omega = 2 pi sin th d th) of f(ward, ggx), midpoint rule.
template <class F>
double hemisphere_integral(double alpha, double a, F f) {
  const double step = 0.5 * M_PI / kThetaSteps;
  double sum = 0;
  for (int i = 0; i < kThetaSteps; ++i) {
    const double theta = (i + 0.5) * step;
    sum += f(ward_half_vector_density(theta, alpha), ggx_half_vector_density(theta, a)) *
           std::sin(theta);
  }
  return 2 * M_PI * step * sum;
}

double squared_error(double alpha, double a) {
  return hemisphere_integral(alpha, a, [](double w, double g) { return (w - g) * (w - g); });
}

}  // namespace

double ward_half_vector_density(double theta_h, double alpha) {
  const double c = std::cos(theta_h), t = std::tan(theta_h);
  return std::exp(-t * t / (alpha * alpha)) / (M_PI * alpha * alpha * c * c * c);
}

double ggx_half_vector_density(double theta_h, double a) {
  const double c = std::cos(theta_h), a2 = a * a;
  const double d = c * c * (a2 - 1) + 1;
  return a2 * c / (M_PI * d * d);
}

double lobe_total_variation(double alpha, double a) {
  return 0.5 * hemisphere_integral(alpha, a, [](double w, double g) { return std::abs(w - g); });
}

LobeFit fit_ggx_to_ward(double alpha) {
  // The squared error is unimodal in a: the GGX lobe is too narrow below the optimum and too
  // wide above it.
  const double golden = 0.5 * (std::sqrt(5.0) - 1);
  double lo = alpha / 4, hi = alpha * 4;
  double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
  double f1 = squared_error(alpha, x1), f2 = squared_error(alpha, x2);
  for (int iteration = 0; iteration < 60; ++iteration) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - golden * (hi - lo), f1 = squared_error(alpha, x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + golden * (hi - lo), f2 = squared_error(alpha, x2);
    }
  }
  LobeFit fit;
  fit.a = 0.5 * (lo + hi);
  fit.squared_error = squared_error(alpha, fit.a);
  fit.total_variation = lobe_total_variation(alpha, fit.a);
  return fit;
}

float ward_alpha_to_roughness(float alpha) {
  return std::clamp(float(std::sqrt(kWardToGgx * std::max(alpha, 0.0f))), 0.0f, 1.0f);
}

Eigen::Vector3f specular_color_factor(const Eigen::Vector3f& ks) {
  return ks.cwiseMax(0.0f) / kDielectricF0;
}

PunctualLight punctual_light(const Eigen::Vector3f& intensity) {
  PunctualLight light;
  const float peak = intensity.maxCoeff();
  if (peak <= 0) return light;
  light.color = intensity / peak;
  light.intensity = peak;
  return light;
}

}  // namespace glint::gltf
