#pragma once
// The built-in synthetic scenes, mirroring paper 1 §4.2 (Figs 2-5, Table 1): objects on a
// floor, near-field point lights, a camera 4 m from the scene's centre moving around it. World
// axes: metres, +y up, floor at y = 0. Colours are linear RGB; every material keeps
// kd + ks <= 1 per channel and every object has a unique id >= 1 (its gt/segment value), in the
// order listed below. Light proxies are spheres of 5 cm radius.
//
// cubes   floor 6x6 m (kd 0.45 grey, ks 0.05, alpha 0.3) and six cubes of 0.4 m edge, yawed,
//         on a ring of 0.9 m radius (ids 2-7):
//           red    kd (0.60 0.06 0.05) ks 0.25 alpha 0.05
//           green  kd (0.10 0.45 0.12) ks 0.12 alpha 0.12
//           blue   kd (0.08 0.12 0.55) ks 0.06 alpha 0.25
//           white  kd (0.75 0.75 0.72) ks 0.15 alpha 0.08
//           gold   kd (0.20 0.14 0.03) ks (0.65 0.50 0.20) alpha 0.15
//           black  kd 0.04 ks 0.35 alpha 0.03
//         lights: (1.5, 2.4, 2.0) intensity 10; (-1.8, 2.0, -1.2) intensity (7, 6, 5).
//         camera: full orbit, radius 3.8 m, 1.5 m high, looking at (0, 0.2, 0): 4.0 m away.
// bunnies floor 8x8 m (kd 0.5 grey, ks 0.04, alpha 0.3) and three Stanford bunnies 1.5 m high
//         on a ring of 1.3 m radius (ids 2-4; mesh DATA/meshes/stanford-bunny.obj):
//           yellow  kd (0.75 0.55 0.04) ks 0.20 alpha 0.05 (very glossy)
//           teal    kd (0.03 0.40 0.38) ks 0.12 alpha 0.12
//           orange  kd (0.80 0.25 0.03) ks 0.06 alpha 0.25 (rough)
//         lights: (0, 2.6, 0) intensity 12; (2.2, 2.0, 1.6) intensity 8; (-2.0, 1.7, -1.8)
//         intensity (7, 6, 4.5).
//         camera: oscillation +-60 deg around the +z side, 2 periods, radius 3.7 m, 1.6 m high
//         (+-0.3 m), looking at (0, 0.6, 0): 3.8 m away.
// office  a room 6x6 m with three walls 2.8 m high (open towards +z), ids in order:
//           floor   kd (0.35 0.25 0.18) ks 0.08 alpha 0.15 (varnished)
//           walls   back (z = -3), left (x = -3), right (x = 3): kd (0.70 0.68 0.62) ks 0.02 a 0.3
//           table   box 1.6 x 0.75 x 0.8 m at (0, 0, -1): DATA/textures/onyx albedo (0.5 m
//                   repeat), ks 0.05 alpha 0.04 (polished stone, spatially varying kd)
//           spot    0.35 m on the table, DATA/meshes/spot.obj with its UV texture, ks 0.05 a 0.2
//           teapot  0.25 m on the table, porcelain kd (0.80 0.80 0.78) ks 0.15 alpha 0.04
//           suzanne 0.3 m on the table, red plastic kd (0.50 0.05 0.05) ks 0.30 alpha 0.10
//           crate   box 0.5 m at (-1.8, 0, -2.0): DATA/textures/bark albedo, ks 0.02 alpha 0.3
//           ball    sphere 0.25 m radius at (1.6, 0.25, -1.6): kd (0.05 0.10 0.45) ks 0.3 a 0.06
//           cabinet box 0.8 x 1.2 x 0.5 m at (2.2, 0, -2.4): DATA/textures/rustymetal, ks 0.1 a 0.3
//         lights on the ceiling height 2.6 m: (-1.0, 2.6, -0.8) intensity 10; (1.2, 2.6, -1.6)
//         intensity 8; (0, 2.6, 0.8) intensity (6, 6, 5).
//         camera: oscillation +-40 deg, 2 periods, around (0, 0, -1) at radius 2.6 m, 1.7 m high
//         (+-0.2 m), looking at the table (0, 0.85, -1.2).
// Light capture (make_light_capture): the same scene at exposure 5e-4, the camera looking up at
// each light in turn (render/trajectories.h light_capture_trajectory); light proxies read
// 0.29-0.76 per channel without clipping and lit surfaces stay below 0.02 (the yellow bunny's
// highlight, the brightest, 0.018), as the pipeline's capture sequence needs (paper 1 §3.2;
// reflectance/light_estimation.h measures the intensities from it).
//
// File paths are not checked here; the Renderer (or read_scene_json) reports a missing file.
#include <cstdint>
#include <string>
#include <vector>

#include "render/scene.h"
#include "render/trajectories.h"

namespace glint::render {

// $GLINT_DATA when set, else "../shared/data" (docs/design.md "Data").
std::string default_data_dir();

// The Kinect v2 camera (core/camera.h) scaled to `width`; a height other than 424 * scale keeps
// square pixels and moves the principal point to the same relative position.
Intrinsics sensor_intrinsics(int width, int height);

struct BuiltinOptions {
  std::string data_dir = default_data_dir();  // holds meshes/ and textures/
  int frames = 300;
  int width = 512, height = 424;
  std::uint64_t seed = 1;  // Scene::seed (sensor and environment noise)
};

// "cubes", "bunnies", "office".
const std::vector<std::string>& builtin_scene_names();

// Throws glint::Error for an unknown name or frames < 1.
Scene make_builtin_scene(const std::string& name, const BuiltinOptions& options);

// Exposure of the light-capture sequence: the built-in 5 cm proxies (intensity 4.5-12 per
// channel, radiance I / (pi r^2) = 573-1528) read 0.29-0.76, so none clips and their intensity
// can be measured, while a kd 0.9 surface 1 m from a light of intensity 12 reads 0.0017.
inline constexpr float kLightCaptureExposure = 5e-4f;

// The light-capture sequence for `scene`: same objects and lights, exposure lowered, the
// camera pointed at the light sources. Throws glint::Error when the scene has no lights.
Scene make_light_capture(const Scene& scene, const LightCaptureParams& path = {},
                         float exposure = kLightCaptureExposure);

}  // namespace glint::render
