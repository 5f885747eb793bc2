#pragma once
// What a reconstruction leaves behind, shared by `glint reconstruct` and the Python module's
// Reconstruction: re-renderings of the model from a pose, the material mesh, materials.json,
// the lights, and the output folder that is replaced whole when the result is complete.
#include <nlohmann/json.hpp>
#include <string>

#include "core/camera.h"
#include "core/timer.h"
#include "fusion/triangle_mesh.h"
#include "reflectance/light_estimation.h"
#include "reflectance/material_maps.h"
#include "reflectance/reflectance_pipeline.h"

namespace glint::reflectance {

// The lights a reconstruction uses, from `source`: a light-capture sequence folder (estimated,
// paper 1 §3.2, with a progress bar) or a lights.json. Throws glint::Error naming `source` when
// it is unreadable or the capture shows no light.
LightEstimate load_lights(const std::string& source);

// Re-renderings smooth the ray-cast normals within this radius: the TSDF's surface carries
// millimetre bumps from the depth quantisation that per-pixel normals turn into speckled
// shading (4 voxels at 5 mm; docs/decisions.md).
inline constexpr float kRenderNormalRadiusM = 0.02f;

// The model re-rendered from `pose` (camera-to-world) into `maps`: ray cast (gradient normals),
// its normals smoothed within `normal_radius_m` (0: not), and shaded with the pipeline's
// materials and lights. `fused_depth`: the depth of a frame just fused from `pose`, which the ray
// cast starts from (fusion::raycast's depth hint), or nullptr. The steps are timed into
// `timings` as "raycast", "smooth_normals" and "shade".
void render_model(const ReflectancePipeline& pipeline, const Intrinsics& intrinsics,
                  const Pose& pose, float normal_radius_m, StageTimings& timings,
                  MaterialMaps& maps, const ImageF* fused_depth = nullptr);

// Marching-cubes mesh of the geometry; per vertex: the refined kd as colour (linear RGB) and
// float properties kd_r/g/b (refined), ks_r/g/b, alpha, scalar_segment (0 = none; vertices
// without a material have zeros) and observations (the stored observations of the observation
// voxel holding the vertex: what the albedo atlas's denoising is guided by).
fusion::TriangleMesh material_mesh(const ReflectancePipeline& pipeline);
// material_mesh() as a binary PLY (colour as 8-bit sRGB), written atomically.
void write_material_mesh(const std::string& path, const ReflectancePipeline& pipeline);

// Per segment: fused kd, ks, alpha, the latest estimate, estimate count, voxel count and the
// mean refined kd of its voxels; the exposure and the observation grid's voxel size.
nlohmann::json materials_json(const ReflectancePipeline& pipeline);
void write_materials_json(const std::string& path, const ReflectancePipeline& pipeline);

// Segments that could carry a material (not merged away, with at least `min_voxels` voxel
// references: SpecularParams::min_distinct_voxels) and how many of them have none, because no
// frame found that many of their voxels with SpecularParams::min_observations observations.
struct MaterialCoverage {
  int segments = 0, without_material = 0;
};
MaterialCoverage material_coverage(const ReflectancePipeline& pipeline, int min_voxels);

// FOLDER/mesh.ply, FOLDER/materials.json and FOLDER/lights.json of the pipeline's current state.
void write_reconstruction(const std::string& folder, const ReflectancePipeline& pipeline,
                          const LightEstimate& lights);

// An output folder written whole: files go to OUT.partial-PID (path()), which commit() renames
// onto OUT; destroyed without commit() it is removed, so a failure leaves no half-written result.
// OUT is replaced only when it is missing, empty or a previous reconstruction (it has
// materials.json), never a folder or file of the user's that happened to be named.
class ReconstructionFolder {
 public:
  // Throws glint::Error naming `output` when it is not replaceable.
  explicit ReconstructionFolder(std::string output);
  ~ReconstructionFolder();
  ReconstructionFolder(const ReconstructionFolder&) = delete;
  ReconstructionFolder& operator=(const ReconstructionFolder&) = delete;

  const std::string& path() const { return partial_; }
  void commit();

 private:
  std::string output_, partial_;
  bool committed_ = false;
};

}  // namespace glint::reflectance
