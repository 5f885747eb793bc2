#include "reflectance/material_maps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "core/fast_exp.h"
#include "core/parallel.h"
#include "reflectance/albedo_refinement.h"
#include "render/ward.h"

namespace glint::reflectance {

WardShading ward_shading(float alpha, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                         const Eigen::Vector3f& eye, const std::vector<render::PointLight>& lights,
                         const PointLighting& lighting) {
  const Eigen::Vector3f wo = (eye - p).normalized();
  if (!(n.dot(wo) > 0.0f)) return {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
  WardShading shading{lighting.indirect,
                      lighting.indirect_radiance * render::ward_lobe_albedo(n.dot(wo), alpha)};
  for (std::size_t l = 0; l < lights.size(); ++l) {
    if (!lighting.reaches(l)) continue;
    const render::PointLight& light = lights[l];
    const Eigen::Vector3f to_light = light.position.cast<float>() - p;
    const float distance2 = to_light.squaredNorm();
    if (!(distance2 > 0)) continue;
    const Eigen::Vector3f wi = to_light / std::sqrt(distance2);
    const float cos_i = n.dot(wi);
    if (cos_i <= 0) continue;
    const Eigen::Vector3f irradiance =
        light.intensity * (lighting.direct_share * cos_i / distance2);
    shading.diffuse += irradiance;
    shading.specular += irradiance * render::ward_specular_lobe(n, wi, wo, alpha);
  }
  return shading;
}

namespace {

// Marks which of n albedos, by their mean over the channels, a blend leaves out. A voxel whose
// normal or surface point misses a crease predicts too little or too much irradiance, and its
// eq. (7) albedo comes out near 0 or 1: among four or more, a minority (at most a quarter) whose
// mean albedo is more than half off their median is left out; a texture edge through the cell
// splits them more evenly and stays. (The 0.01 keeps near-black ones from all being outliers of
// one another.)
void mark_outliers(const float* luminance, int n, bool* outlier) {
  std::fill(outlier, outlier + n, false);
  if (n < 4) return;
  std::array<float, 64> sorted;
  std::copy(luminance, luminance + n, sorted.begin());
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.begin() + n);
  const float median = sorted[std::size_t(n / 2)];
  int outliers = 0;
  for (int k = 0; k < n; ++k) {
    outlier[k] = std::abs(luminance[k] - median) > kRefinedKdOutlier * median + 0.01f;
    outliers += outlier[k];
  }
  if (4 * outliers > n) std::fill(outlier, outlier + n, false);  // no minority: all stay
}

// Drops the corners a blend of them leaves out (mark_outliers()), keeping their order.
void drop_outliers(RefinedNeighbourhood::Corners& corners) {
  std::array<float, 8> luminance;
  std::array<bool, 8> outlier;
  for (int i = 0; i < corners.count; ++i)
    luminance[std::size_t(i)] = corners.kd[std::size_t(i)].mean();
  mark_outliers(luminance.data(), corners.count, outlier.data());
  int kept = 0;
  for (int i = 0; i < corners.count; ++i) {
    if (outlier[std::size_t(i)]) continue;
    corners.corner[std::size_t(kept)] = corners.corner[std::size_t(i)];
    corners.weight[std::size_t(kept)] = corners.weight[std::size_t(i)];
    corners.kd[std::size_t(kept++)] = corners.kd[std::size_t(i)];
  }
  corners.count = kept;
}

// The trilinear cell of point p: its first corner voxel and p's coordinates within it in
// [0, 1)^3. Voxel centres sit at (i + 0.5) * size: the 8 around p start at floor(p / size - 0.5).
struct Cell {
  Eigen::Vector3i base;
  Eigen::Vector3f t;
};
Cell cell_of(const ObservationGrid& grid, const Eigen::Vector3f& p) {
  const Eigen::Vector3f g = p / float(grid.params().voxel_size_m) - Eigen::Vector3f::Constant(0.5f);
  const Eigen::Vector3i base(int(std::floor(g.x())), int(std::floor(g.y())),
                             int(std::floor(g.z())));
  return {base, g - base.cast<float>()};
}

// The trilinear weight of corner c (bit 0: +x, bit 1: +y, bit 2: +z) at t in the cell.
float corner_weight(int c, const Eigen::Vector3f& t) {
  return ((c & 1) ? t.x() : 1 - t.x()) * (((c >> 1) & 1) ? t.y() : 1 - t.y()) *
         (((c >> 2) & 1) ? t.z() : 1 - t.z());
}

// Fills `around`'s voxels for the cell at `base`, unless it holds them already.
void look_up(const ObservationGrid& grid, const Eigen::Vector3i& base, RefinedNeighbourhood& around,
             ObservationGrid::BlockCache* cache = nullptr) {
  if (around.base == base) return;
  around.base = base;
  around.segment = -1;
  grid.find_voxels(base - Eigen::Vector3i::Ones(), 4, around.grid_voxels.data(), cache);
}

// The voxel at offset (dx, dy, dz) from the cell's first corner, each in [-1, 2].
int voxel_at(const RefinedNeighbourhood& around, int dx, int dy, int dz) {
  return around.voxels[std::size_t(((dz + 1) * 4 + dy + 1) * 4 + dx + 1)];
}

// Fills `around`'s refined albedos of `segment` (its voxels looked up), unless it holds them.
void select_segment(const ObservationGrid& grid, int segment, RefinedNeighbourhood& around) {
  if (around.segment == segment) return;
  around.segment = segment;
  around.reliable = 0;
  for (int i = 0; i < 64; ++i) {
    int& v = around.voxels[std::size_t(i)];
    v = around.grid_voxels[std::size_t(i)];
    if (v >= 0 && !(grid.segment(v) == segment && grid.has_refined_kd(v))) v = -1;
    if (v < 0 || !grid.refined_kd_reliable(v)) continue;
    const Eigen::Vector3f& kd = grid.refined_kd(v);
    const std::size_t k = std::size_t(around.reliable++);
    around.weight[k] = refined_albedo_weight(grid.refined_kd_light_tangent(v));
    around.red[k] = kd.x();
    around.green[k] = kd.y();
    around.blue[k] = kd.z();
    around.dx[k] = float(i % 4 - 1);
    around.dy[k] = float(i / 4 % 4 - 1);
    around.dz[k] = float(i / 16 - 1);
  }
  around.reliable_corners.count = around.unreliable_corners.count = 0;
  for (int c = 0; c < 8; ++c) {
    const int v = voxel_at(around, c & 1, (c >> 1) & 1, (c >> 2) & 1);
    if (v < 0) continue;
    const bool reliable = grid.refined_kd_reliable(v);
    RefinedNeighbourhood::Corners& corners =
        reliable ? around.reliable_corners : around.unreliable_corners;
    const std::size_t i = std::size_t(corners.count++);
    corners.corner[i] = c;
    corners.weight[i] = reliable ? refined_albedo_weight(grid.refined_kd_light_tangent(v)) : 1.0f;
    corners.kd[i] = grid.refined_kd(v);
  }
  // Outliers only of the one set a point's blend will take.
  drop_outliers(around.reliable_corners);
  if (around.reliable_corners.count > 0) return;
  if (around.reliable == 0) {
    drop_outliers(around.unreliable_corners);
    return;
  }
  std::array<float, 64> luminance;
  for (int k = 0; k < around.reliable; ++k)
    luminance[std::size_t(k)] =
        Eigen::Vector3f(around.red[std::size_t(k)], around.green[std::size_t(k)],
                        around.blue[std::size_t(k)])
            .mean();
  mark_outliers(luminance.data(), around.reliable, around.reliable_outlier.data());
}

// The weight under a tent twice the voxel's width centred on the point at t in the cell, of the
// voxel at offset d from the cell's first corner.
float wide_tent(const Eigen::Vector3f& t, float dx, float dy, float dz) {
  return (1 - 0.5f * std::fabs(t.x() - dx)) * (1 - 0.5f * std::fabs(t.y() - dy)) *
         (1 - 0.5f * std::fabs(t.z() - dz));
}

// The smoothing's range weight of an albedo: exp(-r^2 / 2), r = its mean absolute channel
// difference from `reference` over contrast * (mean of the reference + 0.01).
struct RangeWeight {
  RangeWeight(const Eigen::Vector3f& reference, float contrast)
      : reference(reference),
        // Albedos lie in [0, 1], so r <= 3 * inverse_scale: capped at 1000, -r^2 / 2 stays within
        // exp_nonpositive()'s range (a contrast that small weighs every other albedo at e^-50 or
        // less anyway).
        inverse_scale(std::min(1.0f / (contrast * (reference.mean() + 0.01f)) / 3.0f, 1000.0f)) {}
  float operator()(const Eigen::Vector3f& albedo) const {
    const float r = (albedo - reference).cwiseAbs().sum() * inverse_scale;
    return exp_nonpositive(-0.5f * r * r);
  }
  Eigen::Vector3f reference;
  float inverse_scale;
};

// The caller's albedo for a point (the segment's refined one) as one more voxel; weight 0: none.
struct SegmentAlbedo {
  float weight = 0;
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();

  // Adds it to a weighted sum of albedos, its weight times its `range` weight.
  void add_to(const RangeWeight& range, Eigen::Vector3f& sum, float& weights) const {
    if (!(weight > 0)) return;
    const float w = weight * range(kd);
    sum += w * kd;
    weights += w;
  }
};

// Joint bilateral smoothing (Tomasi and Manduchi 1998) of the albedo kd interpolated at the point
// at t: the reliable voxels of its 4^3 under the wide tent and the segment's albedo, each
// weighted further by RangeWeight(kd, contrast). The voxel-to-voxel scatter of eq. (7) averages
// out; a texture edge of more contrast is kept. The voxels' weights come from one vectorised loop
// (AVX2 where the CPU has it): an exp per voxel and pixel was most of a re-rendering's material
// lookups.
#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void smooth_refined_kd(const RefinedNeighbourhood& around, const Eigen::Vector3f& t,
                       float contrast, const SegmentAlbedo& segment, Eigen::Vector3f& kd) {
  const float red = kd.x(), green = kd.y(), blue = kd.z();
  const RangeWeight range(kd, contrast);
  std::array<float, 64> weight;
  for (int k = 0; k < around.reliable; ++k) {
    const float r = (std::fabs(around.red[k] - red) + std::fabs(around.green[k] - green) +
                     std::fabs(around.blue[k] - blue)) *
                    range.inverse_scale;
    weight[k] = around.weight[k] * wide_tent(t, around.dx[k], around.dy[k], around.dz[k]) *
                exp_nonpositive(-0.5f * r * r);
  }
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float weights = 0;
  for (int k = 0; k < around.reliable; ++k) {
    sum += weight[k] * Eigen::Vector3f(around.red[k], around.green[k], around.blue[k]);
    weights += weight[k];
  }
  segment.add_to(range, sum, weights);
  if (weights > 1e-6f) kd = sum / weights;
}

// interpolate_refined_kd() at the point at t in the cell of `around`.
bool interpolate(const RefinedNeighbourhood& around, const Eigen::Vector3f& t, Eigen::Vector3f& kd,
                 bool unreliable_corners, const AlbedoBlend& blend) {
  SegmentAlbedo segment;
  if (!unreliable_corners && blend.smoothing > 0) segment = {blend.segment_weight, kd};
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float total = 0;
  const auto add_corners = [&](const RefinedNeighbourhood::Corners& corners) {
    for (int i = 0; i < corners.count; ++i) {
      const int c = corners.corner[std::size_t(i)];
      const float w = corner_weight(c, t) * corners.weight[std::size_t(i)];
      sum += w * corners.kd[std::size_t(i)];
      total += w;
    }
  };
  if (around.reliable_corners.count > 0) {
    add_corners(around.reliable_corners);
  } else if (around.reliable > 0) {
    // No corner is reliable: the reliable voxels one further out, under a tent twice as wide.
    for (int k = 0; k < around.reliable; ++k) {
      if (around.reliable_outlier[std::size_t(k)]) continue;
      const float w = around.weight[std::size_t(k)] * wide_tent(t, around.dx[std::size_t(k)],
                                                                around.dy[std::size_t(k)],
                                                                around.dz[std::size_t(k)]);
      sum += w * Eigen::Vector3f(around.red[std::size_t(k)], around.green[std::size_t(k)],
                                 around.blue[std::size_t(k)]);
      total += w;
    }
  } else if (unreliable_corners) {
    add_corners(around.unreliable_corners);
  } else {
    return false;
  }
  if (!(total > 1e-6f)) return false;
  kd = sum / total;
  if (blend.smoothing > 0) {
    // The segment's albedo joins the voxels' blend within the range weight.
    Eigen::Vector3f blended = total * kd;
    float weights = total;
    segment.add_to(RangeWeight(kd, blend.smoothing), blended, weights);
    kd = blended / weights;
    smooth_refined_kd(around, t, blend.smoothing, segment, kd);
  }
  return true;
}

}  // namespace

