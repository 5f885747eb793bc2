#pragma once
// Shadows and interreflections for the reflectance pipeline (glint's addition to paper 1, whose
// image model, eq. (6), has every light reach every point and nothing else). Per voxel of the
// observation grid, kept beside its other data:
//  - which point lights reach it: one shadow ray per light through the fused TSDF
//    (fusion/ray_march.h), binary (point lights have no penumbra), cast when the voxel is first
//    seen and again every shadow_refresh_frames frames it is seen, as the geometry grows;
//  - its indirect irradiance: the radiance the reconstruction has observed leaving the surfaces
//    around it, gathered over its hemisphere with cosine-weighted rays (one bounce from the
//    voxel's point of view, but the gathered radiance is what the camera saw, so it carries every
//    bounce before it), treating the emitting surfaces as diffuse: a hit voxel emits the colour
//    of its observation of median luminance, which leaves out its highlights. The Monte Carlo
//    estimate E = pi / n * sum_k L(w_k) (cosine-weighted directions, pdf cos / pi) accumulates a
//    few rays every few frames the voxel is seen, up to indirect_rays, then follows the changing
//    reconstruction as a moving average of that many rays, one ray every
//    indirect_refresh_frames frames. A ray that leaves the reconstruction counts as dark unless
//    it then meets the largest plane continued beyond it (continue_plane, ContinuedPlane); one
//    that hits a surface never observed, or one from behind, is not counted (no radiance is
//    known there). Indirect irradiance varies slowly along a surface, so a voxel's estimate pools
//    the rays of its neighbours on the same surface (indirect_pooling): a new voxel gets its light
//    after a few frames rather than after indirect_min_rays of its own rays, and with several
//    times the rays;
//  - one scale for the whole scene's gathered light (indirect_scaled), measured where no light
//    reaches directly, which takes the gather out where nothing bounces and makes up what it
//    misses elsewhere;
//  - per stored observation, what its specular lobe mirrors of the bounced light: the radiance
//    one ray drawn from the lobe around its mirror direction meets (IndirectSpecular::mirror),
//    cast once and kept beside the observation's slot.
// Where the fused geometry lacks an occluder (a part the camera never saw), the shadow test
// (LightTransportParams::shadow_test) lets a voxel's albedo name the light its ray missed; the
// true scene of a synthetic sequence can stand in for the TSDF as an oracle (use_true_scene()).
// Rays start ray_offset_m off the surface point along its normal: the point is the TSDF's zero
// crossing, which a ray starting on it would find again (self-shadowing acne).
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/pool_memory.h"
#include "fusion/block_occupancy.h"
#include "fusion/ray_queue.h"
#include "fusion/tsdf_volume.h"
#include "reflectance/continued_plane.h"
#include "reflectance/light_incidence.h"
#include "reflectance/observation_grid.h"
#include "reflectance/unseen_light.h"
#include "render/scene.h"
#include "render/ward.h"

namespace glint::render {
class EmbreeScene;
class Renderer;
}  // namespace glint::render

