#include "reflectance/material_maps.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"
#include "render/ward.h"

namespace glint::reflectance {

Eigen::Vector3f shade_ward(const render::WardMaterial& material, const Eigen::Vector3f& p,
                           const Eigen::Vector3f& n, const Eigen::Vector3f& eye,
                           const std::vector<render::PointLight>& lights) {
  const Eigen::Vector3f wo = (eye - p).normalized();
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
  for (const render::PointLight& light : lights) {
    const Eigen::Vector3f to_light = light.position.cast<float>() - p;
    const float distance2 = to_light.squaredNorm();
    if (!(distance2 > 0)) continue;
    const Eigen::Vector3f wi = to_light / std::sqrt(distance2);
    const float cos_i = n.dot(wi);
    if (cos_i <= 0) continue;
    radiance +=
        render::ward_brdf(material, n, wi, wo).cwiseProduct(light.intensity) * (cos_i / distance2);
  }
  return radiance;
}

namespace {

// Refined albedos around a point and their interpolation weights.
struct WeightedAlbedos {
  static constexpr int kCapacity = 64;  // the 4^3 voxels around a cell
  int count = 0;
  std::array<float, kCapacity> weight, luminance;
  std::array<Eigen::Vector3f, kCapacity> albedo;

  void add(float w, const Eigen::Vector3f& kd) {
    weight[count] = w;
    albedo[count] = kd;
    luminance[count] = kd.mean();
    ++count;
  }
};

// Weighted mean of the albedos. A voxel whose normal or surface point misses a crease predicts
// too little or too much irradiance, and its eq. (7) albedo comes out near 0 or 1: among four or
// more, a minority (at most a quarter) whose mean albedo is more than half off their median is
// left out; a texture edge through the cell splits them more evenly and stays. (The 0.01 keeps
// near-black ones from all being outliers of one another.)
bool blend_without_outliers(const WeightedAlbedos& around, Eigen::Vector3f& kd) {
  const int n = around.count;
  if (n == 0) return false;
  std::array<float, WeightedAlbedos::kCapacity> sorted = around.luminance;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.begin() + n);
  const float median = sorted[n / 2];
  std::array<bool, WeightedAlbedos::kCapacity> outlier;
  int outliers = 0;
  for (int k = 0; k < n; ++k) {
    outlier[k] = std::abs(around.luminance[k] - median) > kRefinedKdOutlier * median + 0.01f;
    outliers += outlier[k];
  }
  const bool leave_out = n >= 4 && 4 * outliers <= n;
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float weights = 0;
  for (int k = 0; k < n; ++k) {
    if (leave_out && outlier[k]) continue;
    sum += around.weight[k] * around.albedo[k];
    weights += around.weight[k];
  }
  if (!(weights > 1e-6f)) return false;
  kd = sum / weights;
  return true;
}

}  // namespace

bool interpolate_refined_kd(const ObservationGrid& grid, const Eigen::Vector3f& p, int segment,
                            Eigen::Vector3f& kd, bool unreliable_corners) {
  // Voxel centres sit at (i + 0.5) * size: the 8 around p start at floor(p / size - 0.5).
  const Eigen::Vector3f g = p / float(grid.params().voxel_size_m) - Eigen::Vector3f::Constant(0.5f);
  const Eigen::Vector3i base(int(std::floor(g.x())), int(std::floor(g.y())),
                             int(std::floor(g.z())));
  const Eigen::Vector3f t = g - base.cast<float>();
  const auto refined_of_segment = [&](const Eigen::Vector3i& voxel) {
    const int v = grid.find_voxel(voxel);
    return v >= 0 && grid.segment(v) == segment && grid.has_refined_kd(v) ? v : -1;
  };
  WeightedAlbedos reliable, unreliable;
  for (int c = 0; c < 8; ++c) {
    const int v = refined_of_segment(base + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1));
    if (v < 0) continue;
    const float weight = ((c & 1) ? t.x() : 1 - t.x()) * (((c >> 1) & 1) ? t.y() : 1 - t.y()) *
                         (((c >> 2) & 1) ? t.z() : 1 - t.z());
    (grid.refined_kd_reliable(v) ? reliable : unreliable).add(weight, grid.refined_kd(v));
  }
  if (reliable.count == 0) {
    // No corner is reliable: the reliable voxels one further out, under a tent twice as wide.
    for (int dz = -1; dz <= 2; ++dz)
      for (int dy = -1; dy <= 2; ++dy)
        for (int dx = -1; dx <= 2; ++dx) {
          const int v = refined_of_segment(base + Eigen::Vector3i(dx, dy, dz));
          if (v < 0 || !grid.refined_kd_reliable(v)) continue;
          const Eigen::Vector3f d = (t - Eigen::Vector3f(dx, dy, dz)).cwiseAbs();
          const float weight = (1 - 0.5f * d.x()) * (1 - 0.5f * d.y()) * (1 - 0.5f * d.z());
          reliable.add(weight, grid.refined_kd(v));
        }
  }
  if (reliable.count == 0 && !unreliable_corners) return false;
  return blend_without_outliers(reliable.count > 0 ? reliable : unreliable, kd);
}

