#pragma once
// A reconstruction as one glTF 2.0 binary (docs/reflectance.md "Export", /docs/decisions.md):
// the TSDF mesh simplified to a triangle budget (meshoptimizer), split into one primitive per
// segment with its own material (metallic 0, base colour from the baked kd atlas,
// KHR_materials_specular from ks, roughness from Ward's alpha, the raw Ward values in extras),
// the lights as KHR_lights_punctual, all under a root node that turns glint's world (metres,
// up axis given) into glTF's (+Y up, right-handed).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "denoise/denoiser.h"
#include "gltf/glb.h"
#include "reflectance/light_estimation.h"

namespace glint::gltf {

// The up axis of glint's world frame. glint's synthetic scenes have +y up (render/scene.h);
// a real sequence's frame is its poses' (7-Scenes: the first camera's, +y pointing down, so -y).
enum class UpAxis { pos_x, neg_x, pos_y, neg_y, pos_z, neg_z };
// "+x", "-x", "+y", "-y", "+z", "-z"; throws glint::Error naming `option` otherwise.
UpAxis parse_up_axis(const std::string& text, const std::string& option = "--up");
const char* up_axis_name(UpAxis up);
// The root node's rotation: takes `up` to glTF's +Y (a proper rotation, so handedness is kept).
Eigen::Quaternionf world_to_gltf(UpAxis up);

// What the exporter reads from a reconstruction folder.
struct Reconstruction {
  std::vector<Eigen::Vector3f> vertices;   // metres, glint's world
  std::vector<Eigen::Vector3i> triangles;  // counter-clockwise seen from free space
  std::vector<Eigen::Vector3f> kd;         // refined diffuse albedo per vertex, linear
  std::vector<int> segment;                // per vertex, 0 = none
  // Per vertex, its observation voxel's stored observations (0-30); empty for reconstructions
  // written before mesh.ply carried them.
  std::vector<float> observations;
  float observation_voxel_m = 0.02f;  // materials.json "observation_voxel_m"
  nlohmann::json materials;           // materials.json
  reflectance::LightEstimate lights;
};
// FOLDER/mesh.ply (kd_r, kd_g, kd_b, scalar_segment and, when present, observations per
// vertex), FOLDER/materials.json and
// FOLDER/lights.json, as `glint reconstruct` writes them. Throws glint::Error naming the file.
Reconstruction read_reconstruction(const std::string& folder);

struct ExportParams {
  std::size_t mesh_triangles = 300000;  // simplification budget; 0: full resolution
  int texture_size = 2048;              // kd atlas side, texels; 0: per-vertex COLOR_0 only
  UpAxis up = UpAxis::pos_y;
  // Guided DIP on the kd atlas (gltf/albedo_denoising.h) with these settings; needs the atlas and
  // the mesh's observation counts.
  bool denoise_albedo = false;
  denoise::DenoiserSettings denoise{};
  // A synthetic sequence whose ground truth the atlas is measured against (gltf/albedo_truth.h);
  // empty: none.
  std::string albedo_truth{};
};

struct ExportStats {
  std::size_t input_triangles = 0, triangles = 0, vertices = 0;
  float simplification_error_m = 0;  // meshoptimizer's deviation estimate, metres
  int charts = 0, materials = 0, lights = 0;
  float texels_per_metre = 0;
  std::size_t overlapping_texels = 0;
  // Seconds per step: simplification, chart layout, baking (kNN sampling and dilation), PNG.
  double simplify_s = 0, layout_s = 0, bake_s = 0, png_s = 0;
  // Albedo denoising's statistics ("denoising") and the atlas's errors against the truth
  // ("truth": "atlas", and "denoised" when denoised); null when neither ran.
  nlohmann::json albedo;
  // The counts alone (what the GLB's extras carry: the same file from the same input) and with
  // the seconds (reports).
  nlohmann::json counts_json() const;
  nlohmann::json to_json() const;
};

// The GLB document and binary of `scene`; fills `stats` when given. Throws glint::Error when a
// material in materials.json is malformed or the atlas cannot hold the charts.
GlbBuilder build_scene_glb(const Reconstruction& scene, const ExportParams& params,
                           ExportStats* stats = nullptr);
// build_scene_glb() written atomically to `path`.
ExportStats write_scene_glb(const Reconstruction& scene, const ExportParams& params,
                            const std::string& path);

}  // namespace glint::gltf
