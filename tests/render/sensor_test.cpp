// The simulated sensor: exposure, clipping, sRGB quantisation, seeded colour and depth noise.
#include "render/sensor.h"

#include <gtest/gtest.h>

#include <cmath>

namespace glint::render {
namespace {

ImageF ramp(int width, int height, float scale) {
  ImageF image(width, height, 3);
  for (std::size_t i = 0; i < image.values().size(); ++i)
    image.values()[i] = scale * float(i % 97) / 96.0f;
  return image;
}

TEST(Sensor, SrgbCurveRoundTrips) {
  for (float x = 0; x <= 1.0f; x += 0.01f) EXPECT_NEAR(srgb_to_linear(linear_to_srgb(x)), x, 1e-6f);
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357f, 1e-5f);
}

TEST(Sensor, EightBitColourClipsHighlightsAndQuantises) {
  ImageF radiance(3, 1, 3);
  for (int c = 0; c < 3; ++c) {
    radiance.at(0, 0, c) = 0.25f;   // 0.5 after exposure
    radiance.at(1, 0, c) = 0.6f;    // 1.2: saturates
    radiance.at(2, 0, c) = 100.0f;  // saturates
  }
  CameraSettings camera;
  camera.exposure = 2.0f;
  const ImageF colour = expose_colour(radiance, camera, 1, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(colour.at(0, 0, c), std::round(0.735357f * 255) / 255);
    EXPECT_FLOAT_EQ(colour.at(1, 0, c), 1.0f);
    EXPECT_FLOAT_EQ(colour.at(2, 0, c), 1.0f);
  }
  const ImageF ramp_colour = expose_colour(ramp(64, 32, 3.0f), camera, 1, 0);
  for (float value : ramp_colour.values()) {
    EXPECT_GE(value, 0.0f);
    EXPECT_LE(value, 1.0f);
    EXPECT_FLOAT_EQ(value * 255, std::round(value * 255));
  }
}

TEST(Sensor, ColourNoiseIsSeeded) {
  CameraSettings camera;
  camera.sensor_noise = 0.02f;
  const ImageF radiance = ramp(64, 32, 0.8f);
  const ImageF a = expose_colour(radiance, camera, 7, 3);
  EXPECT_EQ(a.values(), expose_colour(radiance, camera, 7, 3).values());
  EXPECT_NE(a.values(), expose_colour(radiance, camera, 8, 3).values());
  EXPECT_NE(a.values(), expose_colour(radiance, camera, 7, 4).values());
  camera.sensor_noise = 0;
  EXPECT_NE(a.values(), expose_colour(radiance, camera, 7, 3).values());
}

TEST(Sensor, DepthNoiseFollowsTheKinectModelAndKeepsHoles) {
  ImageF depth(200, 100, 1, 2.4f);
  depth.at(0, 0, 0) = 0;  // no surface
  CameraSettings camera;
  EXPECT_EQ(measure_depth(depth, camera, 1, 0).values(), depth.values());
  camera.depth_noise = true;
  const ImageF noisy = measure_depth(depth, camera, 1, 0);
  EXPECT_EQ(noisy.at(0, 0, 0), 0.0f);
  EXPECT_EQ(noisy.values(), measure_depth(depth, camera, 1, 0).values());
  EXPECT_NE(noisy.values(), measure_depth(depth, camera, 2, 0).values());
  double sum = 0, sum2 = 0;
  for (std::size_t i = 1; i < noisy.pixel_count(); ++i) {
    const double e = noisy.plane(0)[i] - 2.4;
    sum += e;
    sum2 += e * e;
  }
  const double n = double(noisy.pixel_count() - 1);
  const double sigma = 0.0012 + 0.0019 * 2.0 * 2.0;  // 8.8 mm at 2.4 m
  EXPECT_NEAR(sum / n, 0.0, 4 * sigma / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum2 / n), sigma, 0.05 * sigma);
}

TEST(Sensor, DepthPngValuesAreMillimetresAndDropOutOfRange) {
  ImageF depth(3, 1, 1);
  depth.at(0, 0, 0) = 1.2346f;
  depth.at(1, 0, 0) = 70.0f;
  const ImageF values = depth_png_values(depth);
  EXPECT_FLOAT_EQ(values.at(0, 0, 0) * 65535, 1235.0f);  // rounded to whole millimetres
  EXPECT_EQ(values.at(1, 0, 0), 0.0f);
  EXPECT_EQ(values.at(2, 0, 0), 0.0f);
}

}  // namespace
}  // namespace glint::render
