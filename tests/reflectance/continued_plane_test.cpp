#include "reflectance/continued_plane.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glint::reflectance {
namespace {

const ContinuedPlane kFloor{
    .normal = Eigen::Vector3f::UnitY(), .offset = 0, .albedo = Eigen::Vector3f(0.5f, 0.25f, 0.1f)};

TEST(ContinuedPlane, ARayMeetsItsFrontSideOnly) {
  const Eigen::Vector3f above(0, 1, 0), down_right = Eigen::Vector3f(1, -1, 0).normalized();
  EXPECT_NEAR(kFloor.hit(above, down_right), std::sqrt(2.0f), 1e-6f);
  EXPECT_TRUE(std::isinf(kFloor.hit(above, -down_right)));                // moving away
  EXPECT_TRUE(std::isinf(kFloor.hit(above, Eigen::Vector3f::UnitX())));   // parallel
  EXPECT_TRUE(std::isinf(kFloor.hit(-above, Eigen::Vector3f::UnitY())));  // from behind
  EXPECT_TRUE(std::isinf(ContinuedPlane{}.hit(above, down_right)));       // none
}

TEST(ContinuedPlane, ItsRadianceIsItsAlbedoOverPiTimesTheLightsIrradiance) {
  render::PointLight light;
  light.position = {0, 2, 0};
  light.intensity = {10, 10, 10};
  render::PointLight below = light;
  below.position = {0, -1, 0};
  // At (1, 0, 0): the light 5 m^2 away at cos 2 / sqrt(5); the one below the floor adds nothing.
  const float irradiance = 10 * (2 / std::sqrt(5.0f)) / 5;
  const Eigen::Vector3f radiance = kFloor.radiance({1, 0, 0}, {light, below});
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(radiance[c], kFloor.albedo[c] / float(M_PI) * irradiance, 1e-6f);
}

}  // namespace
}  // namespace glint::reflectance
