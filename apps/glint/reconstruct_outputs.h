#pragma once
// What `glint reconstruct` writes besides its report and reflectance/reconstruction_outputs.h's
// files: per-frame pictures, the Figure-4-style plots and the Table-1-style summary on stdout.
#include <string>

#include "core/image.h"
#include "reflectance/material_evaluation.h"
#include "reflectance/material_maps.h"

namespace glint::app {

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
