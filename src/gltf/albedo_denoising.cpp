#include "gltf/albedo_denoising.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "denoise/noise_level.h"

namespace glint::gltf {
namespace {

// Dilation passes that carry the charts' values into the empty texels around them, so that the
// noise level's 7x7 patches and the U-Net's convolutions at a chart's border see a continuation
// of the chart rather than a step to zero.
constexpr int kFillPasses = 8;
// Guided DIP's fast configuration was sized on 256x256 images. Its cost per pixel rises about
// tenfold from there to an 816x721 image (0.86 us per pixel and step at 256^2 and 384^2, 8.5 at
// 816x721 on 2 cores: the activations leave the caches), so larger atlases are denoised in
// tiles of this side, overlapping by kTileOverlap texels and blended linearly there.
constexpr int kTile = 256;
constexpr int kTileOverlap = 32;
// Retries of the low-resolution layout, each 20 % larger, when the first size is too small for
// the charts at the observation grid's density.
constexpr int kLayoutAttempts = 12;

float total_area(const std::vector<Eigen::Vector3f>& vertices,
                 const std::vector<Eigen::Vector3i>& triangles) {
  double area = 0;
  for (const Eigen::Vector3i& f : triangles)
    area += 0.5 * (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]).norm();
  return float(area);
}

// The layout at `density` texels per metre in the smallest square (of the sizes tried) that
// holds it.
AtlasLayout layout_at_density(const std::vector<Eigen::Vector3f>& vertices,
                              const std::vector<Eigen::Vector3i>& triangles,
                              const std::vector<int>& triangle_group, float density) {
  // Charts waste about a third of their rectangles and add a gutter ring each.
  int size = int(std::ceil(std::sqrt(1.5f * total_area(vertices, triangles)) * density));
  size = std::max(64, (size + 15) / 16 * 16);
  for (int attempt = 0; attempt < kLayoutAttempts; ++attempt) {
    AtlasParams params{.size = size, .gutter = 1, .max_texels_per_metre = density};
    try {
      AtlasLayout layout = layout_atlas(vertices, triangles, triangle_group, params);
      if (layout.texels_per_metre >= 0.999f * density) return layout;
    } catch (const Error&) {
      // Too many charts for this size at any density: try a larger one.
    }
    size = (int(size * 1.2f) + 15) / 16 * 16;
  }
  throw Error("albedo denoising", "atlas",
              "the charts do not fit " + std::to_string(size) + " texels square at " +
                  std::to_string(density) + " texels per metre");
}

struct Box {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // inclusive-exclusive
};

Box filled_box(const std::vector<std::uint8_t>& filled, int size) {
  Box box{size, size, 0, 0};
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (filled[std::size_t(y) * size + x]) {
        box.x0 = std::min(box.x0, x), box.x1 = std::max(box.x1, x + 1);
        box.y0 = std::min(box.y0, y), box.y1 = std::max(box.y1, y + 1);
      }
  if (box.x1 <= box.x0) return {0, 0, 1, 1};
  return box;
}

ImageF crop(const ImageF& image, const Box& box) {
  ImageF out(box.x1 - box.x0, box.y1 - box.y0, image.channels());
  for (int c = 0; c < image.channels(); ++c)
    for (int y = box.y0; y < box.y1; ++y)
      for (int x = box.x0; x < box.x1; ++x) out.at(x - box.x0, y - box.y0, c) = image.at(x, y, c);
  return out;
}

std::vector<std::uint8_t> crop(const std::vector<std::uint8_t>& mask, int size, const Box& box) {
  std::vector<std::uint8_t> out;
  out.reserve(std::size_t(box.x1 - box.x0) * (box.y1 - box.y0));
  for (int y = box.y0; y < box.y1; ++y)
    for (int x = box.x0; x < box.x1; ++x) out.push_back(mask[std::size_t(y) * size + x]);
  return out;
}

// Tile origins along an axis of `length` texels: tiles of kTile (or the whole axis), evenly
// spread, neighbours overlapping by at least kTileOverlap.
std::vector<int> tile_origins(int length) {
  if (length <= kTile) return {0};
  const int tiles = (length - kTileOverlap + kTile - kTileOverlap - 1) / (kTile - kTileOverlap);
  std::vector<int> origins;
  for (int i = 0; i < tiles; ++i)
    origins.push_back(int(std::lround(double(i) * (length - kTile) / (tiles - 1))));
  return origins;
}

// A tile's blending weight along one axis at `position`: a ramp over the overlap on each side
// that has a neighbour, 1 elsewhere.
float ramp(int position, int origin, int size, int length) {
  float weight = 1;
  if (origin > 0) weight = std::min(weight, (float(position - origin) + 0.5f) / kTileOverlap);
  if (origin + size < length)
    weight = std::min(weight, (float(origin + size - position) - 0.5f) / kTileOverlap);
  return weight;
}

// Guided DIP over `noisy` in overlapping tiles; a tile with no guided texel (`guidance` below
// 1 where `baked`) keeps its input.
ImageF denoise_tiled(const ImageF& noisy, const ImageF& guidance,
                     const std::vector<std::uint8_t>& baked,
                     const denoise::DenoiserSettings& settings, AlbedoDenoiseStats& stats) {
  const int width = noisy.width(), height = noisy.height();
  ImageF sum(width, height, 3, 0.0f), weights(width, height, 1, 0.0f);
  const std::vector<int> xs = tile_origins(width), ys = tile_origins(height);
  for (const int y0 : ys)
    for (const int x0 : xs) {
      const Box box{x0, y0, std::min(width, x0 + kTile), std::min(height, y0 + kTile)};
      bool guided = false;
      for (int y = box.y0; y < box.y1 && !guided; ++y)
        for (int x = box.x0; x < box.x1 && !guided; ++x)
          guided = baked[std::size_t(y) * width + x] && guidance.at(x, y, 0) < 1.0f;
      ImageF tile = crop(noisy, box);
      if (guided) {
        const ImageF tile_guidance = crop(guidance, box);
        const denoise::DenoiseRun run =
            denoise::run_denoiser("guided-dip", settings, tile, &tile_guidance);
        tile = run.result;
        stats.seconds += run.stats.seconds;
        stats.iterations = run.stats.iterations;
        stats.device = run.stats.device;
        ++stats.tiles_denoised;
      }
      ++stats.tiles;
      for (int y = box.y0; y < box.y1; ++y)
        for (int x = box.x0; x < box.x1; ++x) {
          const float w =
              ramp(x, box.x0, box.x1 - box.x0, width) * ramp(y, box.y0, box.y1 - box.y0, height);
          weights.at(x, y, 0) += w;
          for (int c = 0; c < 3; ++c) sum.at(x, y, c) += w * tile.at(x - box.x0, y - box.y0, c);
        }
    }
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) sum.at(x, y, c) /= weights.at(x, y, 0);
  return sum;
}

