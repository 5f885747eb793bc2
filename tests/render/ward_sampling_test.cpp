// Ward importance sampling (render/ward_sampling.h) against quadrature: the densities integrate
// to one, and sampled estimates of the directional albedo match the integral of f cos.
#include "render/ward_sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <type_traits>

#include "render/random.h"

namespace glint::render {
namespace {

const Eigen::Vector3f kNormal = Eigen::Vector3f(0.3f, 0.8f, -0.5f).normalized();

// A unit direction at polar angle theta from kNormal, azimuth phi in its tangent frame.
Eigen::Vector3f direction_at(float theta, float phi) {
  Eigen::Vector3f t, b;
  tangent_frame(kNormal, t, b);
  return std::sin(theta) * (std::cos(phi) * t + std::sin(phi) * b) + std::cos(theta) * kNormal;
}

template <class T>
T zero() {
  if constexpr (std::is_arithmetic_v<T>)
    return T(0);
  else
    return T::Zero();
}

// Midpoint rule over the sphere (upper hemisphere only when `hemisphere`) in (theta, phi), fine
// enough for the narrowest lobe tested (alpha 0.05: about 25 steps across its width).
template <class Integrand>
auto integrate_sphere(Integrand&& integrand, bool hemisphere = false) {
  using Value = decltype(integrand(kNormal));
  const int theta_steps = 1500, phi_steps = 1000;
  const double theta_max = hemisphere ? M_PI / 2 : M_PI;
  const double d_theta = theta_max / theta_steps, d_phi = 2 * M_PI / phi_steps;
  Value sum = zero<Value>();
  for (int i = 0; i < theta_steps; ++i) {
    const double theta = (i + 0.5) * d_theta;
    Value ring = zero<Value>();
    for (int j = 0; j < phi_steps; ++j)
      ring += integrand(direction_at(float(theta), float((j + 0.5) * d_phi)));
    sum += ring * std::sin(theta) * d_theta * d_phi;
  }
  return sum;
}

struct Case {
  float alpha;
  float view_deg;  // angle of wo from the normal
};
const Case kCases[] = {{0.05f, 0}, {0.05f, 60}, {0.15f, 30}, {0.3f, 0}, {0.3f, 70}};

// The half-vector density behind eq. (9), exp(-tan^2 / alpha^2) / (pi alpha^2 cos^3).
double half_vector_density(const Eigen::Vector3f& h, float alpha) {
  const double cos_h = kNormal.dot(h);
  if (cos_h <= 0) return 0;
  const double tan2 = (1 - cos_h * cos_h) / (cos_h * cos_h);
  return std::exp(-tan2 / (alpha * alpha)) / (M_PI * alpha * alpha * cos_h * cos_h * cos_h);
}

TEST(WardSampling, HalfVectorDensityIntegratesToOneOverTheHemisphere) {
  for (const float alpha : {0.05f, 0.15f, 0.3f}) {
    const double total = integrate_sphere(
        [&](const Eigen::Vector3f& h) { return half_vector_density(h, alpha); }, true);
    EXPECT_NEAR(total, 1.0, 1e-3) << "alpha " << alpha;
  }
}

// The pdf of wi integrates to the probability that the drawn half vector faces wo: that is 1
// at normal view and loses exactly the half vectors that reflect wo below themselves (drawn,
// then rejected by sample_ward_brdf) at oblique view. Checks eq. (9)'s Jacobian 1 / (4 h.wo).
TEST(WardSampling, SpecularPdfIntegratesToTheShareOfUsableHalfVectors) {
  for (const Case& c : kCases) {
    const Eigen::Vector3f wo = direction_at(c.view_deg * float(M_PI) / 180, 0.4f);
    const double pdf_total = integrate_sphere(
        [&](const Eigen::Vector3f& wi) { return ward_specular_pdf(kNormal, wi, wo, c.alpha); });
    const double usable = integrate_sphere(
        [&](const Eigen::Vector3f& h) {
          return h.dot(wo) > 0 ? half_vector_density(h, c.alpha) : 0.0;
        },
        true);
    EXPECT_NEAR(pdf_total, usable, 2e-3) << "alpha " << c.alpha << " view " << c.view_deg;
    if (c.view_deg == 0) {
      EXPECT_NEAR(pdf_total, 1.0, 2e-3) << "alpha " << c.alpha;
    }
  }
}

TEST(WardSampling, MixturePdfIntegratesToAtMostOne) {
  const WardMaterial material{{0.4f, 0.3f, 0.2f}, {0.3f, 0.3f, 0.3f}, 0.15f};
  const Eigen::Vector3f wo = direction_at(0.0f, 0.0f);
  const double total = integrate_sphere(
      [&](const Eigen::Vector3f& wi) { return ward_brdf_pdf(material, kNormal, wi, wo); });
  EXPECT_NEAR(total, 1.0, 2e-3);
}

// Sampled estimates of the directional albedo int f cos dwi against quadrature, for specular,
// diffuse and mixed materials: within 4 standard errors of the estimate plus the quadrature's
// 1e-3.
TEST(WardSampling, SampledAlbedoMatchesQuadrature) {
  const WardMaterial materials[] = {
      {{0.0f, 0.0f, 0.0f}, {0.8f, 0.8f, 0.8f}, 0.05f},
      {{0.6f, 0.6f, 0.6f}, {0.0f, 0.0f, 0.0f}, 0.1f},
      {{0.6f, 0.3f, 0.1f}, {0.2f, 0.3f, 0.4f}, 0.15f},
      {{0.04f, 0.04f, 0.04f}, {0.35f, 0.35f, 0.35f}, 0.3f},
  };
  const int samples = 200000;
  for (const WardMaterial& material : materials) {
    for (const Case& c : kCases) {
      const Eigen::Vector3f wo = direction_at(c.view_deg * float(M_PI) / 180, 1.1f);
      WardMaterial m = material;
      m.alpha = material.kd.isZero() ? c.alpha : material.alpha;
      const Eigen::Vector3d exact = integrate_sphere([&](const Eigen::Vector3f& wi) {
        return Eigen::Vector3d(
            (ward_brdf(m, kNormal, wi, wo) * std::max(0.0f, kNormal.dot(wi))).cast<double>());
      });
      PixelRandom random(7, 0, 0, RandomPurpose::indirect);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
      for (int s = 0; s < samples; ++s) {
        const float u_lobe = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
        const BrdfSample sample = sample_ward_brdf(m, kNormal, wo, u_lobe, u1, u2);
        if (sample.pdf > 0) {
          EXPECT_NEAR(sample.direction.norm(), 1.0f, 1e-5f);
          EXPECT_GT(kNormal.dot(sample.direction), 0.0f);
        }
        const Eigen::Vector3d weight = sample.weight.cast<double>();
        sum += weight;
        sum2 += weight.cwiseProduct(weight);
      }
      const Eigen::Vector3d mean = sum / samples;
      for (int channel = 0; channel < 3; ++channel) {
        const double variance = sum2[channel] / samples - mean[channel] * mean[channel];
        const double standard_error = std::sqrt(std::max(0.0, variance) / samples);
        EXPECT_NEAR(mean[channel], exact[channel], 4 * standard_error + 1e-3)
            << "kd " << m.kd.transpose() << " ks " << m.ks.transpose() << " alpha " << m.alpha
            << " view " << c.view_deg << " channel " << channel;
      }
    }
  }
}

TEST(WardSampling, BlackMaterialsAndBackFacingViewsGiveNoSample) {
  const WardMaterial black{{0, 0, 0}, {0, 0, 0}, 0.1f};
  EXPECT_EQ(sample_ward_brdf(black, kNormal, kNormal, 0.5f, 0.5f, 0.5f).pdf, 0.0f);
  const WardMaterial grey;
  EXPECT_EQ(sample_ward_brdf(grey, kNormal, -kNormal, 0.5f, 0.5f, 0.5f).pdf, 0.0f);
}

}  // namespace
}  // namespace glint::render