namespace glint::reflectance {

// What the Ward lobe of a surface mirrors of the bounced light around it, ks times a radiance
// times the lobe's directional albedo (render::ward_lobe_albedo(), about cos(theta_o)):
//  - off: nothing (paper 1's image model);
//  - sky: the gathered irradiance E_ind as an even sky of radiance E_ind / pi;
//  - mirror: per stored observation, the mean radiance its lobe rays meet through the fused TSDF
//    (rays drawn from eq. (3)'s lobe about the observation's mirror direction; the hit's diffuse
//    radiance as the gather counts it, dark where a ray leaves the reconstruction, the even sky
//    where none meets an observed surface), times the scene scale up to 1: the floor in a
//    glossy object's lower half, the dark above it. One ray per stored observation, cast once
//    (LightTransport::update_mirrors()), and kPixelLobeRays per re-rendered pixel.
enum class IndirectSpecular { off, sky, mirror };
// With mirror, a lobe this weak (ks below kMirrorMinKs in every channel: walls, floors) mirrors the
// even sky instead: its rays cost as much as a glossy lobe's, and what they would change is ks
// times the departure of a radiance from the sky's (docs/decisions.md, "Lobe rays where the lobe
// is strong enough to matter").
inline constexpr float kMirrorMinKs = 0.05f;
inline bool casts_lobe_rays(const Eigen::Vector3f& ks) { return ks.maxCoeff() >= kMirrorMinKs; }
// The lobe width a material's lobe rays are drawn with (update_mirrors(), PointLightingQuery):
// its alpha, or 0 (no rays, the even sky) for a weak lobe.
inline float lobe_ray_alpha(const render::WardMaterial& material) {
  return casts_lobe_rays(material.ks) ? material.alpha : 0.0f;
}
const char* indirect_specular_name(IndirectSpecular mode);
// Throws glint::Error for a name other than off, sky, mirror.
IndirectSpecular parse_indirect_specular(const std::string& name);

struct LightTransportParams {
  // Shadows, the shadow test, the scaled gather and the lobe's mirror rays on by default, by the
  // rules docs/decisions.md states: defaults serve input whose light is physical (real captures,
  // renderings with shadows), where shadow rays raise the refined albedo, the shadow test finds
  // most of the shadows the fused geometry misses, and the gather, scaled by what the voxels no
  // light reaches show (indirect_scaled), raises it where light bounces and takes nothing out where
  // none does, at about the rest of the pipeline's cost again (figures: docs/benchmarks.md).
  // Paper 1's image model, for renderings without shadows, is shadows = false, indirect = false.
  bool shadows = true;
  bool indirect = true;
  // With shadows: the albedo test of the shadows the fused geometry misses (occluders whose far
  // side the camera never saw, docs/decisions.md "Shadows the fused geometry misses"). A voxel
  // whose refined albedo differs from its segment's reference by more than shadow_test_ratio
  // (widened under gathered light, shadow_test_sigmas) drops the light, among those whose
  // shadow ray grazes fused geometry (passes through an allocated TSDF block from
  // shadow_test_skip_m past the voxel to shadow_test_margin_m short of the light), that brings
  // its albedo nearest the reference, if that improves the ratio by shadow_test_gain.
  bool shadow_test = true;
  float shadow_test_ratio = 1.2f;
  // Under gathered light a voxel's albedo is uncertain by its gathered share s of the
  // irradiance times the gather's relative error e (indirect_error()), and a voxel that much
  // darker than its reference is no evidence of a shadow (walls and furniture beside bounced
  // light, where the gather falls short): the ratio's log widens by shadow_test_sigmas * s * e.
  // 2 standard deviations, not tuned; 0: the fixed ratio.
  float shadow_test_sigmas = 2;
  float shadow_test_gain = 1.1f;
  float shadow_test_skip_m = 0.1f;
  float shadow_test_margin_m = 0.3f;
  // 2 TSDF voxels at the default 5 mm: the fused surface of a flat face scatters by about one
  // voxel, and a ray starting 1 cm above it no longer meets it (tested on a tilted plane).
  float ray_offset_m = 0.01f;
  int shadow_refresh_frames = 16;
  int indirect_rays = 64;  // n of the estimate
  // While a voxel has fewer than indirect_rays: this many rays every indirect_every_frames
  // frames it is seen (staggered over the voxels), which keeps the gather within a few times
  // the observation stage's cost (docs/benchmarks.md).
  int indirect_rays_per_frame = 2;
  int indirect_every_frames = 4;
  int indirect_refresh_frames = 16;  // afterwards one ray every this many frames it is seen
  // A voxel whose estimate holds fewer rays than this counts no indirect light yet (too noisy).
  int indirect_min_rays = 8;
  // A voxel's estimate pools the rays of the voxels of its 3x3x3 neighbourhood on the same
  // surface (pools_indirect_rays()): on its own rays alone a voxel seen every frame needs 16
  // frames to reach indirect_min_rays (docs/decisions.md, "The gather pools its neighbours' rays").
  bool indirect_pooling = true;
  // Gather and lobe rays that leave the reconstruction meet its largest plane continued beyond
  // it (ContinuedPlane; the pipeline finds the plane), where they would count as dark: a floor
  // seen from one side goes on behind the camera.
  bool continue_plane = true;
  // Multiply every voxel's gathered irradiance by one scene scale measured where no light
  // reaches directly: there a voxel's diffuse radiance is kd / pi * E_true, so its albedo solved
  // under the gathered E alone, over its segment's reference, is E_true / E (ReflectancePipeline
  // takes one such sample per due voxel). Black there (a rendering without bounced light) takes
  // the gather out; the gather's shortfall (rays into what the camera never saw) is made up on
  // average. The scale is the median of the latest kIndirectScaleSamples samples, 0 until
  // indirect_scale_min_samples have come, clamped to [0, indirect_scale_max]. The cap: the
  // gather finds about half the bounced light of renderings with bounces (docs/benchmarks.md),
  // and the unlit voxels, where it misses most, overstate the rest of the scene's shortfall
  // (cubes with 3 bounces: 2.8 uncapped).
  bool indirect_scaled = true;
  int indirect_scale_min_samples = 64;
  float indirect_scale_max = 2;
  float indirect_max_distance_m = 10;
  // What the Ward lobe mirrors of the bounced light (IndirectSpecular): a glossy surface
  // mirrors the floor and its neighbours, which eq. (7) would otherwise take for albedo. The
  // lobe rays by default, by the light-transport rule (docs/decisions.md, "The lobe mirrors
  // what its rays meet"); with the scene scale 0 (no bounced light) they mirror nothing.
  IndirectSpecular indirect_specular = IndirectSpecular::mirror;
  // A hit voxel whose median observation reaches this radiance in a channel has clipped: a lamp
  // (its proxy in a synthetic sequence) or its glare, whose light is already direct; it counts
  // as dark. The pipeline sets it from the exposure.
  float saturated_radiance = INFINITY;
  std::uint64_t seed = 1;  // the rays' directions (per voxel, from its grid coordinates)
  // Per segment, the indirect irradiance the shadows and the gather leave unexplained, fitted
  // from its voxels (reflectance/unseen_light.h) and added to each voxel's indirect light.
  bool unseen = false;
  UnseenLightFitParams unseen_fit{};
  // A segment's unseen irradiance is the ratio of its fits' mean intercept and slope, the means
  // over its first unseen_memory frames' fits, then exponential averages with that weight: it
  // follows the gather as its estimates fill in. (The ratio of means: a frame's own ratio is
  // noisy where its slope is small, a dark channel's.)
  int unseen_memory = 8;
};

class LightTransport {
 public:
  // `voxel_capacity`: ObservationGrid::voxel_pool_size() of the grid it serves. Throws
  // glint::Error for bad parameters.
  // `observations_per_voxel`: ObservationGridParams::observations_per_voxel (the mirror rays'
  // slots).
  LightTransport(const LightTransportParams& params, std::size_t voxel_capacity,
                 int observations_per_voxel = 0);

