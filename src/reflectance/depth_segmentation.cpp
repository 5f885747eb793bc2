#include "reflectance/depth_segmentation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "core/parallel.h"

namespace glint::reflectance {
namespace {

using Eigen::Vector3f;

// The 8 neighbours v_i of the concavity and distance tests, in units of neighbour_step_px.
constexpr int kNeighbourX[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kNeighbourY[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

// Read-only view of the vertex and normal planes.
struct Maps {
  const float *vx, *vy, *vz, *nx, *ny, *nz;
  int width, height;
  Maps(const std::vector<float> (&vertex)[3], const std::vector<float> (&normal)[3], int w, int h)
      : vx(vertex[0].data()),
        vy(vertex[1].data()),
        vz(vertex[2].data()),
        nx(normal[0].data()),
        ny(normal[1].data()),
        nz(normal[2].data()),
        width(w),
        height(h) {}
  Vector3f vertex(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
};

// Four pixels of a row as GCC vector lanes (one SSE register: the build's baseline).
constexpr int kLanes = 4;
using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));

template <class T>
T load(const float* p) {
  if constexpr (std::is_same_v<T, float>) {
    return *p;
  } else {
    T v;
    std::memcpy(&v, p, sizeof(v));
    return v;
  }
}

// Tateno et al.'s edge test (see the header) of pixel i = (x, y), or of the kLanes pixels from i
// on when T is Floats: one branch-free body for both, so that the rows' interiors, where no
// neighbour can leave the image, run kLanes pixels at a time. kCheckBounds (scalar only) skips
// neighbours outside the image.
template <class T, bool kCheckBounds = false>
[[gnu::always_inline]] inline auto is_edge(const Maps& m, int x, int y, std::size_t i,
                                           const DepthSegmentationParams& p) {
  using Mask = decltype(T{} > T{});
  const T vx = load<T>(m.vx + i), vy = load<T>(m.vy + i), z = load<T>(m.vz + i);
  const T nx = load<T>(m.nx + i), ny = load<T>(m.ny + i), nz = load<T>(m.nz + i);
  const T noise = kinect_axial_noise_m(z);
  const T scaled_noise = p.convexity_noise_k * noise;
  const T epsilon =
      scaled_noise > p.convexity_epsilon_m ? scaled_noise : T{} + p.convexity_epsilon_m;
  T convexity = T{} + 1.0f, distance = T{};
  Mask discontinuity = Mask{};
  for (int k = 0; k < 8; ++k) {
    const int dx = kNeighbourX[k] * p.neighbour_step_px, dy = kNeighbourY[k] * p.neighbour_step_px;
    if constexpr (kCheckBounds)
      if (x + dx < 0 || y + dy < 0 || x + dx >= m.width || y + dy >= m.height) continue;
    const std::size_t j = i + std::ptrdiff_t(dy) * m.width + dx;
    const T jx = load<T>(m.vx + j), jy = load<T>(m.vy + j), jz = load<T>(m.vz + j);
    const T jnx = load<T>(m.nx + j), jny = load<T>(m.ny + j), jnz = load<T>(m.nz + j);
    const Mask valid = jz > 0;
    const T along_normal = (jx - vx) * nx + (jy - vy) * ny + (jz - z) * nz;
    const T cosine = nx * jnx + ny * jny + nz * jnz;
    const Mask convex_candidate =
        valid & (along_normal > epsilon) & ((jnx != 0) | (jny != 0) | (jnz != 0));
    convexity = convex_candidate & (cosine < convexity) ? cosine : convexity;
    const T magnitude = along_normal < 0 ? -along_normal : along_normal;
    distance = valid & (distance < magnitude) ? magnitude : distance;
    const T depth_step = jz - z < 0 ? z - jz : jz - z;
    discontinuity = discontinuity | (valid & (depth_step > p.discontinuity_ratio * z));
  }
  // No depth or no normal: an edge.
  return (z <= 0) | ((nx == 0) & (ny == 0) & (nz == 0)) | (convexity < p.min_convexity) |
         (distance > p.distance_k * noise) | discontinuity;
}

}  // namespace

DepthSegmenter::DepthSegmenter(const DepthSegmentationParams& params) : params_(params) {
  // The edge fill's window in the order it is searched: nearest first, ties in scan order.
  const int r = params_.fill_radius_px;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= r * r) fill_window_.push_back({dx, dy});
  std::stable_sort(fill_window_.begin(), fill_window_.end(), [](const Offset& a, const Offset& b) {
    return a.dx * a.dx + a.dy * a.dy < b.dx * b.dx + b.dy * b.dy;
  });
}

void DepthSegmenter::compute_vertices_and_normals(const ImageF& depth, const Intrinsics& k) {
  const int w = width_, h = height_, s = params_.normal_step_px;
  for (std::vector<float>* planes : {vertex_, normal_})
    for (int c = 0; c < 3; ++c) planes[c].resize(std::size_t(w) * h);
  float *vx = vertex_[0].data(), *vy = vertex_[1].data(), *vz = vertex_[2].data();
  float *nx = normal_[0].data(), *ny = normal_[1].data(), *nz = normal_[2].data();
  parallel_for(std::size_t(h), [&](std::size_t row) {
    const int y = int(row);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row * w + x;
      const float z = depth.at(x, y, 0);
      const Vector3f v = std::isfinite(z) && z > 0 ? Vector3f(k.back_project(x, y, z).cast<float>())
                                                   : Vector3f::Zero();
      vx[i] = v.x(), vy[i] = v.y(), vz[i] = v.z();
    }
  });
  const Maps m(vertex_, normal_, w, h);
  parallel_for(std::size_t(h), [&](std::size_t row) {
    const int y = int(row);
    std::fill_n(nx + row * w, w, 0.0f);
    std::fill_n(ny + row * w, w, 0.0f);
    std::fill_n(nz + row * w, w, 0.0f);
    if (y < s || y >= h - s) return;
    const std::size_t up = std::size_t(s) * w;
    for (int x = s; x < w - s; ++x) {
      const std::size_t i = row * w + x;
      if (!(vz[i] > 0 && vz[i - s] > 0 && vz[i + s] > 0 && vz[i - up] > 0 && vz[i + up] > 0))
        continue;
      const Vector3f dx = m.vertex(i + s) - m.vertex(i - s);
      const Vector3f dy = m.vertex(i + up) - m.vertex(i - up);
      Vector3f n = dy.cross(dx);  // x right, y down, z forward: faces the camera (-z)
      if (n.squaredNorm() <= 0) continue;
      n.normalize();
      if (n.dot(m.vertex(i)) > 0) n = -n;
      nx[i] = n.x(), ny[i] = n.y(), nz[i] = n.z();
    }
  });
}