// Barycentric coordinates of p (on or near triangle a, b, c) in that triangle.
Eigen::Vector3f barycentric(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                            const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f e0 = b - a, e1 = c - a, d = p - a;
  const float d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const float d20 = d.dot(e0), d21 = d.dot(e1);
  const float det = d00 * d11 - d01 * d01;
  if (std::abs(det) < 1e-20f) return {1, 0, 0};
  const float v = (d11 * d20 - d01 * d21) / det, w = (d00 * d21 - d01 * d20) / det;
  return {1 - v - w, v, w};
}

}  // namespace

nlohmann::json AlbedoDenoiseStats::to_json() const {
  return {{"method", "guided-dip"},   {"width", width},
          {"height", height},         {"texels_per_metre", texels_per_metre},
          {"baked_texels", texels},   {"guided_fraction", guided_fraction},
          {"tiles", tiles},           {"tiles_denoised", tiles_denoised},
          {"iterations", iterations}, {"device", device},
          {"seconds", seconds}};
}

ImageF albedo_guidance(const ImageF& kd, const ImageF& observations,
                       const std::vector<std::uint8_t>& baked, int full_observations) {
  const ImageF noise = denoise::noise_level(kd, {.method = denoise::NoiseMethod::svd, .patch = 7});
  std::vector<std::size_t> texels;
  for (std::size_t i = 0; i < baked.size(); ++i)
    if (baked[i]) texels.push_back(i);
  ImageF guidance(kd.width(), kd.height(), 1, 1.0f);
  if (texels.empty()) return guidance;
  // eq. (13) over the baked texels only: a row of their effective noise levels.
  ImageF effective(int(texels.size()), 1, 1);
  for (std::size_t k = 0; k < texels.size(); ++k) {
    const std::size_t i = texels[k];
    const float count = std::max(observations.values()[i], 1.0f);
    effective.values()[k] = noise.values()[i] * float(full_observations) / count;
  }
  const denoise::Guidance remapped = denoise::guidance_from_noise(effective);
  for (std::size_t k = 0; k < texels.size(); ++k)
    guidance.values()[texels[k]] = remapped.map.values()[k];
  return guidance;
}

