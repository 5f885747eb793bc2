#pragma once
// The online reflectance pipeline (paper 1 §3, Fig. 1), one call per RGB-D frame:
//   geometry      TSDF fusion with tracking or ground-truth poses (fusion/fusion_pipeline.h)
//   observations  the coarse observation grid collects (radiance, direction) pairs (§3.4)
//   segmentation  per-frame depth segmentation, propagated to global segment ids (§3.5), or
//                 the sequence's ground-truth segment ids
//   shadows       which lights reach each seen voxel, by shadow rays through the TSDF (glint's
//                 addition, reflectance/light_transport.h)
//   indirect      each seen voxel's indirect irradiance, gathered from the observed radiance
//                 of the surfaces around it (glint's addition, the same header)
//   specular      HemiCNN per segment on 25 sampled voxels, fused over time (§3.6)
//   mirror        the lobe rays of the due voxels' new observations: what their lobes mirror
//                 of the bounced light (IndirectSpecular::mirror, the same header)
//   albedo        per-voxel diffuse albedo from eq. (7) with the segment's ks, alpha (§3.7)
// Stage times go into timings() as "geometry", "observations", "segmentation", "shadows",
// "indirect", "specular", "mirror", "albedo" and "total" (milliseconds per frame), the rows of
// paper 1 Tables 2-3 and glint's three.
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "core/timer.h"
#include "fusion/fusion_pipeline.h"
#include "io/rgbd_sequence.h"
#include "reflectance/albedo_refinement.h"
#include "reflectance/depth_segmentation.h"
#include "reflectance/hemicnn.h"
#include "reflectance/light_transport.h"
#include "reflectance/material_maps.h"
#include "reflectance/observation_grid.h"
#include "reflectance/reflectance_volume.h"
#include "reflectance/segment_map.h"
#include "reflectance/specular_estimation.h"
#include "render/scene.h"

namespace glint::reflectance {

struct ReflectanceParams {
  fusion::FusionParams geometry{.volume = reflectance_volume_params(), .tracking = {}};
  // Observations 1 degree apart at least (ObservationGridParams::min_observation_spacing_deg):
  // far voxels otherwise fill their slots with near-duplicate views; or 2 frames apart
  // (spacing_max_frames), so a slow hand-held camera still collects enough (docs/decisions.md).
  ObservationGridParams observations{.min_observation_spacing_deg = 1.0, .spacing_max_frames = 2};
  DepthSegmentationParams segmentation;  // min_segment_px at full resolution
  // The depth segmentation runs on the depth image halved this many times (KinectFusion's
  // edge-preserving block average, fusion/depth_maps.h): a quarter of the pixels per level,
  // and smoother normals on noisy sensors; voxels look their label up at the coarser pixel.
  int segmentation_halvings = 1;
  SegmentMapParams segments;
  // Shadows and interreflections: eq. (7), the hemi-images and the lobe fit count only the
  // lights that reach a voxel, and its indirect irradiance (reflectance/light_transport.h).
  LightTransportParams light_transport;
  SpecularParams specular;
  // Each visible voxel's albedo is re-solved every this many frames (staggered over the voxels;
  // a voxel without one is solved at once): one new observation of up to 30 moves the mean
  // little, and the paper's per-frame cost on a GPU is 4x ours per voxel on 2 CPU cores.
  int albedo_refresh_frames = 4;
  // How a voxel's per-observation albedos are combined (reflectance/albedo_refinement.h). The
  // median resists observations whose highlight ks, alpha mispredict; it departs from the
  // paper's mean, which --albedo-average mean restores.
  AlbedoAverage albedo_average = AlbedoAverage::median;
  // Whether eq. (7) takes observations with a clipped channel where a voxel has others too (the
  // paper). By default they are left out: a clipped channel's albedo comes out too dark
  // (observe_diffuse()).
  bool albedo_keep_clipped = false;
  // A voxel whose albedo was solved under light more grazing than this effective incidence
  // cosine (RefinedAlbedo::light_cosine()) is unreliable: the re-rendering interpolates the
  // reliable voxels around it instead where there are any (reflectance/material_maps.h). 0.2
  // (78 degrees) is where a 2-degree normal error makes a 17 % albedo error; it was not tuned.
  // It also sets the weight of the segment's refined albedo in the blend (albedo_blend()).
  // 0 trusts every voxel and blends in no segment albedo, as the paper does.
  float albedo_min_light_cosine = 0.2f;
  // A voxel whose refined albedo (its largest channel) is under 1/this of its segment's
  // reference albedo (update_albedo_references()), or over this times it, is unreliable too: the
  // image model does not explain its observations. The usual cause is a shadow the fused geometry
  // cannot cast, because the occluder's far side was never in view, so the shadow ray passes
  // through it and eq. (7) divides a black pixel by a light that never reached it. 3: a shadow
  // leaves the indirect light, well under a third of the direct, and few textures reach a third
  // of their mean. 0 trusts such voxels, as the paper.
  float albedo_max_ratio = 3.0f;
  // A voxel whose irradiance is more than this share gathered indirect light is unreliable too:
  // the gather is an estimate (emitters taken as diffuse, surfaces never seen as dark, 64 rays
  // of Monte Carlo noise), and where it is most of what eq. (7) divides by, its error is most of
  // the albedo's. Such voxels, mostly in shadow, take the albedo of their lit neighbours or
  // segment instead. 1 trusts them all.
  float albedo_max_indirect_share = 0.5f;
  // Pull a voxel's refined albedo towards its segment's by how much its own error exceeds the
  // segment's spread of albedo (shrink_albedo(), albedo_error()): how its observations scatter
  // (a voxel across two faces, a misfit lobe), its normal's error under the light's angle
  // (albedo_normal_error) and the gathered light's error (LightTransport::indirect_error(),
  // smooth blotches where it is much of the irradiance). Texture, consistent across the
  // observations, stays. false: eq. (7) as is.
  bool albedo_shrinkage = true;
  // The shrinkage's third error: the voxel normal's, in radians, which eq. (7) turns into a
  // relative albedo error of t times it (RefinedAlbedo::light_tangent): under grazing light the
  // voxel takes more of its segment's brightness. 0.05 (3 degrees) puts the shrinkage's reliable
  // voxels (albedo error <= kSpreadMaxError) at light of 45 degrees or steeper, t <= 1, where
  // refined_albedo_weight() stops weighing by the light too (docs/decisions.md).
  float albedo_normal_error = 0.05f;
  // Re-renderings and the mesh smooth the refined albedo between neighbouring voxels that agree
  // to about this relative contrast (interpolate_refined_kd in reflectance/material_maps.h);
  // 0 interpolates trilinearly only, as the paper. On a uniform surface a voxel's eq. (7) albedo
  // scatters by a few per cent; 0.2 rather than no limit keeps textures' contrast
  // (docs/decisions.md).
  float albedo_smoothing = 0.2f;
  // Radiance = pixel colour / exposure; the lights are in the same radiance units
  // (reflectance/light_estimation.h).
  float exposure = 1;
};

struct ReflectanceFrame {
  fusion::FrameResult geometry;
  int observed_voxels = 0;
  int segments = 0;  // global segments seen in this frame
};

class ReflectancePipeline {
 public:
  ReflectancePipeline(const Intrinsics& intrinsics, const ReflectanceParams& params,
                      const HemiCnn& network, std::vector<render::PointLight> lights);

