#include "gltf/texture_atlas.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "core/error.h"
#include "core/parallel.h"

namespace glint::gltf {
namespace {

// Texel density below which a chart layout is refused (one texel per 10 cm).
constexpr float kMinTexelsPerMetre = 10;
// Texels outside a triangle whose centre is within this Chebyshev distance of it are baked too.
constexpr float kReach = 1.0f;

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Chart label: dominant axis of a normal, 2 k + (negative).
int axis_label(const Eigen::Vector3f& n) {
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  return 2 * k + (n[k] < 0);
}

struct Chart {
  int axis = 0;  // the projection drops this axis
  Eigen::Vector2f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  Eigen::Vector2f hi{std::numeric_limits<float>::lowest(), std::numeric_limits<float>::lowest()};
  int x = 0, y = 0;  // the packed rectangle's corner, texels
};

Eigen::Vector2f project(const Eigen::Vector3f& p, int axis) {
  return {p[(axis + 1) % 3], p[(axis + 2) % 3]};
}

// Rectangle side in texels: the projected extent, one texel so both ends sit on texel centres,
// and the gutter on both sides.
int rect_side(float extent_m, float density, int gutter) {
  return int(std::ceil(extent_m * density)) + 1 + 2 * gutter;
}

// Shelf packing of the charts (in `order`) at `density`; false when they overflow the atlas.
bool pack(std::vector<Chart>& charts, const std::vector<int>& order, float density,
          const AtlasParams& params) {
  int x = 0, y = 0, shelf = 0;
  for (const int c : order) {
    Chart& chart = charts[c];
    const int w = rect_side(chart.hi.x() - chart.lo.x(), density, params.gutter);
    const int h = rect_side(chart.hi.y() - chart.lo.y(), density, params.gutter);
    if (w > params.size) return false;
    if (x + w > params.size) x = 0, y += shelf, shelf = 0;
    if (y + h > params.size) return false;
    chart.x = x, chart.y = y;
    x += w;
    shelf = std::max(shelf, h);
  }
  return true;
}

}  // namespace

AtlasLayout layout_atlas(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles,
                         const std::vector<int>& triangle_group, const AtlasParams& params) {
  if (params.size < 8 || params.gutter < 1)
    throw Error("texture atlas", "size", "needs at least 8 texels per side and a gutter of 1");
  const int n = int(triangles.size());
  // Labels from the face's area-weighted vertex normals: a TSDF mesh's face normals are noisy
  // at the voxel scale, and labelling by them breaks a surface near 45 degrees into many tiny
  // charts, each paying its gutter.
  std::vector<Eigen::Vector3f> vertex_normal(vertices.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& f : triangles) {
    const Eigen::Vector3f normal =
        (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
    for (int k = 0; k < 3; ++k) vertex_normal[f[k]] += normal;
  }
  std::vector<int> label(n);
  for (int t = 0; t < n; ++t) {
    const Eigen::Vector3i& f = triangles[t];
    label[t] = axis_label(vertex_normal[f[0]].normalized() + vertex_normal[f[1]].normalized() +
                          vertex_normal[f[2]].normalized());
  }
  // Triangles sharing an edge, with one label and group, join a chart (union-find over the
  // sorted edge list).
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * std::size_t(n));
  for (int t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      edges.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b), t);
    }
  std::sort(edges.begin(), edges.end());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges[i].first != edges[i - 1].first) continue;
    const int s = edges[i - 1].second, t = edges[i].second;
    if (label[s] != label[t] || triangle_group[s] != triangle_group[t]) continue;
    const int rs = find_root(parent, s), rt = find_root(parent, t);
    if (rs != rt) parent[std::max(rs, rt)] = std::min(rs, rt);
  }
  AtlasLayout layout;
  layout.size = params.size;
  std::vector<int> chart_of(n), chart_index(n, -1);
  std::vector<Chart> charts;
  for (int t = 0; t < n; ++t) {
    const int root = find_root(parent, t);
    if (chart_index[root] < 0) {
      chart_index[root] = int(charts.size());
      charts.emplace_back().axis = label[t] / 2;
    }
    Chart& chart = charts[chart_of[t] = chart_index[root]];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f p = project(vertices[triangles[t][k]], chart.axis);
      chart.lo = chart.lo.cwiseMin(p);
      chart.hi = chart.hi.cwiseMax(p);
    }
  }
  layout.charts = int(charts.size());
  if (charts.empty()) return layout;

  // Tallest first; the densest layout that fits, from the bound that ignores gutters and waste.
  std::vector<int> order(charts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return charts[a].hi.y() - charts[a].lo.y() > charts[b].hi.y() - charts[b].lo.y();
  });
  double area = 0;
  for (const Chart& chart : charts)
    area += double(chart.hi.x() - chart.lo.x()) * (chart.hi.y() - chart.lo.y());
  float density = float(params.size / std::sqrt(std::max(area, 1e-12)));
  if (params.max_texels_per_metre > 0) density = std::min(density, params.max_texels_per_metre);
  while (!pack(charts, order, density, params)) {
    density *= 0.98f;
    if (density < kMinTexelsPerMetre)
      throw Error("texture atlas", "--texture-size",
                  std::to_string(charts.size()) + " charts do not fit " +
                      std::to_string(params.size) + " texels square at " +
                      std::to_string(int(kMinTexelsPerMetre)) +
                      " texels per metre; raise the size or lower --mesh-triangles");
  }
  layout.texels_per_metre = density;

  // One output vertex per (mesh vertex, chart).
  std::unordered_map<std::uint64_t, int> vertex_of;
  vertex_of.reserve(3 * std::size_t(n) / 2);
  layout.triangles.resize(n);
  const float scale = 1.0f / float(params.size);
  for (int t = 0; t < n; ++t) {
    const Chart& chart = charts[chart_of[t]];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = triangles[t][k];
      const auto [found, added] = vertex_of.try_emplace(
          std::uint64_t(v) << 32 | std::uint32_t(chart_of[t]), int(layout.source_vertex.size()));
      if (added) {
        const Eigen::Vector2f p = (project(vertices[v], chart.axis) - chart.lo) * density;
        const Eigen::Vector2f texel(chart.x + params.gutter + 0.5f + p.x(),
                                    chart.y + params.gutter + 0.5f + p.y());
        layout.source_vertex.push_back(v);
        layout.chart.push_back(std::uint32_t(chart_of[t]));
        layout.uv.push_back(texel * scale);
      }
      layout.triangles[t][k] = found->second;
    }
  }
  return layout;
}

