#pragma once
// HemiCNN training data from rendered sequences (paper 1 §4.1: "we use those images together
// with our previously described pipeline to create 500 HemiImages per sequence"): each
// sequence of glint's training set (render/training_set.h: one object, id 1, one homogeneous
// Ward material) is run through glint's own geometry fusion (ground-truth poses) and
// observation collection with ground-truth segmentation, and up to max_images of the object's
// voxels with enough observations become HemiImages, in every requested kind (projection and
// input; reflectance inputs are scaled with the sequence's true lights).
#include <cstdint>
#include <string>
#include <vector>

#include "reflectance/hemi_image.h"
#include "reflectance/observation_grid.h"
#include "render/ward.h"

namespace glint::reflectance {

struct HemiExtractionParams {
  ObservationGridParams observations{.voxel_capacity = 1u << 18};  // 2 cm, as the pipeline
  double geometry_voxel_m = 0.005;
  std::size_t geometry_block_capacity = 1u << 15;  // one object: far fewer blocks than a room
  int max_images = 500;
  int min_observations = 5;  // as the pipeline's sampling (SpecularParams)
  std::uint64_t seed = 1;
};

struct HemiImageKind {
  HemiProjection projection = HemiProjection::parabolic;
  HemiInput input = HemiInput::radiance;
};

struct ExtractedHemiImages {
  render::WardMaterial material;  // from the sequence's scene.json, object id 1
  int count = 0;
  // Per requested kind: count x 3 x 15 x 15 floats.
  std::vector<std::vector<float>> images;
};

// Throws glint::Error naming the sequence for a folder that is not a glint sequence with
// ground truth, or a scene.json without object 1.
ExtractedHemiImages extract_hemi_images(const std::string& sequence_folder,
                                        const std::vector<HemiImageKind>& kinds,
                                        const HemiExtractionParams& params = {});

}  // namespace glint::reflectance