namespace {

// Segment of the voxel holding p, else of the nearest labelled of its 26 neighbours.
int segment_at(const ObservationGrid& grid, const Eigen::Vector3f& p) {
  const int v = grid.find(p);
  if (v >= 0 && grid.segment(v) > 0) return grid.segment(v);
  const float size = float(grid.params().voxel_size_m);
  const Eigen::Vector3f g = p / size;
  const Eigen::Vector3i centre(int(std::floor(g.x())), int(std::floor(g.y())),
                               int(std::floor(g.z())));
  int best = 0;
  float best_distance = INFINITY;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz);
        const int n = grid.find_voxel(voxel);
        if (n < 0 || grid.segment(n) <= 0) continue;
        const float distance = (grid.voxel_centre(voxel) - p).squaredNorm();
        if (distance < best_distance) best = grid.segment(n), best_distance = distance;
      }
  return best;
}

}  // namespace

bool material_at(const ObservationGrid& grid, const SpecularEstimator& materials,
                 const Eigen::Vector3f& p, PointMaterial& material) {
  material.segment = segment_at(grid, p);
  const SegmentMaterial* fused = materials.material(material.segment);
  if (!fused) return false;
  material.fused = material.refined = fused->ward;
  if (fused->kd_refined) material.refined.kd = *fused->kd_refined;
  interpolate_refined_kd(grid, p, material.segment, material.refined.kd, !fused->kd_refined);
  return true;
}

namespace {

void put(ImageF& image, int x, int y, const Eigen::Vector3f& value) {
  for (int c = 0; c < 3; ++c) image.at(x, y, c) = value[c];
}

}  // namespace

MaterialMaps render_material_maps(const fusion::SurfaceView& surface, const Pose& camera_to_world,
                                  const ObservationGrid& grid, const SpecularEstimator& materials,
                                  const std::vector<render::PointLight>& lights, float exposure) {
  const int width = surface.depth_m.width(), height = surface.depth_m.height();
  MaterialMaps maps;
  maps.kd = maps.kd_refined = maps.ks = maps.rgb = maps.rgb_refined = ImageF(width, height, 3);
  maps.alpha = maps.covered = ImageF(width, height, 1);
  maps.segment = Image<std::int32_t>(width, height, 1);
  const Eigen::Vector3f eye = camera_to_world.translation().cast<float>();
  parallel_for(std::size_t(height), [&](std::size_t row) {
    const int y = int(row);
    for (int x = 0; x < width; ++x) {
      if (!(surface.depth_m.at(x, y, 0) > 0)) continue;
      const Eigen::Vector3f p(surface.points_m.at(x, y, 0), surface.points_m.at(x, y, 1),
                              surface.points_m.at(x, y, 2));
      const Eigen::Vector3f n(surface.normals.at(x, y, 0), surface.normals.at(x, y, 1),
                              surface.normals.at(x, y, 2));
      if (!p.allFinite() || !n.allFinite()) continue;
      PointMaterial material;
      if (!material_at(grid, materials, p, material)) continue;
      maps.segment.at(x, y, 0) = material.segment;
      maps.covered.at(x, y, 0) = 1;
      put(maps.kd, x, y, material.fused.kd);
      put(maps.kd_refined, x, y, material.refined.kd);
      put(maps.ks, x, y, material.fused.ks);
      maps.alpha.at(x, y, 0) = material.fused.alpha;
      const auto pixel = [&](const Eigen::Vector3f& radiance) {
        return (radiance * exposure).cwiseMax(0.0f).cwiseMin(1.0f).eval();
      };
      put(maps.rgb, x, y, pixel(shade_ward(material.fused, p, n, eye, lights)));
      put(maps.rgb_refined, x, y, pixel(shade_ward(material.refined, p, n, eye, lights)));
    }
  });
  return maps;
}

}  // namespace glint::reflectance