ImageF bake_atlas(AtlasLayout& layout, const std::vector<Eigen::Vector3f>& vertices,
                  const SurfaceSampler& sample, const AtlasParams& params,
                  std::vector<std::uint8_t>* baked) {
  const int size = layout.size;
  ImageF image(size, size, 3, 0.0f);
  std::vector<int> owner(std::size_t(size) * size, -1);
  std::vector<float> reach(owner.size(), 0.0f);  // texels from the owner's triangle
  // Triangles per chart: charts own disjoint rectangles, so they bake in parallel.
  std::vector<std::vector<int>> chart_triangles(layout.charts);
  for (int t = 0; t < int(layout.triangles.size()); ++t)
    chart_triangles[layout.chart[layout.triangles[t][0]]].push_back(t);
  std::atomic<std::size_t> overlapping{0};
  parallel_for(chart_triangles.size(), [&](std::size_t c) {
    std::size_t overlaps = 0;
    for (const int t : chart_triangles[c]) {
      const Eigen::Vector3i& f = layout.triangles[t];
      Eigen::Vector2f q[3];
      for (int k = 0; k < 3; ++k) q[k] = layout.uv[f[k]] * float(size);
      const float area =
          (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
      if (std::abs(area) < 1e-12f) continue;
      const int x0 =
          std::max(0, int(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}) - kReach)));
      const int x1 =
          std::min(size - 1, int(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}) + kReach)));
      const int y0 =
          std::max(0, int(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}) - kReach)));
      const int y1 =
          std::min(size - 1, int(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}) + kReach)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const Eigen::Vector2f p(x + 0.5f, y + 0.5f);
          float b[3];
          for (int k = 0; k < 3; ++k) {
            const Eigen::Vector2f& a = q[(k + 1) % 3];
            const Eigen::Vector2f& e = q[(k + 2) % 3];
            b[k] = ((e - a).x() * (p - a).y() - (e - a).y() * (p - a).x()) / area;
          }
          float distance = 0;
          if (std::min({b[0], b[1], b[2]}) < 0) {
            // Outside: bilinear filtering of a point inside reads texels up to one texel away
            // (Chebyshev), so texels that close are baked from the nearest point of the edge.
            distance = std::numeric_limits<float>::max();
            for (int k = 0; k < 3; ++k) {
              const Eigen::Vector2f& a = q[k];
              const Eigen::Vector2f e = q[(k + 1) % 3] - a;
              const float s =
                  std::clamp((p - a).dot(e) / std::max(e.squaredNorm(), 1e-12f), 0.0f, 1.0f);
              const float d = (a + s * e - p).cwiseAbs().maxCoeff();
              if (d < distance) {
                distance = d;
                b[k] = 1 - s, b[(k + 1) % 3] = s, b[(k + 2) % 3] = 0;
              }
            }
            if (distance > kReach) continue;
          }
          const std::size_t texel = std::size_t(y) * size + x;
          if (owner[texel] >= 0) {
            // A texel on a shared edge is claimed twice legitimately; one well inside two
            // triangles is a fold.
            if (distance == 0 && reach[texel] == 0 && std::min({b[0], b[1], b[2]}) > 0.01f)
              ++overlaps;
            if (distance >= reach[texel]) continue;
          }
          owner[texel] = t;
          reach[texel] = distance;
          const Eigen::Vector3f point = b[0] * vertices[layout.source_vertex[f[0]]] +
                                        b[1] * vertices[layout.source_vertex[f[1]]] +
                                        b[2] * vertices[layout.source_vertex[f[2]]];
          const Eigen::Vector3f value = sample(point, t);
          for (int ch = 0; ch < 3; ++ch) image.at(x, y, ch) = value[ch];
        }
    }
    overlapping += overlaps;
  });
  layout.overlapping_texels = overlapping;

  std::vector<std::uint8_t> filled(owner.size());
  for (std::size_t i = 0; i < owner.size(); ++i) filled[i] = owner[i] >= 0;
  if (baked) *baked = filled;
  dilate_atlas(image, filled, params.gutter);
  return image;
}

void dilate_atlas(ImageF& image, std::vector<std::uint8_t>& filled, int passes) {
  const int width = image.width(), height = image.height(), channels = image.channels();
  if (channels > 4) throw Error("texture atlas", "", "dilation takes at most 4 channels");
  std::vector<std::uint8_t> next = filled;
  for (int pass = 0; pass < passes; ++pass) {
    parallel_for(std::size_t(height), [&](std::size_t row) {
      const int y = int(row);
      for (int x = 0; x < width; ++x) {
        if (filled[std::size_t(y) * width + x]) continue;
        float sum[4] = {0, 0, 0, 0};
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= width || v >= height || !filled[std::size_t(v) * width + u])
              continue;
            for (int ch = 0; ch < channels; ++ch) sum[ch] += image.at(u, v, ch);
            ++count;
          }
        if (count == 0) continue;
        for (int ch = 0; ch < channels; ++ch) image.at(x, y, ch) = sum[ch] / float(count);
        next[std::size_t(y) * width + x] = 1;
      }
    });
    filled = next;
  }
}

}  // namespace glint::gltf
