#pragma once
// Pictures of one rendered frame for people (docs, quick checks): RGB as the sensor sees it,
// depth in false colour, and the ground-truth kd, ks (sRGB-encoded for display) and alpha
// (grey, 0 -> black, 0.35 -> white) maps. Not a data format: sequences hold the exact values.
#include <string>

#include "render/scene.h"

namespace glint::app {

// Renders trajectory frame 0 of `scene` and writes DIR/{rgb,depth,kd,ks,alpha}.png.
// Returns the render time in milliseconds.
double write_frame_preview(const render::Scene& scene, const std::string& out_dir);

}  // namespace glint::app
