#pragma once
// Guided denoising of the kd atlas (the guided-denoising paper applied to the material maps;
// docs/reflectance.md "Export"). A voxel's refined kd is a mean over its observations (paper 1,
// eq. (7)), so it is noisy where the voxel was seen few times. The mesh is laid out again at the
// observation grid's density (one texel per voxel: the resolution the kd has), baked, and
// denoised by guided DIP, in overlapping tiles of at most 256^2, with a guidance map from the
// local noise level and the observation count. The correction (denoised - baked) is what the full
// atlas receives, so texels the guidance keeps keep their full-resolution detail.
#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/image.h"
#include "denoise/denoiser.h"
#include "gltf/texture_atlas.h"

namespace glint::gltf {

struct AlbedoDenoiseParams {
  denoise::DenoiserSettings settings{};  // guided DIP: the preset ("fast") and its overrides
  float voxel_m = 0.02f;                 // the observation grid's voxel size
  int full_observations = 30;            // m: a voxel's observation capacity
};

struct AlbedoDenoiseStats {
  int width = 0, height = 0;  // the denoised image (the low-resolution atlas, cropped)
  float texels_per_metre = 0;
  std::size_t texels = 0;             // baked texels
  double guided_fraction = 0;         // baked texels whose guidance is below 1
  int tiles = 0, tiles_denoised = 0;  // tiles of at most 256^2; those with a guided texel
  double seconds = 0;                 // the denoiser's, summed over the tiles
  int iterations = 0;                 // per tile
  std::string device;
  nlohmann::json to_json() const;
};

// The guidance map, eq. (13), of n_eff = n m / max(c, 1) per baked texel: n the local noise
// level of `kd` (SVD, 7x7 patches, eqs. (7)-(12)), c the texel's observation count (channel 0
// of `observations`): a mean of c observations has m / c times the variance of one of m. Only
// baked texels (`baked`, row-major) enter the histogram; the others get 1.
ImageF albedo_guidance(const ImageF& kd, const ImageF& observations,
                       const std::vector<std::uint8_t>& baked, int full_observations);

// The correction field of one mesh: built (layout, bake, guided DIP) on construction.
class AlbedoCorrection {
 public:
  // `kd` and `observations` give a surface point's kd and observation count (channel 0) on
  // triangle t of `triangles` (grouped by `triangle_group`, as layout_atlas() takes them).
  // Throws glint::Error when the denoiser fails (e.g. its plugin is missing).
  AlbedoCorrection(const std::vector<Eigen::Vector3f>& vertices,
                   const std::vector<Eigen::Vector3i>& triangles,
                   const std::vector<int>& triangle_group, const SurfaceSampler& kd,
                   const SurfaceSampler& observations, const AlbedoDenoiseParams& params);

  // Denoised minus baked kd at surface point p of triangle t (bilinear in the denoised atlas).
  Eigen::Vector3f operator()(const Eigen::Vector3f& p, int t) const;
  const AlbedoDenoiseStats& stats() const { return stats_; }

 private:
  const std::vector<Eigen::Vector3f>& vertices_;
  AtlasLayout layout_;
  ImageF correction_;  // the layout's size, 3 channels, 0 outside the baked texels
  AlbedoDenoiseStats stats_;
};

}  // namespace glint::gltf