bool interpolate_refined_kd(const ObservationGrid& grid, const Eigen::Vector3f& p, int segment,
                            Eigen::Vector3f& kd, bool unreliable_corners,
                            const AlbedoBlend& blend) {
  const Cell cell = cell_of(grid, p);
  RefinedNeighbourhood around;
  look_up(grid, cell.base, around);
  select_segment(grid, segment, around);
  return interpolate(around, cell.t, kd, unreliable_corners, blend);
}

namespace {

// A point this close to the surface plane of the voxel holding it lies on that voxel's surface,
// in voxels (chosen on cubes, where 0 and 0.25 scored lower on most averaged metrics).
constexpr float kOnVoxelSurface = 0.1f;

// The segment of surface point p: where the voxel holding p and its 26 neighbours hold one
// segment, that one (or none); else that of p's voxel where p lies on its surface plane, and
// otherwise that of the labelled voxel among the 27 whose surface plane passes nearest to p.
// Where two objects meet (a box on a floor), a voxel holds both surfaces and one label, but its
// plane is that of one surface (the plane fit leaves out neighbours more than 30 degrees off
// it): the other surface's points lie off it. Where none of the 27 has a surface, the one whose
// centre is nearest. `around` holds the voxels of p's trilinear cell (look_up()); `last` keeps
// the 27's segment for the next points, which mostly lie in the same voxel.
int segment_at(const ObservationGrid& grid, const Eigen::Vector3f& p,
               const RefinedNeighbourhood& around, MaterialLookup::VoxelSegment& last) {
  const float size = float(grid.params().voxel_size_m);
  const Eigen::Vector3f g = p / size;
  const Eigen::Vector3i centre(int(std::floor(g.x())), int(std::floor(g.y())),
                               int(std::floor(g.z())));
  // p's voxel in the 4^3 from base - 1: 1 or 2 along each axis (the cell's base is p's voxel or
  // the one below it), so its 3^3 lie within.
  const Eigen::Vector3i first = around.base - Eigen::Vector3i::Ones();
  const auto voxel_at = [&](const Eigen::Vector3i& voxel) {
    const Eigen::Vector3i d = voxel - first;
    return around.grid_voxels[std::size_t((d.z() * 4 + d.y()) * 4 + d.x())];
  };
  const auto segment_of = [&](int v) { return v >= 0 ? std::max(grid.segment(v), 0) : 0; };
  const auto for_each_of_27 = [&](auto&& visit) {  // p's voxel and its 26 neighbours
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz);
          visit(voxel, voxel_at(voxel));
        }
  };
  if (last.voxel != centre) {
    last.voxel = centre;
    last.segment = 0;
    for_each_of_27([&](const Eigen::Vector3i&, int n) {
      const int segment = segment_of(n);
      if (segment > 0 && last.segment != segment)
        last.segment = last.segment == 0 ? segment : MaterialLookup::VoxelSegment::kMixed;
    });
  }
  if (last.segment != MaterialLookup::VoxelSegment::kMixed) return last.segment;
  const auto plane_distance = [&](int v) {
    return grid.has_surface(v) ? std::fabs(grid.normal(v).dot(p - grid.position(v))) : INFINITY;
  };
  const int v = voxel_at(centre);
  if (segment_of(v) > 0 && plane_distance(v) <= kOnVoxelSurface * size) return grid.segment(v);
  int best = 0;
  float best_plane = INFINITY, best_centre = INFINITY;
  for_each_of_27([&](const Eigen::Vector3i& voxel, int n) {
    if (segment_of(n) == 0) return;
    const float plane = plane_distance(n);
    const float to_centre = (grid.voxel_centre(voxel) - p).squaredNorm();
    if (plane < best_plane || (plane == best_plane && to_centre < best_centre))
      best = grid.segment(n), best_plane = plane, best_centre = to_centre;
  });
  return best;
}

}  // namespace

