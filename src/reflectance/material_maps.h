#pragma once
// Re-rendering of the reconstructed model from a camera (paper 1 §4.2, Figs 2-3, Table 1): the
// surface seen by the camera (a TSDF ray cast) is looked up in the observation grid for its
// segment and that segment's fused Ward material; the refined diffuse albedo is interpolated
// trilinearly between the surrounding observation voxels of the same segment (§3.7), and
// optionally smoothed where neighbouring voxels agree to within the scatter of eq. (7); each
// pixel is shaded with the Ward BRDF under the estimated near-field point lights (with the light
// transport's shadows and indirect light where they are on, and the direct light dimmed where
// the voxels' observations lacked it: PointMaterial::direct_share), once with the HemiCNN's kd
// and once with the refined kd.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "fusion/raycast.h"
#include "reflectance/observation_grid.h"
#include "reflectance/specular_estimation.h"
#include "render/scene.h"

namespace glint::reflectance {

struct MaterialMaps {
  ImageF kd, kd_refined, ks;    // 3 channels, linear albedo
  ImageF alpha;                 // 1 channel
  ImageF rgb, rgb_refined;      // 3 channels: radiance * exposure, clipped to [0, 1] (linear)
  Image<std::int32_t> segment;  // global segment id, 0 = none
  ImageF covered;               // 1 where the model was hit and its segment has a material
};

// Eq. (6) summed over the point lights (L_l = intensity / r^2) with the material factored out:
// the outgoing radiance at a point is kd / pi * diffuse + ks * specular (per channel), where
// diffuse = sum_l L_l cos(theta_i,l) and specular weighs each term by the Ward lobe of the
// roughness alpha. Both are 0 where the eye sees the surface from behind.
struct WardShading {
  Eigen::Vector3f diffuse, specular;
  Eigen::Vector3f radiance(const render::WardMaterial& material) const {
    return (material.kd / float(M_PI)).cwiseProduct(diffuse) + material.ks.cwiseProduct(specular);
  }
};
// With `lighting`, only the lights it lets reach p count, its indirect irradiance adds to
// diffuse and its indirect radiance (PointLighting::indirect_radiance) to specular, as in the
// albedo refinement's image model.
WardShading ward_shading(float alpha, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                         const Eigen::Vector3f& eye, const std::vector<render::PointLight>& lights,
                         const PointLighting& lighting = {});

// How the voxels' refined albedos around a point are blended (interpolate_refined_kd()).
struct AlbedoBlend {
  // The edge-preserving smoothing's relative contrast; 0: the paper's trilinear interpolation
  // alone.
  float smoothing = 0;
  // The weight of the caller's albedo for the point (the segment's refined albedo) as one more
  // voxel's, in refined_albedo_weight()'s units (a voxel solved under light at 45 degrees or
  // steeper weighs 1), under the smoothing's range weight (so only with smoothing > 0); 0: none,
  // as the paper.
  float segment_weight = 0;
};

// Refined kd at p: trilinear weights of the 8 observation voxels around p, restricted to those
// of `segment` with a refined albedo, and of those to the reliable ones (solved under light
// that is not grazing, ObservationGrid::refined_kd_reliable) where there are any; with none
// reliable, the reliable voxels of the 4^3 around p under a tent of twice the width, and only
// without those the unreliable corners (when `unreliable_corners`: a caller with a better
// albedo for p, such as the segment's refined one, keeps its own). The reliable voxels'
// weights are multiplied by refined_albedo_weight(), less the more grazing their light was
// (reflectance/albedo_refinement.h), here and in the smoothing below. Less a minority of outliers
// (at most a quarter of four or more, mean albedo off their median by more than
// kRefinedKdOutlier of it), renormalised; false when there is none.
// With `smoothing` > 0 that estimate is then smoothed edge-preservingly: the reliable voxels of
// the 4^3 under the wide tent, weighted by how close their albedo is to it: a Gaussian in their
// mean absolute channel difference relative to the estimate's mean (+ 0.01), with standard
// deviation `smoothing` (a voxel 2 * smoothing off counts e^-2 as much). 0: the paper's
// trilinear interpolation alone.
// With `segment_weight` > 0, smoothing and without `unreliable_corners`, the caller's kd joins
// the reliable voxels in both steps as one more albedo of that weight (beside the trilinear and
// the wide tents alike), times the range weight from the estimate so far. A shrinkage towards
// the segment's albedo (paper 1 §3.5 assumes objects of locally homogeneous material): where the
// voxels around p are few or solved under grazing light it dominates, and the estimate no longer
// jumps between the voxels' and the segment's where the last reliable voxel falls out of reach;
// among voxels lit well it hardly counts. An estimate far from the segment's albedo (a texture,
// or two materials under one label) is beyond the range weight and keeps its own: without it, a
// red head that glint's own segmentation merged with a grey table (office) took the mix.
inline constexpr float kRefinedKdOutlier = 0.5f;
bool interpolate_refined_kd(const ObservationGrid& grid, const Eigen::Vector3f& p, int segment,
                            Eigen::Vector3f& kd, bool unreliable_corners = true,
                            const AlbedoBlend& blend = {});

// The observation voxels of the 4^3 around a trilinear cell (from the cell's first corner - 1,
// x fastest), and of those the voxels of one segment with a refined albedo: pool indices, -1
// where there is none. The 4^3 holds the 3^3 around the voxel holding any point of the cell.
struct RefinedNeighbourhood {
  Eigen::Vector3i base = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
  std::array<int, 64> grid_voxels{};
  int segment = -1;
  std::array<int, 64> voxels{};
  // Those with a reliable refined albedo, as arrays for the smoothing's vectorised loop: the
  // albedo, the offset from the cell's first corner and the voxel's refined_albedo_weight().
  int reliable = 0;
  std::array<float, 64> red, green, blue, dx, dy, dz, weight;
  // Of those, the ones the wide tent's blend leaves out as outliers (set only where no corner
  // is reliable, the one case that blend is made).
  std::array<bool, 64> reliable_outlier;
  // The cell's 8 trilinear corners of the segment with a refined albedo, the reliable and the
  // unreliable apart, in corner order (bit 0: +x, bit 1: +y, bit 2: +z): the corner, its weight
  // beside the trilinear one (refined_albedo_weight() for a reliable one, else 1) and its albedo;
  // less the ones their blend leaves out as outliers, in the one set a point's blend takes (the
  // reliable corners, else the unreliable ones where there is no reliable voxel in the 4^3).
  // Which albedos are outliers depends on the set alone, not on the point's weights, so it is
  // found once per cell and segment instead of at every point.
  struct Corners {
    int count = 0;
    std::array<int, 8> corner;
    std::array<float, 8> weight;
    std::array<Eigen::Vector3f, 8> kd;
  };
  Corners reliable_corners, unreliable_corners;
};

struct PointMaterial {
  int segment = 0;
  render::WardMaterial fused, refined;
  // The share of the direct light its voxels' observations showed (1 - their
  // ObservationGrid::light_shortfall, trilinear over the cell's voxels of the segment with a
  // refined albedo): PointLighting::direct_share of a re-rendering.
  float direct_share = 1;
};

// The material at surface point p: the segment of the voxel holding p (else of the nearest
// labelled neighbour voxel), its fused Ward parameters, and the same with the refined kd
// (interpolate_refined_kd() with `blend`, the segment's fused refined kd as the caller's; before
// the segment has one, the unreliable voxels around p, else the network's kd); false when p lies
// in no segment with a material yet. Meant for many points of one model, such as a
// re-rendering's pixels or a mesh's vertices, in an order where neighbours follow each other: it
// keeps the last point's neighbourhood (64 voxels, which serve both its segment and its refined
// albedo), which the next point mostly shares, and the grid blocks it found last
// (ObservationGrid::BlockCache). One per thread; the grid must not change while it is in use.
class MaterialLookup {
 public:
  // The grid voxel the last point lay in, and the one segment it and its 26 neighbours hold
  // (0: none), or kMixed.
  struct VoxelSegment {
    static constexpr int kMixed = -1;
    Eigen::Vector3i voxel = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
    int segment = 0;
  };