void DepthSegmenter::detect_edges() {
  const int w = width_, h = height_, s = params_.neighbour_step_px;
  const Maps m(vertex_, normal_, w, h);
  std::uint8_t* edge = result_.edges.plane(0);
  const DepthSegmentationParams& p = params_;
  parallel_for(std::size_t(h), [&](std::size_t row) {
    const int y = int(row);
    std::uint8_t* out = edge + row * w;
    const bool inner_row = y >= s && y < h - s;
    const int left = inner_row ? std::min(s, w) : w, right = std::max(left, w - s);
    int x = 0;
    for (; x < left; ++x) out[x] = is_edge<float, true>(m, x, y, row * w + x, p);
    for (; x + kLanes <= right; x += kLanes) {
      const auto lanes = is_edge<Floats>(m, x, y, row * w + x, p);
      for (int lane = 0; lane < kLanes; ++lane) out[x + lane] = lanes[lane] != 0;
    }
    for (; x < right; ++x) out[x] = is_edge<float>(m, x, y, row * w + x, p);
    for (; x < w; ++x) out[x] = is_edge<float, true>(m, x, y, row * w + x, p);
  });
}

int DepthSegmenter::find_root(int run) {
  while (run_parent_[run] != run) run = run_parent_[run] = run_parent_[run_parent_[run]];
  return run;
}

