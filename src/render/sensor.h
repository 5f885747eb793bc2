#pragma once
// The simulated RGB-D sensor between the renderer's noise-free buffers and the files:
//  - colour: radiance * exposure (+ Gaussian noise of std-dev sensor_noise on linear values),
//    clipped to [0, 1] like a saturating sensor, sRGB-encoded and quantised to 8 bits;
//  - depth: optional Kinect-like axial noise sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 metres
//    (Nguyen et al. 2012), pixels without a surface stay 0.
// Noise is seeded by (seed, frame_index) and deterministic for any thread count.
#include <cstdint>

#include "core/image.h"
#include "render/scene.h"

namespace glint::render {

// Linear [0,1] -> sRGB-encoded [0,1] (IEC 61966-2-1) and back.
float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);

// 3-channel sRGB image with values k / 255 (ready for io::write_image as 8-bit PNG).
ImageF expose_colour(const ImageF& radiance, const CameraSettings& camera, std::uint64_t seed,
                     int frame_index);

// Depth in metres as measured: camera.depth_noise adds the axial noise, values stay >= 0.
ImageF measure_depth(const ImageF& depth_m, const CameraSettings& camera, std::uint64_t seed,
                     int frame_index);

// Depth in metres -> 16-bit PNG code values (millimetres / 65535, i.e. depth_scale 1000);
// depths beyond 65.535 m become 0 (no measurement).
ImageF depth_png_values(const ImageF& depth_m);

}  // namespace glint::render