namespace {

// ObservationGrid::light_shortfall at the point at t in the cell of `around`: trilinear over the
// cell's corners of the segment with a refined albedo; 0 without any.
float interpolate_shortfall(const ObservationGrid& grid, const RefinedNeighbourhood& around,
                            const Eigen::Vector3f& t) {
  float sum = 0, total = 0;
  for (int c = 0; c < 8; ++c) {
    const int v = voxel_at(around, c & 1, (c >> 1) & 1, (c >> 2) & 1);
    if (v < 0) continue;
    const float weight = corner_weight(c, t);
    sum += weight * grid.light_shortfall(v);
    total += weight;
  }
  return total > 1e-6f ? sum / total : 0.0f;
}

}  // namespace

bool MaterialLookup::operator()(const Eigen::Vector3f& p, PointMaterial& material) {
  const Cell cell = cell_of(grid_, p);
  look_up(grid_, cell.base, around_, &blocks_);
  material.segment = segment_at(grid_, p, around_, last_voxel_);
  const SegmentMaterial* fused = materials_.material(material.segment);
  if (!fused) return false;
  material.fused = material.refined = fused->ward;
  if (fused->kd_refined) material.refined.kd = *fused->kd_refined;
  select_segment(grid_, material.segment, around_);
  interpolate(around_, cell.t, material.refined.kd, !fused->kd_refined, blend_);
  material.direct_share = 1 - interpolate_shortfall(grid_, around_, cell.t);
  return true;
}

