#pragma once
// The HemiCNN training set on disk (paper 1 §4.1: hemi-images made from rendered sequences of
// one object each, sets of 25 of them drawn per training example). Plain C++, no libtorch.
//
//   DIR/index.json      {"format": "glint-hemi-dataset", "version": 1, "size": 15,
//                        "projection": "parabolic" | "orthographic",
//                        "input": "radiance" | "reflectance" (HemiInput; absent: radiance),
//                        "sequences": [{"file": "seq_00000.npy",
//                                       "target": [L, a, b, c_r, c_g, c_b, d],
//                                       "kd": [r, g, b], "ks": [r, g, b], "alpha": a,
//                                       "source": "the rendered sequence it came from"}, ...]}
//   DIR/seq_XXXXX.npy   float32 [M, 3, size, size], kMinHemiImages <= M <= kMaxHemiImages:
//                       M hemi-images of one object, each channel-major (CHW, as
//                       make_hemi_image writes them), linear radiance (pixel / exposure) or,
//                       for "reflectance", radiance times the voxel's reflectance_scale.
// "target" is render::to_perceptual of (kd, ks, alpha): the regression target of eq. (5).
// Memory: a read dataset holds every image, M * 3 * size^2 * 4 bytes per sequence
// (1.35 MB for M = 500, size 15).
#include <cstddef>
#include <string>
#include <vector>

#include "reflectance/hemi_image.h"
#include "render/perceptual.h"
#include "render/ward.h"

namespace glint::reflectance {

inline constexpr int kMinHemiImages = 25;   // one set of the HemiCNN's input
inline constexpr int kMaxHemiImages = 500;  // the paper's hemi-images per sequence

struct HemiSequence {
  std::string file;    // npy file name inside the dataset folder
  std::string source;  // where the images came from (free text)
  render::WardMaterial material;
  render::PerceptualWard target;  // to_perceptual(material)
  int images = 0;                 // M
  std::vector<float> values;      // M x 3 x size x size

  const float* image(int index, int size) const {
    return values.data() + static_cast<std::size_t>(index) * 3 * size * size;
  }
};

struct HemiDataset {
  std::string directory;
  int size = 15;  // pixels per hemi-image side
  HemiProjection projection = HemiProjection::parabolic;
  HemiInput input = HemiInput::radiance;
  std::vector<HemiSequence> sequences;
};

// Reads index.json and every npy file. Throws glint::Error naming the file (and the key or
// sequence) for: a missing or malformed index, a wrong format or version, a size outside
// [kMinHemiImageSize, kMaxHemiImageSize], a missing, truncated or non-float npy file, a shape
// other than [M, 3, size, size], M outside [kMinHemiImages, kMaxHemiImages], a non-finite value,
// a material with negative albedos or alpha <= 0, or a target that is not its material's.
HemiDataset read_hemi_dataset(const std::string& directory);

// Writes a dataset: one npy file per add_sequence (atomic), index.json on finish() (atomic).
// Without finish() the folder has no index and read_hemi_dataset rejects it.
class HemiDatasetWriter {
 public:
  // Creates the folder (and parents). Throws glint::Error for a size out of range or when the
  // folder cannot be created.
  explicit HemiDatasetWriter(std::string directory, int size = 15,
                             HemiProjection projection = HemiProjection::parabolic,
                             HemiInput input = HemiInput::radiance);

  // Writes `count` images (count x 3 x size x size floats, CHW each) of one object as the next
  // seq_XXXXX.npy and returns its index. Throws glint::Error for a count outside
  // [kMinHemiImages, kMaxHemiImages], a non-finite value or an invalid material.
  int add_sequence(const float* images, int count, const render::WardMaterial& material,
                   const std::string& source);

  // Writes index.json listing every added sequence.
  void finish();

  int sequence_count() const { return static_cast<int>(entries_.size()); }

 private:
  std::string directory_;
  int size_;
  HemiProjection projection_;
  HemiInput input_;
  std::vector<HemiSequence> entries_;  // without values
};

}  // namespace glint::reflectance
