#include "reflectance/light_capture.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace glint::reflectance {
namespace {

TEST(LightCapture, BackProjectsABrightDiscToItsWorldPosition) {
  // A 64x48 camera 2 m below a lamp, looking up (+z of the camera = world +y).
  const Intrinsics k{64, 48, 50.0, 50.0, 31.5, 23.5};
  Pose camera = Pose::Identity();
  camera.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // camera z -> world +y, camera y -> world -z
  camera.translation() = Eigen::Vector3d(0.5, 0.0, -0.25);
  ImageF rgb(64, 48, 3, 0.01f), depth(64, 48, 1, 3.0f);  // dark background
  for (int y = 20; y < 27; ++y)
    for (int x = 10; x < 17; ++x) {  // 7x7 bright pixels centred on (13, 23)
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = 1.0f;
      depth.at(x, y, 0) = 2.0f;
    }
  rgb.at(50, 40, 0) = rgb.at(50, 40, 1) = rgb.at(50, 40, 2) = 1.0f;  // one hot pixel: noise
  LightCaptureParams params;
  params.exposure = 0.25f;
  const auto lights = light_candidates(rgb, depth, k, camera, params);
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_DOUBLE_EQ(lights[0].weight, 49);
  const Eigen::Vector3d expected = camera * k.back_project(13, 23, 2.0);
  EXPECT_LT((lights[0].position - expected).norm(), 1e-9);
  EXPECT_TRUE(lights[0].radiance.isApprox(Eigen::Vector3f(4, 4, 4)));
  EXPECT_NEAR(lights[0].position.y(), 2.0, 1e-9);
}

TEST(LightCapture, RejectsMismatchedImages) {
  const Intrinsics k{8, 8, 10.0, 10.0, 3.5, 3.5};
  EXPECT_THROW(bright_samples(ImageF(8, 8, 3), ImageF(4, 8, 1), k, Pose::Identity(), {}), Error);
}

}  // namespace
}  // namespace glint::reflectance
