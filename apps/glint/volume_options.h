#pragma once
// The TSDF volume's command-line options, shared by `glint fuse` and `glint reconstruct`.
#include <CLI/CLI.hpp>

#include "fusion/volume_params.h"

namespace glint::app {

// --voxel, --trunc, --trunc-per-depth, --depth-max, --blocks onto `volume`.
void add_volume_options(CLI::App* command, fusion::VolumeParams& volume);

}  // namespace glint::app