  // One frame. ground_truth_segments: per-pixel object ids (the synthetic gt/segment image) to
  // use instead of the depth segmentation, or nullptr. Throws glint::Error for a frame that
  // does not fit (sizes) or an exhausted pool.
  ReflectanceFrame process(const io::RgbdFrame& frame,
                           const Image<std::int32_t>* ground_truth_segments = nullptr);

  const fusion::TsdfVolume& geometry() const { return geometry_.volume(); }
  // Where the geometry's TSDF integration runs: "cpu" or "cuda".
  const char* integration_device() const { return geometry_.integration_device(); }
  const ObservationGrid& observations() const { return grid_; }
  const SegmentMap& segments() const { return segment_map_; }
  const SpecularEstimator& materials() const { return specular_; }
  const LightTransport& light_transport() const { return transport_; }
  // Shadow rays against the true scene from now on (LightTransport::use_true_scene()).
  void use_true_visibility(std::shared_ptr<const render::EmbreeScene> scene) {
    transport_.use_true_scene(std::move(scene));
  }
  // Indirect irradiance from the true scene's path tracer (LightTransport::use_true_indirect()).
  void use_true_indirect(std::shared_ptr<const render::Renderer> renderer) {
    transport_.use_true_indirect(std::move(renderer));
  }
  const std::vector<render::PointLight>& lights() const { return lights_; }
  const StageTimings& timings() const { return timings_; }
  // The geometry stage's parts: "track", "raycast" (the model tracking aligns to; both only
  // without ground-truth poses), "allocate_blocks", "integrate".
  const StageTimings& geometry_timings() const { return geometry_.timings(); }
  const Intrinsics& intrinsics() const { return intrinsics_; }
  float exposure() const { return params_.exposure; }
  // How re-renderings and the mesh blend the refined albedos: the smoothing above, and the
  // segment's refined albedo as one more voxel weighing as much as one solved under light at the
  // reliability threshold (albedo_min_light_cosine; none where that is 0, as the paper).
  AlbedoBlend albedo_blend() const {
    return {params_.albedo_smoothing,
            refined_albedo_weight(tangent_of(params_.albedo_min_light_cosine))};
  }
  int frames_processed() const { return frame_; }

