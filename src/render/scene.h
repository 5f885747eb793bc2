#pragma once
// A renderable scene: objects with Ward materials, near-field point lights, an optional
// environment map, a camera with its trajectory. World axes: metres, +y up, floors at y = 0.
// This is the in-memory form of scene.json (render/scene_json.h) and what the built-in scenes
// (render/builtin_scenes.h) produce.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "render/ward.h"

namespace glint::render {

enum class ShapeKind { mesh, box, sphere, plane };

struct Material {
  WardMaterial ward;          // homogeneous Ward parameters
  std::string kd_texture;     // optional: image whose (linearised) colours replace ward.kd
  float texture_scale_m = 1;  // metres covered by one texture repeat (planar/box projection)
};

struct Object {
  std::string name;
  int id = 0;  // segment id written to gt/segment (1, 2, ...; 0 is "no object")
  ShapeKind shape = ShapeKind::box;
  std::string mesh_path;  // OBJ or PLY, for ShapeKind::mesh
  // Shape size before `transform`: box edge lengths (box centred on the origin); sphere radius
  // in x (centred on the origin); plane extents in x and z (the plane is y = 0, normal +y,
  // centred on the origin); mesh: the mesh is uniformly scaled so its bounding box is size.y()
  // high, centred in x and z, and resting on y = 0.
  Eigen::Vector3d size{1, 1, 1};
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // object-to-world
  Material material;
};

// Isotropic point light; radiance at distance r is intensity / r^2 (near-field, paper 1 §3.2).
struct PointLight {
  Eigen::Vector3d position{0, 2, 0};
  Eigen::Vector3f intensity{1, 1, 1};  // linear RGB radiant intensity (W/sr, arbitrary scale)
  double proxy_radius_m = 0.03;        // visible emissive sphere drawn around the light
};

struct Environment {
  std::string path;        // equirectangular HDR (.hdr / .exr)
  float scale = 1;         // radiance multiplier
  float rotation_deg = 0;  // about +y
  int samples = 64;        // light samples per pixel
};

struct CameraSettings {
  Intrinsics intrinsics = kinect_v2_intrinsics();
  float exposure = 1;        // linear radiance multiplier before 8-bit quantisation (clips)
  float sensor_noise = 0;    // std-dev of Gaussian noise on linear colour, 0 = none
  bool depth_noise = false;  // Kinect-like axial noise sigma(z) = 0.0012 + 0.0019 (z-0.4)^2 m
};

struct Scene {
  std::vector<Object> objects;
  std::vector<PointLight> lights;
  std::optional<Environment> environment;
  CameraSettings camera;
  std::vector<Pose> trajectory;  // camera-to-world per frame (OpenCV camera axes)
  double frames_per_second = 30;
  bool shadows = true;
  // Indirect light (render/renderer.h): path vertices after the one the camera sees, each lit
  // by the point lights (and environment); 0 = direct light only, as the pipeline's model.
  int bounces = 0;
  int indirect_samples = 32;  // paths per pixel for the indirect part (the direct part is exact)
  std::uint64_t seed = 1;     // noise and path seeds derive from it and the frame index
};

}  // namespace glint::render
