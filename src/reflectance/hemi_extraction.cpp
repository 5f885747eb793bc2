#include "reflectance/hemi_extraction.h"

#include <algorithm>
#include <filesystem>
#include <random>

#include "core/error.h"
#include "fusion/fusion_pipeline.h"
#include "io/rgbd_sequence.h"
#include "reflectance/material_evaluation.h"
#include "reflectance/segment_map.h"
#include "render/scene_json.h"

namespace glint::reflectance {

ExtractedHemiImages extract_hemi_images(const std::string& sequence_folder,
                                        const std::vector<HemiImageKind>& kinds,
                                        const HemiExtractionParams& params) {
  const io::RgbdSequence sequence = io::open_rgbd_sequence(sequence_folder);
  if (!has_ground_truth_maps(sequence) || !sequence.has_ground_truth())
    throw Error(sequence_folder, "", "needs a glint sequence with gt/ maps and poses");
  const render::Scene scene =
      render::read_scene_json((std::filesystem::path(sequence_folder) / "scene.json").string());
  const auto object = std::find_if(scene.objects.begin(), scene.objects.end(),
                                   [](const render::Object& o) { return o.id == 1; });
  if (object == scene.objects.end())
    throw Error(sequence_folder + "/scene.json", "objects", "has no object with id 1");

  fusion::FusionParams geometry;
  geometry.volume.voxel_size_m = params.geometry_voxel_m;
  geometry.use_ground_truth_poses = true;
  geometry.volume.block_capacity = params.geometry_block_capacity;
  geometry.volume.colour = false;  // the observation grid keeps the colours
  fusion::FusionPipeline fusion(sequence.intrinsics, geometry);
  ObservationGrid grid(params.observations);
  SegmentMap segments;
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const io::RgbdFrame frame = io::read_rgbd_frame(sequence, i);
    const fusion::FrameResult placed = fusion.process(frame);
    grid.collect(frame.depth_m, frame.colour, sequence.intrinsics, placed.camera_to_world,
                 scene.camera.exposure, fusion.volume(), int(i));
    segments.update(grid, grid.visible(), read_ground_truth_segments(sequence, i), true);
  }

  // The object's voxels with enough observations, in a seeded random order.
  std::vector<int> voxels;
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.segment(v) == 1 && grid.has_surface(v) &&
        grid.observation_count(v) >= params.min_observations)
      voxels.push_back(v);
  std::mt19937_64 random(params.seed);
  std::shuffle(voxels.begin(), voxels.end(), random);
  voxels.resize(std::min<std::size_t>(voxels.size(), params.max_images));

  ExtractedHemiImages result;
  result.material = object->material.ward;
  result.count = int(voxels.size());
  for (const HemiImageKind& kind : kinds) {
    HemiImageParams hemi;
    hemi.projection = kind.projection;
    const std::size_t floats = std::size_t(3) * hemi.size * hemi.size;
    std::vector<float>& images = result.images.emplace_back(voxels.size() * floats);
    for (std::size_t k = 0; k < voxels.size(); ++k) {
      const int v = voxels[k];
      const Eigen::Vector3f scale =
          hemi_input_scale(kind.input, scene.lights, grid.position(v), grid.normal(v));
      make_hemi_image(grid.observations(v), grid.observation_count(v), grid.normal(v), hemi,
                      images.data() + k * floats, scale);
    }
  }
  return result;
}

}  // namespace glint::reflectance