  const LightTransportParams& params() const { return params_; }
  bool enabled() const { return params_.shadows || params_.indirect || params_.unseen; }
  // Whether the lobe mirrors each observation's lobe rays (IndirectSpecular::mirror, with the
  // gather).
  bool mirrors() const {
    return params_.indirect && params_.indirect_specular == IndirectSpecular::mirror;
  }

  // Casts the shadow rays due for the voxels `grid` saw in its latest collect(); more than
  // kMaxShadowedLights lights: the further ones are never shadowed. `occupancy` is of `volume`
  // as it is now.
  void update_shadows(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                      const fusion::BlockOccupancy& occupancy,
                      const std::vector<render::PointLight>& lights, int frame);
  // From now on, shadow rays test the true scene instead of the fused TSDF: an oracle for
  // synthetic sequences, as ground-truth poses are (`glint reconstruct --gt-visibility`), which
  // measures how much of the refined albedo's error is the visibility the fused geometry gives
  // (occluders whose far sides the camera never saw).
  void use_true_scene(std::shared_ptr<const render::EmbreeScene> scene) {
    true_scene_ = std::move(scene);
  }
  const render::EmbreeScene* true_scene() const { return true_scene_.get(); }
  // From now on, a voxel's indirect irradiance is the true scene's instead of the gather's:
  // Renderer::indirect_irradiance() at its surface point, ray_offset_m off it, with
  // kTrueIndirectPaths paths, once, when it is first due. The oracle of `glint reconstruct
  // --gt-indirect`: it measures how much of the refined albedo's error under bounced light is
  // the gather's (surfaces the camera never saw, their radiance taken as diffuse). The true
  // light is not scaled (indirect_scale() 1).
  void use_true_indirect(std::shared_ptr<const render::Renderer> renderer) {
    true_indirect_ = std::move(renderer);
  }
  // The estimate's relative standard error is the incoming radiance's coefficient of variation
  // over sqrt(512): 4.4 % of it (2,048 paths give office's (c) figures within 0.1 dB).
  static constexpr int kTrueIndirectPaths = 512;
  // Casts the gather rays due for the same voxels.
  void update_indirect(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                       const fusion::BlockOccupancy& occupancy,
                       const std::vector<render::PointLight>& lights, int frame);