  MaterialLookup(const ObservationGrid& grid, const SpecularEstimator& materials,
                 const AlbedoBlend& blend = {})
      : grid_(grid), materials_(materials), blend_(blend) {}
  bool operator()(const Eigen::Vector3f& p, PointMaterial& material);

 private:
  const ObservationGrid& grid_;
  const SpecularEstimator& materials_;
  AlbedoBlend blend_;
  RefinedNeighbourhood around_;
  ObservationGrid::BlockCache blocks_;  // the grid blocks found last
  VoxelSegment last_voxel_;
};

// Fills `maps` (0 where the model was not hit or has no material). Images of the view's size
// keep their storage: a caller rendering view after view passes the same maps, and their 15 MB
// (512 x 424) are not allocated and faulted in afresh, 6 ms of each re-rendering on one core.
// With `transport` (and the `volume` it was cast through) the re-rendering casts shadows, a
// shadow ray per pixel and light, and adds the indirect light of the voxel under each pixel.
void render_material_maps(const fusion::SurfaceView& surface, const Pose& camera_to_world,
                          const ObservationGrid& grid, const SpecularEstimator& materials,
                          const std::vector<render::PointLight>& lights, float exposure,
                          const AlbedoBlend& blend, MaterialMaps& maps,
                          const LightTransport* transport = nullptr,
                          const fusion::TsdfVolume* volume = nullptr);

}  // namespace glint::reflectance