void DepthSegmenter::label_components() {
  // Runs of non-edge pixels, united with the runs they touch in the row above (4-connected
  // components). A root is its component's first run, so labels are handed out in the raster
  // order of the components' first pixels.
  const int w = width_, h = height_;
  const std::uint8_t* edge = result_.edges.plane(0);
  runs_.clear();
  run_parent_.clear();
  std::size_t previous_row = 0;
  for (int y = 0; y < h; ++y) {
    const std::size_t this_row = runs_.size();
    const std::uint8_t* row = edge + std::size_t(y) * w;
    for (int x = 0; x < w;) {
      while (x < w && row[x]) ++x;
      if (x == w) break;
      const int begin = x;
      while (x < w && !row[x]) ++x;
      run_parent_.push_back(int(runs_.size()));
      runs_.push_back({y, begin, x});
    }
    std::size_t above = previous_row;
    for (std::size_t r = this_row; r < runs_.size(); ++r) {
      while (above < this_row && runs_[above].end <= runs_[r].begin) ++above;
      for (std::size_t q = above; q < this_row && runs_[q].begin < runs_[r].end; ++q) {
        const int a = find_root(int(q)), b = find_root(int(r));
        if (a != b) run_parent_[std::max(a, b)] = std::min(a, b);
      }
    }
    previous_row = this_row;
  }

  component_size_.assign(runs_.size(), 0);
  for (std::size_t r = 0; r < runs_.size(); ++r)
    component_size_[find_root(int(r))] += runs_[r].end - runs_[r].begin;
  label_of_root_.assign(runs_.size(), 0);
  result_.segment_count = 0;
  std::int32_t* labels = result_.labels.plane(0);
  std::fill_n(labels, std::size_t(w) * h, 0);
  for (std::size_t r = 0; r < runs_.size(); ++r) {
    const int root = find_root(int(r));
    if (component_size_[root] < params_.min_segment_px) continue;
    if (label_of_root_[root] == 0) label_of_root_[root] = ++result_.segment_count;
    std::fill(labels + std::size_t(runs_[r].row) * w + runs_[r].begin,
              labels + std::size_t(runs_[r].row) * w + runs_[r].end, label_of_root_[root]);
  }
}

void DepthSegmenter::fill_edges() {
  // Pixels with depth but no label take the label of the nearest labelled pixel in the window,
  // only across small depth gaps: a label must not leak onto another surface.
  const int w = width_, h = height_;
  std::int32_t* labels = result_.labels.plane(0);
  component_.assign(labels, labels + std::size_t(w) * h);
  const float* vz = vertex_[2].data();
  parallel_for(std::size_t(h), [&](std::size_t row) {
    const int y = int(row);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row * w + x;
      if (component_[i] != 0 || vz[i] <= 0) continue;
      for (const Offset& o : fill_window_) {
        const int xx = x + o.dx, yy = y + o.dy;
        if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
        const std::size_t j = std::size_t(yy) * w + xx;
        if (component_[j] && std::abs(vz[j] - vz[i]) < params_.discontinuity_ratio * vz[i]) {
          labels[i] = component_[j];
          break;
        }
      }
    }
  });
}

const DepthSegmentation& DepthSegmenter::segment(const ImageF& depth,
                                                 const Intrinsics& intrinsics) {
  width_ = depth.width();
  height_ = depth.height();
  result_.edges.ensure_size(width_, height_, 1);
  result_.labels.ensure_size(width_, height_, 1);
  compute_vertices_and_normals(depth, intrinsics);
  detect_edges();
  label_components();
  fill_edges();
  return result_;
}

DepthSegmentation segment_depth(const ImageF& depth, const Intrinsics& intrinsics,
                                const DepthSegmentationParams& params) {
  DepthSegmenter segmenter(params);
  return segmenter.segment(depth, intrinsics);
}

}  // namespace glint::reflectance