  // With IndirectSpecular::mirror: casts the lobe rays of the stored observations of `voxels` that
  // have none yet (a slot's rays are cast again once a newer observation has taken the slot), drawn
  // from eq. (3)'s lobe of width alpha(voxel) (voxels of alpha 0 are left out: they mirror the
  // even sky, as weak lobes do, casts_lobe_rays()).
  void update_mirrors(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                      const fusion::BlockOccupancy& occupancy,
                      const std::vector<render::PointLight>& lights, std::span<const int> voxels,
                      const std::function<float(int)>& alpha);
  // Voxel v's mirrored radiance per stored observation (PointLighting::mirrored) into `radiance`
  // (at least its observation count): the span filled; empty without IndirectSpecular::mirror
  // or while mirror_scale() is 0 (PointLighting::indirect_radiance, then 0, stands in).
  std::span<const Eigen::Vector3f> mirrored(const ObservationGrid& grid, int v,
                                            std::span<Eigen::Vector3f> radiance) const;
  // The mean radiance kPixelLobeRays lobe rays from surface point p (unit normal n) for the view
  // along unit wo meet, times mirror_scale(); NaN where none is known. `queue` is cleared first.
  // A pixel shows its lobe's blur, where one sharp ray would alias.
  static constexpr int kPixelLobeRays = 4;
  Eigen::Vector3f mirror_radiance(fusion::RayQueue& queue, const ObservationGrid& grid,
                                  const fusion::BlockOccupancy& occupancy,
                                  const fusion::TsdfVolume& volume,
                                  const std::vector<render::PointLight>& lights,
                                  const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                                  const Eigen::Vector3f& wo, float alpha,
                                  ObservationGrid::BlockCache& blocks) const;

