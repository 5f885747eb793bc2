#include "reflectance/depth_segmentation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/parallel.h"

namespace glint::reflectance {
namespace {

using Eigen::Vector3f;

// Vertex and normal maps; a pixel without depth (or without a normal) has z = 0.
struct Geometry {
  int width, height;
  std::vector<Vector3f> vertex, normal;
  bool valid(int x, int y) const {
    return x >= 0 && y >= 0 && x < width && y < height && vertex[y * width + x].z() > 0;
  }
};

Geometry vertex_and_normal_maps(const ImageF& depth, const Intrinsics& k, int step) {
  Geometry g{depth.width(), depth.height(), {}, {}};
  g.vertex.assign(depth.pixel_count(), Vector3f::Zero());
  g.normal.assign(depth.pixel_count(), Vector3f::Zero());
  parallel_for(std::size_t(g.height), [&](std::size_t y) {
    for (int x = 0; x < g.width; ++x) {
      const float z = depth.at(x, int(y), 0);
      if (std::isfinite(z) && z > 0)
        g.vertex[y * g.width + x] = k.back_project(x, y, z).cast<float>();
    }
  });
  parallel_for(std::size_t(g.height), [&](std::size_t yy) {
    const int y = int(yy);
    for (int x = 0; x < g.width; ++x) {
      if (!g.valid(x, y) || !g.valid(x - step, y) || !g.valid(x + step, y) ||
          !g.valid(x, y - step) || !g.valid(x, y + step))
        continue;
      const Vector3f dx = g.vertex[y * g.width + x + step] - g.vertex[y * g.width + x - step];
      const Vector3f dy = g.vertex[(y + step) * g.width + x] - g.vertex[(y - step) * g.width + x];
      Vector3f n = dy.cross(dx);  // x right, y down, z forward: faces the camera (-z)
      if (n.squaredNorm() <= 0) continue;
      n.normalize();
      if (n.dot(g.vertex[y * g.width + x]) > 0) n = -n;
      g.normal[y * g.width + x] = n;
    }
  });
  return g;
}

// Union-find over pixel indices for the connected components.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

DepthSegmentation segment_depth(const ImageF& depth, const Intrinsics& intrinsics,
                                const DepthSegmentationParams& p) {
  const Geometry g = vertex_and_normal_maps(depth, intrinsics, p.normal_step_px);
  const int w = g.width, h = g.height;
  DepthSegmentation out;
  out.edges = Image<std::uint8_t>(w, h, 1, 1);
  // Non-edge test per pixel (eqs of Tateno et al. 2016, thresholds after their public code).
  parallel_for(std::size_t(h), [&](std::size_t yy) {
    const int y = int(yy);
    const int s = p.neighbour_step_px;
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const Vector3f& v = g.vertex[i];
      const Vector3f& n = g.normal[i];
      if (v.z() <= 0 || n.isZero()) continue;  // stays an edge
      float convexity = 1, distance = 0;
      bool discontinuity = false;
      for (int dy = -s; dy <= s; dy += s)
        for (int dx = -s; dx <= s; dx += s) {
          if ((dx == 0 && dy == 0) || !g.valid(x + dx, y + dy)) continue;
          const int j = (y + dy) * w + x + dx;
          const float along_normal = (g.vertex[j] - v).dot(n);
          if (along_normal > p.convexity_epsilon_m && !g.normal[j].isZero())
            convexity = std::min(convexity, n.dot(g.normal[j]));
          distance = std::max(distance, std::abs(along_normal));
          discontinuity |= std::abs(g.vertex[j].z() - v.z()) > p.discontinuity_ratio * v.z();
        }
      const bool edge = convexity < p.min_convexity ||
                        distance > p.distance_k * kinect_axial_noise_m(v.z()) || discontinuity;
      out.edges.at(x, y, 0) = edge ? 1 : 0;
    }
  });

  DisjointSets sets(w * h);
  const std::uint8_t* edge = out.edges.plane(0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (edge[i]) continue;
      if (x > 0 && !edge[i - 1]) sets.unite(i, i - 1);
      if (y > 0 && !edge[i - w]) sets.unite(i, i - w);
    }
  std::vector<int> size(w * h, 0);
  for (int i = 0; i < w * h; ++i)
    if (!edge[i]) ++size[sets.find(i)];
  std::vector<int> label_of_root(w * h, 0);
  out.labels = Image<std::int32_t>(w, h, 1, 0);
  std::int32_t* labels = out.labels.plane(0);
  for (int i = 0; i < w * h; ++i) {
    if (edge[i]) continue;
    const int root = sets.find(i);
    if (size[root] < p.min_segment_px) continue;
    if (label_of_root[root] == 0) label_of_root[root] = ++out.segment_count;
    labels[i] = label_of_root[root];
  }

  // Edge pixels with depth take the label of the nearest labelled pixel in the window.
  const std::vector<std::int32_t> component(labels, labels + w * h);
  const int r = p.fill_radius_px;
  parallel_for(std::size_t(h), [&](std::size_t yy) {
    const int y = int(yy);
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (component[i] != 0 || g.vertex[i].z() <= 0) continue;
      int best = 0, best_distance = r * r + 1;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy2 = y + dy;
          if (xx < 0 || yy2 < 0 || xx >= w || yy2 >= h) continue;
          const int label = component[yy2 * w + xx];
          const int d2 = dx * dx + dy * dy;
          // Only across small depth gaps: a label must not leak onto another surface.
          if (label && d2 < best_distance &&
              std::abs(g.vertex[yy2 * w + xx].z() - g.vertex[i].z()) <
                  p.discontinuity_ratio * g.vertex[i].z()) {
            best = label;
            best_distance = d2;
          }
        }
      labels[i] = best;
    }
  });
  return out;
}

}  // namespace glint::reflectance