 private:
  // The voxels whose albedo is due this frame (albedo_due_).
  void collect_albedo_due();
  // Hands the light transport the largest plane so far, with its segment's kd (ContinuedPlane),
  // every kPlaneEveryFrames frames: a floor changes little from frame to frame.
  void continue_largest_plane();
  static constexpr int kPlaneEveryFrames = 4;
  // Solves the due voxels' albedo (eq. 7), and fuses each segment's mean over its reliable ones
  // into its SegmentMaterial::kd_refined: the albedo a re-rendering falls back on where no voxel
  // nearby has one (unlit or unobserved parts; the paper assumes a segment homogeneous).
  // `occupancy`: of the geometry as it is now, for the shadow test (null without shadows).
  void refine_albedo_of_visible(const fusion::BlockOccupancy* occupancy);
  // The lights to leave out of voxel v's eq. (7), by the shadow test
  // (LightTransportParams::shadow_test): `observed` is under `lighting` (its cast lights) and
  // becomes the observation under those it keeps.
  LightMask test_shadows(int v, const SegmentMaterial& material, float reference,
                         const PointLighting& lighting, const fusion::BlockOccupancy& occupancy,
                         float clipped, DiffuseObservation& observed) const;
  // The depth segmentation's labels at full resolution: the segmenter's own without halvings,
  // else frame_labels_ filled from the coarse ones.
  const Image<std::int32_t>& segment_frame(const ImageF& depth_m);

  Intrinsics intrinsics_;
  ReflectanceParams params_;
  fusion::FusionPipeline geometry_;
  ObservationGrid grid_;
  SegmentMap segment_map_;
  DepthSegmenter depth_segmenter_;    // at the resolution segmentation_halvings gives
  Image<std::int32_t> frame_labels_;  // scratch of segment_frame()
  SpecularEstimator specular_;
  LightTransport transport_;
  std::vector<render::PointLight> lights_;
  StageTimings timings_;
  // Groups `values` (one per due voxel) by `segment_of` (-1: none) and calls visit(segment, its
  // values, free to reorder) for each segment with at least kMinReferenceVoxels of them.
  void for_each_segment_sample(const std::vector<int>& segment_of, const std::vector<float>& values,
                               int segments,
                               const std::function<void(int, std::span<float>)>& visit);
  // Updates each segment's reference albedo for the test of judge_albedo() in the next
  // frame, as its largest channel: the median over this frame's due voxels of their albedos
  // solved under trusted light, where the segment has at least kMinReferenceVoxels of them;
  // else it keeps its last one (before any, the test takes the segment's HemiCNN albedo). A
  // median, since the voxels in shadows the geometry cannot cast are a minority of a segment,
  // and the network's albedo can be off by more than the ratio (a dark object read as grey).
  void update_albedo_references(int segments);
  static constexpr int kMinReferenceVoxels = 16;
  // Updates each segment's spread of log brightness (ReflectanceParams::albedo_shrinkage) for the
  // next frame: 1.4826 MAD of log(largest channel / reference) over this frame's due voxels whose
  // albedo error (albedo_error()) is at most kSpreadMaxError, where the segment has at least
  // kMinReferenceVoxels of them; else it keeps its last one. 5 %: voxels observed consistently,
  // lit mostly directly and at 45 degrees or steeper, whose spread is the segment's texture and
  // noise (not tuned).
  void update_albedo_spreads(int segments);
  static constexpr float kSpreadMaxError = 0.05f;
  // Fits each segment's unseen irradiance (reflectance/unseen_light.h) to this frame's due
  // voxels that are neither clipped nor under grazing light, and fuses it for the next frames.
  void fit_unseen_light(int segments);

  // Scratch of refine_albedo_of_visible(): the due voxels; their trusted albedos and segments
  // (-1: none); their known irradiance and diffuse radiance and segments (-1: not for the
  // unseen-light fit); one of those segment lists grouped by segment.
  std::vector<int> albedo_due_, due_segment_;
  std::vector<float> due_albedo_, by_segment_;
  // Per due voxel no light reaches directly: its albedo under the gathered light alone over its
  // segment's reference (NaN: not a sample).
  std::vector<float> scale_samples_;
  std::vector<int> fit_segment_;
  std::vector<Eigen::Vector3f> fit_irradiance_, fit_radiance_, grouped_irradiance_,
      grouped_radiance_;
  std::vector<int> segment_starts_, segment_fill_, segment_order_, fit_order_;
  // Per due voxel: its segment (-1: none) and log brightness over the reference, for
  // update_albedo_spreads().
  std::vector<int> spread_segment_;
  std::vector<float> spread_sample_;
  std::vector<float> albedo_reference_;  // per segment id; NaN: none yet
  std::vector<float> albedo_spread_;     // per segment id; NaN: none yet
  int frame_ = 0;
};

}  // namespace glint::reflectance