  // Voxel v's lighting: the lights its shadow rays reach less those the shadow test found
  // occluded, and its indirect light; all lights and no indirect light for what is switched off,
  // not yet cast or not yet estimated.
  PointLighting lighting(int v) const {
    PointLighting result;
    if (params_.shadows && shadow_cast_[v]) result.lit = lit_[v] & ~occluded_[v];
    if (params_.indirect && indirect_estimated_[v]) {
      result.indirect = indirect_[v] * indirect_scale();
      if (params_.indirect_specular != IndirectSpecular::off)
        result.indirect_radiance = result.indirect / float(M_PI);
    }
    return result;
  }
  // The factor on the radiance the lobe rays meet: the scene scale up to 1. A rendering without
  // bounced light (scale 0) mirrors nothing either; above 1 the scale makes up gather rays that
  // met nothing known, which a lobe ray that met a known surface did not lose.
  float mirror_scale() const { return std::min(indirect_scale(), 1.0f); }
  // Voxel v's gathered indirect irradiance before the scene scale (zero where not estimated).
  Eigen::Vector3f gathered(int v) const {
    return params_.indirect && indirect_estimated_[v] ? indirect_[v] : Eigen::Vector3f::Zero();
  }
  // The scene scale of the gathered light (LightTransportParams::indirect_scaled; 1 without the
  // gather or the scale).
  float indirect_scale() const { return scales_gather() ? scale_ : 1.0f; }
  // Whether the scene scale sits at indirect_scale_max: where no light reaches, surfaces are
  // typically at least that many times as bright as the gathered light explains. With real
  // input that can mean a source the lights leave out (a lamp, a window), or much light bounced
  // from surfaces never seen.
  bool indirect_scale_capped() const {
    return scales_gather() && scale_ >= params_.indirect_scale_max;
  }
  // Whether the gathered light is scaled: the gather on, scaled, and not the true scene's.
  bool scales_gather() const {
    return params_.indirect && params_.indirect_scaled && !true_indirect_;
  }
  // The scaled gather's relative error at one voxel: the spread of the scale's samples over
  // their median (1.4826 MAD / median); 0 before the scale has enough samples, where their
  // median is 0, or where the gather is not scaled. It also counts what else scatters their
  // albedos (normals, textures), so it errs high.
  float indirect_error() const { return indirect_error_; }
  // Adds samples of E_true / E_gathered from voxels no light reaches directly and updates the
  // scale and indirect_error() (where scales_gather()).
  void add_indirect_scale_samples(std::span<const float> samples);
  static constexpr std::size_t kIndirectScaleSamples = 1024;
  // The lights voxel v's shadow rays reach (all before they are cast, or without shadows),
  // before the albedo test.
  LightMask cast_lights(int v) const {
    return params_.shadows && shadow_cast_[v] ? lit_[v] : kAllLights;
  }
  // The lights the albedo test found occluded at voxel v (params().shadow_test): lighting()
  // leaves them out. Each voxel from one thread at a time.
  void set_occluded(int v, LightMask lights) { occluded_[v] = lights; }
  LightMask occluded(int v) const { return params_.shadows ? occluded_[v] : 0; }
  // The same with its segment's unseen irradiance added to the indirect light.
  PointLighting lighting(int v, int segment) const {
    PointLighting result = lighting(v);
    result.indirect += unseen(segment);
    return result;
  }
  // A segment's unseen irradiance (zero before its first fit, or with unseen off).
  Eigen::Vector3f unseen(int segment) const {
    if (segment < 0 || std::size_t(segment) >= unseen_.size()) return Eigen::Vector3f::Zero();
    return unseen_irradiance(unseen_[std::size_t(segment)].line, params_.unseen_fit.min_share);
  }
  // Fuses one frame's fit of a segment's radiance line (fit_radiance_line()).
  void fuse_unseen(int segment, const RadianceLine& line);
  // Rays counted in voxel v's own indirect estimate (not its neighbours' it pools).
  int indirect_rays(int v) const { return indirect_rays_[v]; }
  // The plane that gather and lobe rays leaving the reconstruction meet beyond it (not known():
  // none; ContinuedPlane).
  void set_continued_plane(const ContinuedPlane& plane) { plane_ = plane; }
  const ContinuedPlane& continued_plane() const { return plane_; }

