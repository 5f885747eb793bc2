#pragma once
// Evaluation against synthetic ground truth (paper 1 §4.2, Table 1, Figs 4-5): per frame, the
// re-rendered material maps (reflectance/material_maps.h) are compared with the sequence's
// gt/{kd,ks,alpha,segment} maps and the re-rendering with the input image, per ground-truth
// object over the object's pixels that the model covers:
//   L1 (mean absolute deviation), RMSE, PSNR (peak 1) and SSIM (denoise/metrics.h, masked),
// for kd, refined kd, ks, alpha, RGB and refined RGB. PSNR and SSIM also over the whole frame
// with everything but the object zero in both images ("_frame"): paper 1's RGB PSNR must be of
// that kind, since its RGB RMSE of 0.16-0.21 alone gives 13.6-15.9 dB against the 21.7-28.6 dB
// it reports, a gap that grows as the object's share of the frame shrinks (8 dB for the floor,
// 11-13 dB for the bunnies). The SSIM of those object-alone images is also averaged over the
// object's pixels alone ("ssim_object"): the object's box crop ("ssim") lets SSIM windows across
// the outline see the other objects and a silhouette a pixel off, so that a constant map within
// 0.01 of the truth scores 0.93, where paper 1 gives its yellow bunny's ks, 0.00 off, an SSIM of
// 1.00; the whole frame counts the empty windows. Parameter maps are compared as linear
// values; RGB as 8-bit-style sRGB-encoded values in [0, 1], as the images are viewed.
// Table 1 averages each object's per-frame values over the frames that show it, and then over
// the objects ("avg").
#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "core/image.h"
#include "io/rgbd_sequence.h"
#include "reflectance/material_maps.h"

namespace glint::reflectance {

struct GroundTruthMaps {
  ImageF kd, ks, alpha;         // 3, 3, 1 channels
  Image<std::int32_t> segment;  // object ids, 0 = background
};

// True when the sequence has glint's gt/ folders (written by `glint synth` / `glint render`).
bool has_ground_truth_maps(const io::RgbdSequence& sequence);
// The gt/ maps of frame i (glint sequences). Throws glint::Error naming a missing file.
GroundTruthMaps read_ground_truth_maps(const io::RgbdSequence& sequence, std::size_t i);
// gt/segment of frame i only.
Image<std::int32_t> read_ground_truth_segments(const io::RgbdSequence& sequence, std::size_t i);
// gt/<kind>/<frame>.exr of frame i (kind: kd, ks, alpha, depth, normal), checked to have
// `channels` channels. Throws glint::Error naming the file.
ImageF read_ground_truth_map(const io::RgbdSequence& sequence, std::size_t i,
                             const std::string& kind, int channels);

enum class Quantity { kd, kd_refined, ks, alpha, rgb, rgb_refined };
inline constexpr std::array<Quantity, 6> kQuantities{Quantity::kd,  Quantity::kd_refined,
                                                     Quantity::ks,  Quantity::alpha,
                                                     Quantity::rgb, Quantity::rgb_refined};
const char* quantity_name(Quantity quantity);

struct Scores {
  double l1 = 0, rmse = 0, psnr = 0, ssim = 0;
  double psnr_frame = 0, ssim_frame = 0;  // the whole frame, the object alone
  double ssim_object = 0;                 // the object alone, over the object's pixels
};

class MaterialEvaluation {
 public:
  // Objects with fewer covered pixels than this in a frame are not scored in it.
  explicit MaterialEvaluation(int min_object_pixels = 200) : min_pixels_(min_object_pixels) {}

  // Scores one frame; `input_rgb` is the frame's linear colour.
  void add_frame(int frame, const MaterialMaps& estimate, const GroundTruthMaps& truth,
                 const ImageF& input_rgb);

  // Per object and quantity: the mean over the frames that scored it.
  std::map<int, std::map<Quantity, Scores>> table() const;
  // The mean of table() over the objects.
  std::map<Quantity, Scores> average() const;
  // Per object, per frame: mean estimated and true red channel / value of kd, kd_refined, ks,
  // alpha and RGB over the object's covered pixels (Figure 4's curves).
  struct Sample {
    int frame = 0;
    double kd = 0, kd_refined = 0, ks = 0, alpha = 0, rgb = 0, rgb_refined = 0;
    double true_kd = 0, true_ks = 0, true_alpha = 0, true_rgb = 0;
    double coverage = 0;  // covered / object pixels
  };
  const std::map<int, std::vector<Sample>>& series() const { return series_; }

  nlohmann::json to_json() const;

 private:
  int min_pixels_;
  std::map<int, std::map<Quantity, std::vector<Scores>>> frames_;
  std::map<int, std::vector<Sample>> series_;
};

}  // namespace glint::reflectance
