#pragma once
// What `glint reconstruct` writes besides its report: the material mesh, materials.json,
// per-frame pictures, the Figure-4-style plots and the Table-1-style summary on stdout.
#include <nlohmann/json.hpp>
#include <string>

#include "core/image.h"
#include "reflectance/material_evaluation.h"
#include "reflectance/material_maps.h"
#include "reflectance/reflectance_pipeline.h"

namespace glint::app {

// Marching-cubes mesh of the geometry; per vertex: the refined kd as colour (8-bit sRGB) and
// float properties kd_r/g/b (refined), ks_r/g/b, alpha and scalar_segment (0 = none).
void write_material_mesh(const std::string& path, const reflectance::ReflectancePipeline& pipeline);

// Per segment: fused kd, ks, alpha, the latest estimate, estimate count, voxel count and the
// mean refined kd of its voxels.
nlohmann::json materials_json(const reflectance::ReflectancePipeline& pipeline);
void write_materials_json(const std::string& path,
                          const reflectance::ReflectancePipeline& pipeline);

// Segments that could carry a material (not merged away, with at least `min_voxels` voxel
// references: SpecularParams::min_distinct_voxels) and how many of them have none, because no
// frame found that many of their voxels with SpecularParams::min_observations observations.
struct MaterialCoverage {
  int segments = 0, without_material = 0;
};
MaterialCoverage material_coverage(const reflectance::ReflectancePipeline& pipeline,
                                   int min_voxels);

// OUT/frames/NNNNNN-{input,render,render-hemicnn,albedo,segments}.png (8-bit sRGB) and
// NNNNNN-overview.png (input, re-rendering, refined albedo and segments side by side).
void write_frame_pictures(const std::string& output, int frame, const ImageF& input_colour,
                          const reflectance::MaterialMaps& maps);

// FOLDER/NNNNNN-{render,render-hemicnn,albedo}.png of a re-rendering from a free pose.
void write_view_pictures(const std::string& folder, int index,
                         const reflectance::MaterialMaps& maps);

// Estimated (thin), refined (dashed) and true (bold) red kd, ks, alpha and red RGB of every
// object over the evaluated frames (paper 1 Fig. 4).
void write_material_plots(const std::string& path,
                          const reflectance::MaterialEvaluation& evaluation, int frame_step);

// Paper 1 Table 1: per object and averaged L1, RMSE, PSNR, SSIM of every quantity.
void print_evaluation_table(const reflectance::MaterialEvaluation& evaluation);

}  // namespace glint::app
