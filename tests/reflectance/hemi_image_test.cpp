#include "reflectance/hemi_image.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <vector>

#include "core/error.h"
#include "reflectance/light_incidence.h"

namespace glint::reflectance {
namespace {

TEST(HemiImage, LocalFrameIsOrthonormalAndMapsTheNormalToZ) {
  for (const Eigen::Vector3f& n :
       {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(1, 2, 3).normalized(),
        Eigen::Vector3f(0.3f, -0.9f, -0.1f).normalized()}) {
    const Eigen::Matrix3f m = local_frame(n);
    EXPECT_TRUE((m * m.transpose()).isIdentity(1e-5f));
    EXPECT_NEAR(m.determinant(), 1.0f, 1e-5f);
    EXPECT_TRUE((m * n).isApprox(Eigen::Vector3f::UnitZ(), 1e-5f));
  }
}

TEST(HemiImage, ParabolicMapKnownValues) {
  // Straight up is the centre; the horizon is the rim; 45 degrees lands at tan(22.5 deg).
  EXPECT_TRUE(project_to_disk({0, 0, 1}, HemiProjection::parabolic).isZero());
  EXPECT_TRUE(
      project_to_disk({1, 0, 0}, HemiProjection::parabolic).isApprox(Eigen::Vector2f(1, 0)));
  const float s = std::sqrt(0.5f);
  EXPECT_NEAR(project_to_disk({s, 0, s}, HemiProjection::parabolic).x(), std::tan(M_PI / 8), 1e-6);
  EXPECT_NEAR(project_to_disk({s, 0, s}, HemiProjection::orthographic).x(), s, 1e-6);
}

TEST(HemiImage, NearestNeighbourFillSplitsTheDisk) {
  // Normal +z; a red observation towards +x and a blue one towards -x: the left half of the
  // image is blue, the right half red; the centre column is equidistant.
  const std::vector<Observation> obs = {
      {{1, 0, 0}, Eigen::Vector3f(1, 0, 1).normalized(), 0},
      {{0, 0, 1}, Eigen::Vector3f(-1, 0, 1).normalized(), 1},
      {{0, 1, 0}, {0, 0, -1}, 2},  // below the surface: ignored
  };
  HemiImageParams params;
  std::vector<float> image(3 * 15 * 15, -1.0f);
  make_hemi_image(obs.data(), 3, Eigen::Vector3f::UnitZ(), params, image.data());
  const int plane = 15 * 15;
  for (int y = 0; y < 15; ++y) {
    EXPECT_EQ(image[0 * plane + y * 15 + 14], 1.0f);  // right column red
    EXPECT_EQ(image[2 * plane + y * 15 + 0], 1.0f);   // left column blue
  }
  for (int i = 0; i < plane; ++i) EXPECT_EQ(image[plane + i], 0.0f);  // no green anywhere
}

TEST(HemiImage, SizesOutsideTheSupportedRangeAreRejected) {
  std::vector<float> image(3 * 65 * 65);
  for (int size : {0, kMinHemiImageSize - 1, kMaxHemiImageSize + 1}) {
    HemiImageParams params;
    params.size = size;
    EXPECT_THROW(make_hemi_image(nullptr, 0, Eigen::Vector3f::UnitZ(), params, image.data()),
                 Error);
  }
}

TEST(HemiImage, NoObservationsGiveABlackImage) {
  std::vector<float> image(3 * 15 * 15, -1.0f);
  make_hemi_image(nullptr, 0, Eigen::Vector3f::UnitZ(), {}, image.data());
  for (float v : image) EXPECT_EQ(v, 0.0f);
}

TEST(HemiImage, ReflectanceInputShowsALambertianSurfacesAlbedoWhateverTheLights) {
  // A Lambertian point (normal +y) under two coloured lights: its radiance is kd / pi times
  // sum_l I_l cos / r^2 (eq. (6), ks = 0) in every direction, so its reflectance is kd.
  const Eigen::Vector3f position(0.2f, 0.0f, -0.1f), normal = Eigen::Vector3f::UnitY();
  const Eigen::Vector3f kd(0.6f, 0.3f, 0.1f);
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0.2, 2.0, -0.1};  // straight above, 2 m
  lights[0].intensity = {8, 6, 4};
  lights[1].position = {1.7, 1.5, -0.1};  // 45 degrees
  lights[1].intensity = {3, 3, 9};
  const Eigen::Vector3f irradiance =
      lights[0].intensity / 4.0f + lights[1].intensity * (std::sqrt(0.5f) / 4.5f);
  const Eigen::Vector3f radiance = kd.cwiseProduct(irradiance) / float(M_PI);
  std::vector<Observation> obs;
  for (const Eigen::Vector3f& d : {Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(1, 1, 0).normalized(),
                                   Eigen::Vector3f(0, 1, -2).normalized()})
    obs.push_back({radiance, d, 0});
  std::vector<float> image(3 * 15 * 15);
  make_hemi_image(obs.data(), int(obs.size()), normal, {}, image.data(),
                  hemi_input_scale(HemiInput::reflectance, lights, position, normal));
  for (int c = 0; c < 3; ++c)
    for (int p = 0; p < 225; ++p) EXPECT_NEAR(image[c * 225 + p], kd[c], 1e-3f * kd[c]);

  // Radiance input leaves the colours as they are, bit for bit.
  std::vector<float> plain(image.size()), radiance_input(image.size());
  make_hemi_image(obs.data(), int(obs.size()), normal, {}, plain.data());
  make_hemi_image(obs.data(), int(obs.size()), normal, {}, radiance_input.data(),
                  hemi_input_scale(HemiInput::radiance, lights, position, normal));
  EXPECT_EQ(plain, radiance_input);
}

TEST(HemiImage, ReflectanceScaleFloorsGrazingAndBackLitIrradiance) {
  const Eigen::Vector3f position = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::UnitY();
  std::vector<render::PointLight> lights(1);
  lights[0].intensity = {4, 4, 0};  // no blue at all
  lights[0].position = {0, -2, 0};  // behind the surface; head-on it would give 4 / 2^2 = 1
  const Eigen::Vector3f floored(float(M_PI) / (kMinIrradianceShare * 1.0f),
                                float(M_PI) / (kMinIrradianceShare * 1.0f), 0.0f);
  EXPECT_TRUE(reflectance_scale(lights, position, normal).isApprox(floored, 1e-6f));
  lights[0].position = {2, 0.02, 0};  // grazing: cos 0.01 is under the floor
  EXPECT_TRUE(reflectance_scale(lights, position, normal).isApprox(floored, 1e-3f));
  lights[0].position = {0, 2, 0};  // head-on: pi / (I / r^2)
  EXPECT_TRUE(reflectance_scale(lights, position, normal)
                  .isApprox(Eigen::Vector3f(float(M_PI), float(M_PI), 0.0f), 1e-6f));
  EXPECT_TRUE(reflectance_scale({}, position, normal).isZero());
}

}  // namespace
}  // namespace glint::reflectance
