#include "reflectance/hemi_image.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <vector>

#include "core/error.h"

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

}  // namespace
}  // namespace glint::reflectance