 private:
  LightTransportParams params_;
  PoolArray<LightMask> lit_;
  PoolArray<bool> shadow_cast_;
  PoolArray<LightMask> occluded_;
  PoolArray<Eigen::Vector3f> indirect_sum_;  // sum of the counted rays' radiance
  PoolArray<std::uint16_t> indirect_rays_;   // rays counted, at most indirect_rays
  PoolArray<std::uint32_t> indirect_next_;   // index of the next direction in the voxel's sequence
  PoolArray<Eigen::Vector3f> indirect_;      // the estimate lighting() gives, where ...
  PoolArray<bool> indirect_estimated_;       // ... it holds indirect_min_rays
  // Per observation slot (ObservationGrid::first_slot()): the mean radiance its lobe rays met
  // (binary16), whether any met a known one, and the frame + 1 of the observation they were
  // cast for (0: none).
  struct MirrorSample {
    std::uint32_t tag = 0;
    std::array<std::uint16_t, 3> radiance{};
    bool known = false;
  };
  PoolArray<MirrorSample> mirror_;
  // indirect_ of the due voxels from the rays gathered so far (their own or their pool's).
  void estimate_indirect(const ObservationGrid& grid);
  std::vector<int> due_;  // scratch: the voxels due in a frame
  ContinuedPlane plane_;
  std::shared_ptr<const render::EmbreeScene> true_scene_;
  std::shared_ptr<const render::Renderer> true_indirect_;
  // Per segment id: its fused radiance line and the frames fused into it.
  struct FusedLine {
    RadianceLine line;
    int frames = 0;
  };
  std::vector<FusedLine> unseen_;
  float scale_ = 0;                   // indirect_scale() where scales_gather()
  float indirect_error_ = 0;          // indirect_error()
  std::vector<float> scale_samples_;  // a ring of the latest kIndirectScaleSamples
  std::size_t scale_next_ = 0;
  std::vector<float> scale_scratch_;
};

// Whether voxel u's gather rays count in the indirect estimate of voxel v (surface points p,
// unit normals n): u is on v's surface, its normal within acos(0.9) = 26 degrees of v's and its
// point within half a voxel of v's tangent plane; a crease or a thin object's far side is not.
inline bool pools_indirect_rays(const Eigen::Vector3f& p_v, const Eigen::Vector3f& n_v,
                                const Eigen::Vector3f& p_u, const Eigen::Vector3f& n_u,
                                float voxel_size_m) {
  return n_v.dot(n_u) >= 0.9f && std::abs(n_v.dot(p_u - p_v)) <= 0.5f * voxel_size_m;
}

// Surface point p's shadow rays (unit normal n): one per light in front of it, from
// p + offset_m * n, ending short of the light's proxy sphere (the lamp itself is in the fused
// depth of a synthetic sequence). Queued in light order from ray `first`; `queued` holds their
// lights.
struct ShadowRays {
  int first = 0;
  LightMask queued = 0;
};
ShadowRays queue_shadow_rays(fusion::RayQueue& queue, const fusion::TsdfVolume& volume,
                             const std::vector<render::PointLight>& lights,
                             const Eigen::Vector3f& p, const Eigen::Vector3f& n, float offset_m);
// The lights that reach the point once `queue` has marched its rays: those not queued (behind
// the surface, or beyond kMaxShadowedLights) and those whose ray met no surface.
LightMask shadow_mask(const fusion::RayQueue& queue, const ShadowRays& rays);
// The same rays tested against the true scene's objects.
LightMask true_shadow_mask(const render::EmbreeScene& scene, const fusion::TsdfVolume& volume,
                           const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                           const Eigen::Vector3f& n, float offset_m);
// Of the lights in `lit`, those whose shadow ray from p grazes fused geometry: passes through an
// allocated block of `volume` (the block of the nearest voxel, as the TSDF's samples take it)
// from skip_m along it to margin_m short of its end (LightTransportParams::shadow_test).
LightMask grazing_lights(const fusion::BlockOccupancy& occupancy, const fusion::TsdfVolume& volume,
                         const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                         const Eigen::Vector3f& n, LightMask lit,
                         const LightTransportParams& params);
// Both for one point (the queue is cleared first).
LightMask shadow_mask(fusion::RayQueue& queue, const fusion::TsdfVolume& volume,
                      const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                      const Eigen::Vector3f& n, float offset_m);

// The lighting of an arbitrary surface point (a re-rendering's pixel): shadow rays of its own,
// and the indirect irradiance of the observation voxel that holds it. One per thread.
class PointLightingQuery {
 public:
  PointLightingQuery(const LightTransport& transport, const ObservationGrid& grid,
                     const fusion::TsdfVolume& volume, const fusion::BlockOccupancy& occupancy,
                     const std::vector<render::PointLight>& lights)
      : transport_(transport),
        grid_(grid),
        volume_(volume),
        occupancy_(occupancy),
        lights_(lights),
        rays_(volume, &occupancy) {}
  // With IndirectSpecular::mirror, `eye` (the viewpoint) and the lobe's width `alpha` give the lobe
  // rays whose radiance it reflects (PointLighting::indirect_radiance); alpha 0: the even sky.
  PointLighting operator()(const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                           const Eigen::Vector3f& eye, float alpha);

 private:
  const LightTransport& transport_;
  const ObservationGrid& grid_;
  const fusion::TsdfVolume& volume_;
  const fusion::BlockOccupancy& occupancy_;
  const std::vector<render::PointLight>& lights_;
  fusion::RayQueue rays_;
  ObservationGrid::BlockCache blocks_;
};

}  // namespace glint::reflectance