namespace {

void put(ImageF& image, int x, int y, const Eigen::Vector3f& value) {
  for (int c = 0; c < 3; ++c) image.at(x, y, c) = value[c];
}

// Zeroes row y of every channel.
template <class T>
void clear_row(Image<T>& image, int y) {
  for (int c = 0; c < image.channels(); ++c)
    std::fill_n(image.plane(c) + std::size_t(y) * image.width(), image.width(), T{});
}

}  // namespace

void render_material_maps(const fusion::SurfaceView& surface, const Pose& camera_to_world,
                          const ObservationGrid& grid, const SpecularEstimator& materials,
                          const std::vector<render::PointLight>& lights, float exposure,
                          const AlbedoBlend& blend, MaterialMaps& maps,
                          const LightTransport* transport, const fusion::TsdfVolume* volume) {
  const int width = surface.depth_m.width(), height = surface.depth_m.height();
  // The float maps and their channels.
  const std::array<std::pair<ImageF*, int>, 7> float_maps{{{&maps.kd, 3},
                                                           {&maps.kd_refined, 3},
                                                           {&maps.ks, 3},
                                                           {&maps.rgb, 3},
                                                           {&maps.rgb_refined, 3},
                                                           {&maps.alpha, 1},
                                                           {&maps.covered, 1}}};
  for (const auto& [image, channels] : float_maps) image->ensure_size(width, height, channels);
  maps.segment.ensure_size(width, height, 1);
  const Eigen::Vector3f eye = camera_to_world.translation().cast<float>();
  const bool lit = transport && volume && transport->enabled();
  const std::optional<fusion::BlockOccupancy> occupancy =
      lit ? std::optional<fusion::BlockOccupancy>(*volume) : std::nullopt;
  parallel_for(std::size_t(height), [&](std::size_t row) {
    const int y = int(row);
    for (const auto& [image, channels] : float_maps) clear_row(*image, y);
    clear_row(maps.segment, y);
    MaterialLookup lookup(grid, materials, blend);
    std::optional<PointLightingQuery> lighting;
    if (lit) lighting.emplace(*transport, grid, *volume, *occupancy, lights);
    for (int x = 0; x < width; ++x) {
      if (!(surface.depth_m.at(x, y, 0) > 0)) continue;
      const Eigen::Vector3f p(surface.points_m.at(x, y, 0), surface.points_m.at(x, y, 1),
                              surface.points_m.at(x, y, 2));
      const Eigen::Vector3f n(surface.normals.at(x, y, 0), surface.normals.at(x, y, 1),
                              surface.normals.at(x, y, 2));
      if (!p.allFinite() || !n.allFinite()) continue;
      PointMaterial material;
      if (!lookup(p, material)) continue;
      maps.segment.at(x, y, 0) = material.segment;
      maps.covered.at(x, y, 0) = 1;
      put(maps.kd, x, y, material.fused.kd);
      put(maps.kd_refined, x, y, material.refined.kd);
      put(maps.ks, x, y, material.fused.ks);
      maps.alpha.at(x, y, 0) = material.fused.alpha;
      const auto pixel = [&](const Eigen::Vector3f& radiance) {
        return (radiance * exposure).cwiseMax(0.0f).cwiseMin(1.0f).eval();
      };
      // The two materials differ in kd only: one shading serves both.
      PointLighting light_here =
          lighting ? (*lighting)(p, n, eye, lobe_ray_alpha(material.fused)) : PointLighting{};
      light_here.direct_share = material.direct_share;
      const WardShading shading = ward_shading(material.fused.alpha, p, n, eye, lights, light_here);
      put(maps.rgb, x, y, pixel(shading.radiance(material.fused)));
      put(maps.rgb_refined, x, y, pixel(shading.radiance(material.refined)));
    }
  });
}

}  // namespace glint::reflectance