AlbedoCorrection::AlbedoCorrection(const std::vector<Eigen::Vector3f>& vertices,
                                   const std::vector<Eigen::Vector3i>& triangles,
                                   const std::vector<int>& triangle_group, const SurfaceSampler& kd,
                                   const SurfaceSampler& observations,
                                   const AlbedoDenoiseParams& params)
    : vertices_(vertices) {
  const float density = 1.0f / params.voxel_m;
  layout_ = layout_at_density(vertices, triangles, triangle_group, density);
  const int size = layout_.size;
  const AtlasParams bake_params{.size = size, .gutter = 1};
  std::vector<std::uint8_t> baked;
  ImageF albedo = bake_atlas(layout_, vertices, kd, bake_params, &baked);
  const ImageF counts = bake_atlas(layout_, vertices, observations, bake_params);

  std::vector<std::uint8_t> filled = baked;
  dilate_atlas(albedo, filled, 1 + kFillPasses);
  const Box box = filled_box(filled, size);
  const ImageF noisy = crop(albedo, box);
  const std::vector<std::uint8_t> baked_crop = crop(baked, size, box);
  const ImageF guidance =
      albedo_guidance(noisy, crop(counts, box), baked_crop, params.full_observations);

  stats_.width = noisy.width();
  stats_.height = noisy.height();
  stats_.texels_per_metre = layout_.texels_per_metre;
  for (std::size_t i = 0; i < baked_crop.size(); ++i) {
    if (!baked_crop[i]) continue;
    ++stats_.texels;
    stats_.guided_fraction += guidance.values()[i] < 1.0f;
  }
  if (stats_.texels > 0) stats_.guided_fraction /= double(stats_.texels);
  log().info("kd atlas denoising: {}x{} texels at {:.0f} texels/m, {:.0f} % of them guided",
             noisy.width(), noisy.height(), layout_.texels_per_metre, 100 * stats_.guided_fraction);
  const ImageF denoised = denoise_tiled(noisy, guidance, baked_crop, params.settings, stats_);

  correction_ = ImageF(size, size, 3, 0.0f);
  for (int c = 0; c < 3; ++c)
    for (int y = box.y0; y < box.y1; ++y)
      for (int x = box.x0; x < box.x1; ++x)
        if (baked[std::size_t(y) * size + x])
          correction_.at(x, y, c) =
              denoised.at(x - box.x0, y - box.y0, c) - noisy.at(x - box.x0, y - box.y0, c);
}

Eigen::Vector3f AlbedoCorrection::operator()(const Eigen::Vector3f& p, int t) const {
  const Eigen::Vector3i& f = layout_.triangles[t];
  const Eigen::Vector3f b =
      barycentric(p, vertices_[layout_.source_vertex[f[0]]], vertices_[layout_.source_vertex[f[1]]],
                  vertices_[layout_.source_vertex[f[2]]]);
  const int size = layout_.size;
  const Eigen::Vector2f texel =
      (b[0] * layout_.uv[f[0]] + b[1] * layout_.uv[f[1]] + b[2] * layout_.uv[f[2]]) * float(size) -
      Eigen::Vector2f::Constant(0.5f);
  const int x0 = std::clamp(int(std::floor(texel.x())), 0, size - 1);
  const int y0 = std::clamp(int(std::floor(texel.y())), 0, size - 1);
  const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
  const float fx = std::clamp(texel.x() - float(x0), 0.0f, 1.0f);
  const float fy = std::clamp(texel.y() - float(y0), 0.0f, 1.0f);
  Eigen::Vector3f value;
  for (int c = 0; c < 3; ++c)
    value[c] = (1 - fy) * ((1 - fx) * correction_.at(x0, y0, c) + fx * correction_.at(x1, y0, c)) +
               fy * ((1 - fx) * correction_.at(x0, y1, c) + fx * correction_.at(x1, y1, c));
  return value;
}

}  // namespace glint::gltf
