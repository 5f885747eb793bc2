#pragma once
// A texture atlas for a triangle mesh: charts, packing, baking.
// Charts: edge-connected triangles of one group (the segment) whose normals (the mean of their
// vertices' area-weighted normals) share their dominant axis (one of ±x, ±y, ±z), projected
// orthographically onto the plane of the other two axes, so every chart has the same texel
// density (texels per metre) along its plane and a triangle is at most sqrt(3) times denser
// across its slope. Packing: the charts' bounding rectangles, each with a gutter, on shelves,
// tallest first, at the largest density (searched downwards in 2 % steps) that fits the square
// atlas. Seams: every texel whose centre lies in a triangle or within one texel (Chebyshev) of
// it is baked from the nearest surface point of that triangle (the inside one wins), so bilinear
// filtering anywhere in a chart reads only texels of its own chart, baked; `gutter` dilation
// passes then fill the empty texels next to baked ones as a margin. Use no mipmaps: coarser
// levels would mix charts.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/image.h"

namespace glint::gltf {

struct AtlasParams {
  int size = 2048;  // texels per side
  int gutter = 1;   // texels around each chart's bounding rectangle (>= 1)
  // The layout's density is at most this (texels per metre; 0: as dense as `size` allows).
  float max_texels_per_metre = 0;
};

struct AtlasLayout {
  int size = 0;
  float texels_per_metre = 0;
  int charts = 0;
  // Output vertices (a mesh vertex is split where charts meet): the mesh vertex each copies,
  // its chart and its texture coordinate (glTF's: (0, 0) the image's top-left corner).
  std::vector<std::uint32_t> source_vertex;
  std::vector<std::uint32_t> chart;
  std::vector<Eigen::Vector2f> uv;
  // The mesh's triangles in the same order, over the output vertices.
  std::vector<Eigen::Vector3i> triangles;
  // Texels claimed by two triangles of one chart (a fold the projection overlaps); such texels
  // show one of the two surfaces.
  std::size_t overlapping_texels = 0;
};

// Charts `triangles` over `vertices` (triangle t belongs to group triangle_group[t]) and packs
// them. Throws glint::Error when even one texel per 10 cm leaves the charts no room (too many
// charts for `size`).
AtlasLayout layout_atlas(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles,
                         const std::vector<int>& triangle_group, const AtlasParams& params = {});

// The value at a surface point of triangle t (thread-safe; called in parallel).
using SurfaceSampler = std::function<Eigen::Vector3f(const Eigen::Vector3f& point, int triangle)>;

// The atlas image (3 channels, as the sampler returns them, 0 where no chart is): every texel
// whose centre lies in a triangle, or within one texel of it, gets sample(nearest point of the
// triangle); then `params.gutter` dilation passes give each empty texel next to baked ones their
// mean (8-neighbourhood). Also fills `layout.overlapping_texels` and, when given, `baked`: 1 for
// the texels baked from a triangle, 0 for the gutter and empty ones (size² entries, row-major).
ImageF bake_atlas(AtlasLayout& layout, const std::vector<Eigen::Vector3f>& vertices,
                  const SurfaceSampler& sample, const AtlasParams& params = {},
                  std::vector<std::uint8_t>* baked = nullptr);

// `passes` dilation passes over `image`: each fills the empty texels (filled[i] == 0) beside
// filled ones with their mean (8-neighbourhood), reading the previous pass only, and marks them
// filled. At most 4 channels.
void dilate_atlas(ImageF& image, std::vector<std::uint8_t>& filled, int passes);

}  // namespace glint::gltf
