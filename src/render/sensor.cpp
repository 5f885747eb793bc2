#include "render/sensor.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "render/random.h"

namespace glint::render {

float linear_to_srgb(float linear) {
  const float x = std::clamp(linear, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

float srgb_to_linear(float encoded) {
  const float x = std::clamp(encoded, 0.0f, 1.0f);
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}

ImageF expose_colour(const ImageF& radiance, const CameraSettings& camera, std::uint64_t seed,
                     int frame_index) {
  ImageF colour(radiance.width(), radiance.height(), 3);
  const std::size_t pixels = radiance.pixel_count();
  parallel_for_chunks(pixels, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      PixelRandom random(seed, frame_index, i, RandomPurpose::colour_noise);
      for (int c = 0; c < 3; ++c) {
        float value = radiance.plane(c)[i] * camera.exposure;
        if (camera.sensor_noise > 0) value += camera.sensor_noise * random.gaussian();
        colour.plane(c)[i] = std::round(linear_to_srgb(value) * 255.0f) / 255.0f;  // clips
      }
    }
  });
  return colour;
}

ImageF measure_depth(const ImageF& depth_m, const CameraSettings& camera, std::uint64_t seed,
                     int frame_index) {
  if (!camera.depth_noise) return depth_m;
  ImageF measured(depth_m.width(), depth_m.height(), 1);
  const float* in = depth_m.plane(0);
  float* out = measured.plane(0);
  parallel_for_chunks(depth_m.pixel_count(), 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const float z = in[i];
      if (z <= 0) continue;
      PixelRandom random(seed, frame_index, i, RandomPurpose::depth_noise);
      const float sigma = kinect_axial_noise_m(z);
      out[i] = std::max(0.0f, z + sigma * random.gaussian());
    }
  });
  return measured;
}

ImageF depth_png_values(const ImageF& depth_m) {
  ImageF values(depth_m.width(), depth_m.height(), 1);
  const float* in = depth_m.plane(0);
  float* out = values.plane(0);
  for (std::size_t i = 0; i < depth_m.pixel_count(); ++i) {
    const float millimetres = std::round(in[i] * 1000.0f);
    out[i] = millimetres <= 65535.0f ? millimetres / 65535.0f : 0.0f;
  }
  return values;
}

}  // namespace glint::render
