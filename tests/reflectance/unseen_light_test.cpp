#include "reflectance/unseen_light.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "reflectance/light_transport.h"

namespace glint::reflectance {
namespace {

// A segment of albedo kd whose voxels get known irradiance E (a share of them in full shadow)
// and the same unseen irradiance A: D = kd / pi * (E + A), with 2 % noise.
struct Segment {
  std::vector<Eigen::Vector3f> irradiance, radiance;
};
Segment segment_voxels(const Eigen::Vector3f& kd, const Eigen::Vector3f& unseen, int count,
                       float shadowed_share, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> lit(0.3f, 1.5f), unit(0, 1);
  std::normal_distribution<float> noise(1.0f, 0.02f);
  Segment s;
  for (int i = 0; i < count; ++i) {
    const float e = unit(rng) < shadowed_share ? 0.0f : lit(rng);
    const Eigen::Vector3f known(e, 0.9f * e, 0.8f * e);
    s.irradiance.push_back(known);
    s.radiance.push_back(kd.cwiseProduct(known + unseen) / float(M_PI) * noise(rng));
  }
  return s;
}

TEST(UnseenLight, TheRadianceLineGivesTheUnseenIrradianceOfEachChannel) {
  const Eigen::Vector3f kd(0.6f, 0.3f, 0.1f), unseen(0.4f, 0.3f, 0.2f);
  Segment s = segment_voxels(kd, unseen, 400, 0.2f, 1);
  // A tenth of the voxels are outliers: lit by the model, black in the image (a shadow the fused
  // geometry does not cast), or a highlight the specular term missed.
  for (int i = 0; i < 40; ++i) s.radiance[std::size_t(10 * i)] *= i % 2 ? 0.0f : 3.0f;
  std::vector<int> order;
  const auto line = fit_radiance_line(s.irradiance, s.radiance, {}, order);
  ASSERT_TRUE(line.has_value());
  EXPECT_TRUE(line->slope.isApprox(kd / float(M_PI), 0.05f)) << line->slope.transpose();
  const Eigen::Vector3f found = unseen_irradiance(*line, 0.1f);
  EXPECT_TRUE(found.isApprox(unseen, 0.1f)) << found.transpose();
}

TEST(UnseenLight, NoUnseenLightFitsNone) {
  std::vector<int> order;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Segment s = segment_voxels({0.5f, 0.5f, 0.5f}, Eigen::Vector3f::Zero(), 200, 0, seed);
    const auto line = fit_radiance_line(s.irradiance, s.radiance, {}, order);
    ASSERT_TRUE(line.has_value());
    EXPECT_LT(std::abs(line->intercept.mean()), 0.03f * line->slope.mean());  // A within 0.03
    EXPECT_TRUE(unseen_irradiance(*line, 0.1f).isZero());
  }
}

TEST(UnseenLight, TooFewVoxelsOrTooLittleSpreadFitNothing) {
  std::vector<int> order;
  const Segment few = segment_voxels({0.5f, 0.5f, 0.5f}, {0.2f, 0.2f, 0.2f}, 40, 0.2f, 3);
  EXPECT_FALSE(fit_radiance_line(few.irradiance, few.radiance, {}, order).has_value());
  // Every voxel under about the same light: the intercept would be an extrapolation.
  Segment flat = segment_voxels({0.5f, 0.5f, 0.5f}, {0.2f, 0.2f, 0.2f}, 200, 0, 4);
  for (Eigen::Vector3f& e : flat.irradiance) e = 1.0f + 0.1f * (e.array() - 0.9f);
  EXPECT_FALSE(fit_radiance_line(flat.irradiance, flat.radiance, {}, order).has_value());
  // Darker where more light falls: no albedo explains it.
  Segment inverted = segment_voxels({0.5f, 0.5f, 0.5f}, Eigen::Vector3f::Zero(), 200, 0, 5);
  for (std::size_t i = 0; i < inverted.radiance.size(); ++i)
    inverted.radiance[i] = Eigen::Vector3f::Constant(2) - inverted.irradiance[i];
  EXPECT_FALSE(fit_radiance_line(inverted.irradiance, inverted.radiance, {}, order).has_value());
}

TEST(UnseenLight, LightTransportFusesTheLinesOfSuccessiveFrames) {
  LightTransportParams params;
  params.unseen = true;
  params.unseen_memory = 4;
  LightTransport transport(params, 16);
  EXPECT_TRUE(transport.enabled());
  EXPECT_TRUE(transport.unseen(3).isZero());  // before any fit
  const RadianceLine line{.slope = Eigen::Vector3f::Constant(0.1f),
                          .intercept = Eigen::Vector3f::Constant(0.05f),
                          .typical_irradiance = 1};
  transport.fuse_unseen(3, line);
  EXPECT_TRUE(transport.unseen(3).isApprox(Eigen::Vector3f::Constant(0.5f)));
  // A frame whose intercept is zero: the mean of the two lines.
  transport.fuse_unseen(3, RadianceLine{.slope = line.slope, .typical_irradiance = 1});
  EXPECT_TRUE(transport.unseen(3).isApprox(Eigen::Vector3f::Constant(0.25f)));
  // Voxel 0 of segment 3: its indirect light is the segment's unseen irradiance (no gather).
  EXPECT_TRUE(transport.lighting(0, 3).indirect.isApprox(Eigen::Vector3f::Constant(0.25f)));
  EXPECT_TRUE(transport.lighting(0, 2).indirect.isZero());
  // Below min_share of the typical irradiance: none.
  transport.fuse_unseen(5, RadianceLine{.slope = line.slope,
                                        .intercept = Eigen::Vector3f::Constant(0.005f),
                                        .typical_irradiance = 1});
  EXPECT_TRUE(transport.unseen(5).isZero());
}

}  // namespace
}  // namespace glint::reflectance
