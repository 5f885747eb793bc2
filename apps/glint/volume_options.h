#pragma once
// The geometry's command-line options (TSDF volume, tracking, integration device), shared by
// `glint fuse` and `glint reconstruct`.
#include <CLI/CLI.hpp>

#include "fusion/fusion_pipeline.h"
#include "fusion/volume_params.h"

namespace glint::app {

// --voxel, --trunc, --trunc-per-depth, --depth-max, --blocks onto `volume`.
void add_volume_options(CLI::App* command, fusion::VolumeParams& volume);

// --track-model-halvings onto `tracking`.
void add_tracking_options(CLI::App* command, fusion::TrackingParams& tracking);

// --device cpu|cuda|auto (default auto): where TSDF integration runs.
void add_integration_device_option(CLI::App* command, fusion::IntegrationDevice& device);

}  // namespace glint::app
