#include "reflectance/reflectance_pipeline.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <span>
#include <string>

#include "core/error.h"
#include "core/parallel.h"
#include "core/robust_statistics.h"
#include "fusion/block_occupancy.h"
#include "fusion/depth_maps.h"
#include "reflectance/albedo_refinement.h"

namespace glint::reflectance {
namespace {

// The radiance above which an observation has clipped: an 8-bit (or normalised) pixel saturates
// at 1, which is radiance 1 / exposure; 0.99 allows for rounding.
float saturated_radiance(float exposure) { return 0.99f / exposure; }

// The lobe fit leaves out clipped observations (or takes them as bounds).
SpecularParams with_saturation(SpecularParams params, float exposure) {
  params.fit.saturated_radiance = saturated_radiance(exposure);
  return params;
}

// Clipped emitters count as dark in the indirect gather.
LightTransportParams with_saturation(LightTransportParams params, float exposure) {
  params.saturated_radiance = saturated_radiance(exposure);
  return params;
}

// min_segment_px is given at full resolution; each halving quarters it.
DepthSegmentationParams halved_segmentation_params(const ReflectanceParams& params) {
  DepthSegmentationParams halved = params.segmentation;
  for (int level = 0; level < params.segmentation_halvings; ++level)
    halved.min_segment_px = std::max(1, halved.min_segment_px / 4);
  return halved;
}

// The indices i with segment_of[i] > 0 grouped by segment (a counting sort): segment s's are
// order[starts[s], starts[s + 1]). `fill` is scratch.
void group_by_segment(const std::vector<int>& segment_of, int segments, std::vector<int>& starts,
                      std::vector<int>& fill, std::vector<int>& order) {
  starts.assign(std::size_t(segments) + 1, 0);
  for (const int segment : segment_of)
    if (segment > 0) ++starts[std::size_t(segment)];
  std::exclusive_scan(starts.begin(), starts.end(), starts.begin(), 0);
  order.resize(std::size_t(starts.back()));
  fill.assign(starts.begin(), starts.end() - 1);
  for (std::size_t i = 0; i < segment_of.size(); ++i)
    if (const int segment = segment_of[i]; segment > 0)
      order[std::size_t(fill[std::size_t(segment)]++)] = int(i);
}

}  // namespace

ReflectancePipeline::ReflectancePipeline(const Intrinsics& intrinsics,
                                         const ReflectanceParams& params, const HemiCnn& network,
                                         std::vector<render::PointLight> lights)
    : intrinsics_(intrinsics),
      params_(params),
      geometry_(intrinsics, params.geometry),
      grid_(params.observations),
      segment_map_(params.segments),
      depth_segmenter_(halved_segmentation_params(params)),
      specular_(network, with_saturation(params.specular, params.exposure)),
      transport_(with_saturation(params.light_transport, params.exposure), grid_.voxel_pool_size(),
                 grid_.params().observations_per_voxel),
      lights_(std::move(lights)) {
  if (params.albedo_refresh_frames < 1)
    throw Error("reflectance pipeline", "albedo_refresh_frames", "must be >= 1");
  if (!(params.albedo_min_light_cosine >= 0 && params.albedo_min_light_cosine <= 1))
    throw Error("reflectance pipeline", "albedo_min_light_cosine", "must be in [0, 1]");
  if (!(params.albedo_max_ratio == 0 || params.albedo_max_ratio >= 1))
    throw Error("reflectance pipeline", "albedo_max_ratio", "must be 0 (off) or >= 1");
  if (!(params.albedo_max_indirect_share >= 0 && params.albedo_max_indirect_share <= 1))
    throw Error("reflectance pipeline", "albedo_max_indirect_share", "must be in [0, 1]");
  if (!(params.albedo_normal_error >= 0 && std::isfinite(params.albedo_normal_error)))
    throw Error("reflectance pipeline", "albedo_normal_error", "must be finite and >= 0");
  if (!(params.albedo_smoothing >= 0 && std::isfinite(params.albedo_smoothing)))
    throw Error("reflectance pipeline", "albedo_smoothing", "must be finite and >= 0");
  if (lights_.empty())
    throw Error("reflectance pipeline", "lights",
                "needs at least one light (estimate them with `glint lights`)");
}

LightMask ReflectancePipeline::test_shadows(int v, const SegmentMaterial& material, float reference,
                                            const PointLighting& lighting,
                                            const fusion::BlockOccupancy& occupancy, float clipped,
                                            DiffuseObservation& observed) const {
  const LightTransportParams& params = transport_.params();
  const int segment = grid_.segment(v);
  // |log| of the ratio of the albedo (largest channel) to the reference.
  const auto misfit = [&](const DiffuseObservation& candidate) {
    const auto solved = solve_albedo(candidate, transport_.unseen(segment));
    return solved && solved->kd.maxCoeff() > 0
               ? std::abs(std::log(solved->kd.maxCoeff() / reference))
               : INFINITY;
  };
  float best = misfit(observed);
  // The ratio widens by the albedo's uncertainty from the gathered light
  // (LightTransportParams::shadow_test_sigmas).
  const float share = observed.cosines > 0 ? observed.indirect / observed.cosines : 0.0f;
  if (!(best > std::log(params.shadow_test_ratio) +
                   params.shadow_test_sigmas * share * transport_.indirect_error()))
    return 0;
  const LightMask candidates =
      grazing_lights(occupancy, geometry_.volume(), lights_, grid_.position(v), grid_.normal(v),
                     lighting.lit, params);
  LightMask dropped = 0;
  for (LightMask left = candidates; left != 0; left &= left - 1) {
    const LightMask light = left & -left;
    PointLighting without = lighting;
    without.lit &= ~light;
    const auto candidate = observe_diffuse(
        grid_.observations(v), grid_.observation_count(v), grid_.position(v), grid_.normal(v),
        lights_, material.ward.ks, material.ward.alpha, params_.albedo_average, clipped, without);
    if (!candidate) continue;
    const float fit = misfit(*candidate);
    if (fit < best - std::log(params.shadow_test_gain)) {
      best = fit;
      dropped = light;
      observed = *candidate;
    }
  }
  return dropped;
}

void ReflectancePipeline::continue_largest_plane() {
  // A plane as thick as an observation voxel: its voxels' positions scatter by less.
  transport_.set_continued_plane(
      largest_plane(grid_, float(grid_.params().voxel_size_m), [&](int segment) {
        const SegmentMaterial* material = specular_.material(segment);
        return material ? material->ward.kd : Eigen::Vector3f::Constant(NAN);
      }));
}

void ReflectancePipeline::collect_albedo_due() {
  // Due: voxels never refined, and those whose turn in the refresh cycle it is.
  albedo_due_.clear();
  for (const VisibleVoxel& seen : grid_.visible())
    if (!grid_.has_refined_kd(seen.voxel) ||
        (seen.voxel + frame_) % params_.albedo_refresh_frames == 0)
      albedo_due_.push_back(seen.voxel);
}

void ReflectancePipeline::refine_albedo_of_visible(const fusion::BlockOccupancy* occupancy) {
  // The stage waits on memory more than it computes (1.3 us per voxel on office against 0.4 us
  // with its data in cache), so each chunk runs a two-stage prefetch: a voxel's own state
  // kVoxelAhead iterations early, then, once that has arrived, its observations.
  constexpr std::size_t kVoxelAhead = 8, kObservationsAhead = 3;
  // Per thread and segment: the sum of the reliable refined kd (rgb) and their count. The sums
  // are in fixed point (kd in [0, 1] in steps of 2^-24), so that they add up to the same total
  // whichever thread took which voxels: a run's result does not depend on the scheduling.
  using FixedSums = Eigen::Matrix<std::int64_t, 4, 1>;
  constexpr double kFixedOne = double(1 << 24);
  const int segments = segment_map_.max_segment_id() + 1;
  tbb::enumerable_thread_specific<std::vector<FixedSums>> sums(std::size_t(segments),
                                                               FixedSums::Zero());
  // Observations at or above this radiance have clipped (observe_diffuse() leaves them out).
  const float clipped =
      params_.albedo_keep_clipped ? INFINITY : saturated_radiance(params_.exposure);
  // The references of the frames before (update_albedo_references()); a segment without one
  // yet is measured against its HemiCNN albedo.
  albedo_reference_.resize(std::size_t(segments), NAN);
  // Per due voxel, the largest channel of its albedo where the light it was solved under can be
  // trusted (not grazing, not mostly the gathered indirect light), and its segment, else -1:
  // this frame's contribution to the references.
  due_albedo_.resize(albedo_due_.size());
  due_segment_.assign(albedo_due_.size(), -1);
  // The unseen-light fit takes the due voxels solved under light that is not grazing (as
  // trusted ones are), whatever share of it is indirect: the shadowed ones give its intercept.
  const bool fit_unseen = transport_.params().unseen;
  const float max_light_tangent = tangent_of(params_.albedo_min_light_cosine);
  fit_segment_.assign(fit_unseen ? albedo_due_.size() : 0, -1);
  fit_irradiance_.resize(fit_segment_.size());
  fit_radiance_.resize(fit_segment_.size());
  const bool shadow_test =
      occupancy && transport_.params().shadows && transport_.params().shadow_test;
  const bool scale_gather = transport_.scales_gather();
  const bool shrink = params_.albedo_shrinkage;
  const float gather_error = transport_.indirect_error();
  albedo_spread_.resize(std::size_t(segments), NAN);
  spread_segment_.assign(shrink ? albedo_due_.size() : 0, -1);
  spread_sample_.resize(spread_segment_.size());
  scale_samples_.assign(scale_gather ? albedo_due_.size() : 0, NAN);
  parallel_for_chunks(albedo_due_.size(), 64, [&](std::size_t begin, std::size_t end) {
    std::vector<FixedSums>& segment_sums = sums.local();
    std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> mirrored;
    for (std::size_t i = begin; i < std::min(begin + kVoxelAhead, end); ++i)
      grid_.prefetch_voxel(albedo_due_[i]);
    for (std::size_t i = begin; i < end; ++i) {
      if (i + kVoxelAhead < end) grid_.prefetch_voxel(albedo_due_[i + kVoxelAhead]);
      if (i + kObservationsAhead < end)
        grid_.prefetch_observations(albedo_due_[i + kObservationsAhead], false);
      const int v = albedo_due_[i];
      const int segment = grid_.segment(v);
      const SegmentMaterial* material = specular_.material(segment);
      if (!material) continue;
      const bool in_map = segment > 0 && segment < segments;
      const bool known = in_map && !std::isnan(albedo_reference_[std::size_t(segment)]);
      PointLighting lighting = transport_.lighting(v);
      if (shadow_test) lighting.lit = transport_.cast_lights(v);
      lighting.mirrored = transport_.mirrored(grid_, v, mirrored);
      // The voxel's observations under `lighting` less the specular term of `ks` (eq. (7)).
      const auto observe = [&](const Eigen::Vector3f& ks) {
        return observe_diffuse(grid_.observations(v), grid_.observation_count(v), grid_.position(v),
                               grid_.normal(v), lights_, ks, material->ward.alpha,
                               params_.albedo_average, clipped, lighting);
      };
      auto observed = observe(material->ward.ks);
      if (shadow_test) {
        const LightMask dropped =
            observed && known ? test_shadows(v, *material, albedo_reference_[std::size_t(segment)],
                                             lighting, *occupancy, clipped, *observed)
                              : 0;
        transport_.set_occluded(v, dropped);
        lighting.lit &= ~dropped;  // the lights `observed` now answers to
      }
      if (fit_unseen && observed && in_map && !observed->lower_bound &&
          (observed->sines == 0 || observed->sines <= max_light_tangent * observed->cosines)) {
        fit_segment_[i] = segment;
        fit_irradiance_[i] = observed->irradiance;
        fit_radiance_[i] = observed->radiance;
      }
      const float reference =
          known ? albedo_reference_[std::size_t(segment)] : material->ward.kd.maxCoeff();
      if (scale_gather && observed)
        scale_samples_[i] = indirect_scale_sample(*observed, transport_.gathered(v), reference);
      const auto refined =
          observed ? solve_albedo(*observed, transport_.unseen(segment)) : std::nullopt;
      // Each voxel is written by one iteration only: the due list holds it once.
      grid_.has_refined_kd(v) = refined.has_value();
      grid_.refined_kd_reliable(v) = false;
      grid_.light_shortfall(v) = 0;
      if (!refined) continue;
      const Eigen::Vector3f kd = refined->kd.cwiseMax(0.0f).cwiseMin(1.0f);
      // The references, the segment sums and the verdict take the albedo before shrinkage.
      const float error =
          shrink ? albedo_error(*refined, gather_error, params_.albedo_normal_error) : 0.0f;
      grid_.refined_kd(v) =
          known ? shrink_albedo(kd, reference, error, albedo_spread_[std::size_t(segment)]) : kd;
      if (shrink && known && error <= kSpreadMaxError && kd.maxCoeff() > 0) {
        spread_segment_[i] = segment;
        spread_sample_[i] = std::log(kd.maxCoeff() / reference);
      }
      grid_.refined_kd_light_tangent(v) = refined->light_tangent;
      const bool trusted_light = refined->light_cosine() >= params_.albedo_min_light_cosine &&
                                 refined->indirect_share <= params_.albedo_max_indirect_share;
      if (trusted_light && in_map) {
        due_albedo_[i] = kd.maxCoeff();
        due_segment_[i] = segment;
      }
      AlbedoVerdict verdict =
          judge_albedo(kd.maxCoeff(), refined->lower_bound, reference, params_.albedo_max_ratio);
      if (verdict.light_shortfall > 0)
        if (const auto bare = observe(Eigen::Vector3f::Zero()))
          if (const auto without_lobe = solve_albedo(*bare, transport_.unseen(segment)))
            verdict = judge_without_lobe(verdict, without_lobe->kd.maxCoeff(), reference,
                                         params_.albedo_max_ratio);
      grid_.light_shortfall(v) = verdict.light_shortfall;
      if (!verdict.estimate) continue;
      grid_.refined_kd_reliable(v) = trusted_light;
      if (trusted_light && in_map)
        segment_sums[segment] +=
            FixedSums(std::llround(kd.x() * kFixedOne), std::llround(kd.y() * kFixedOne),
                      std::llround(kd.z() * kFixedOne), 1);
    }
  });
  update_albedo_references(segments);
  if (shrink) update_albedo_spreads(segments);
  if (fit_unseen) fit_unseen_light(segments);
  if (scale_gather) {
    std::erase_if(scale_samples_, [](float sample) { return std::isnan(sample); });
    transport_.add_indirect_scale_samples(scale_samples_);
  }
  // Each segment's mean over its voxels solved reliably in this frame, into its
  // SegmentMaterial::kd_refined.
  for (int segment = 1; segment < segments; ++segment) {
    FixedSums sum = FixedSums::Zero();
    for (const auto& local : sums) sum += local[segment];
    if (sum.w() > 0)
      specular_.fuse_refined_albedo(
          segment, (sum.head<3>().cast<double>() / (kFixedOne * double(sum.w()))).cast<float>());
  }
}

void ReflectancePipeline::for_each_segment_sample(
    const std::vector<int>& segment_of, const std::vector<float>& values, int segments,
    const std::function<void(int, std::span<float>)>& visit) {
  group_by_segment(segment_of, segments, segment_starts_, segment_fill_, segment_order_);
  by_segment_.resize(segment_order_.size());
  for (std::size_t k = 0; k < segment_order_.size(); ++k)
    by_segment_[k] = values[std::size_t(segment_order_[k])];
  for (int segment = 1; segment < segments; ++segment) {
    const int first = segment_starts_[std::size_t(segment)];
    const int count = segment_starts_[std::size_t(segment) + 1] - first;
    if (count >= kMinReferenceVoxels)
      visit(segment, std::span<float>(by_segment_.data() + first, std::size_t(count)));
  }
}

void ReflectancePipeline::update_albedo_references(int segments) {
  for_each_segment_sample(due_segment_, due_albedo_, segments,
                          [&](int segment, std::span<float> albedos) {
                            albedo_reference_[std::size_t(segment)] = median_in_place(albedos);
                          });
}

void ReflectancePipeline::update_albedo_spreads(int segments) {
  for_each_segment_sample(spread_segment_, spread_sample_, segments,
                          [&](int segment, std::span<float> samples) {
                            albedo_spread_[std::size_t(segment)] =
                                robust_spread_in_place(samples, median_in_place(samples));
                          });
}

void ReflectancePipeline::fit_unseen_light(int segments) {
  group_by_segment(fit_segment_, segments, segment_starts_, segment_fill_, segment_order_);
  grouped_irradiance_.resize(segment_order_.size());
  grouped_radiance_.resize(segment_order_.size());
  for (std::size_t k = 0; k < segment_order_.size(); ++k) {
    grouped_irradiance_[k] = fit_irradiance_[std::size_t(segment_order_[k])];
    grouped_radiance_[k] = fit_radiance_[std::size_t(segment_order_[k])];
  }
  const LightTransportParams& params = transport_.params();
  for (int segment = 1; segment < segments; ++segment) {
    const std::size_t first = std::size_t(segment_starts_[std::size_t(segment)]);
    const std::size_t count = std::size_t(segment_starts_[std::size_t(segment) + 1]) - first;
    if (const auto line = fit_radiance_line(std::span(grouped_irradiance_).subspan(first, count),
                                            std::span(grouped_radiance_).subspan(first, count),
                                            params.unseen_fit, fit_order_))
      transport_.fuse_unseen(segment, *line);
  }
}

const Image<std::int32_t>& ReflectancePipeline::segment_frame(const ImageF& depth_m) {
  const int shift = params_.segmentation_halvings;
  ImageF halved;
  const ImageF& depth = fusion::halved_depth(
      depth_m, shift, params_.geometry.tracking.bilateral.sigma_depth_m, halved);
  const Image<std::int32_t>& coarse =
      depth_segmenter_.segment(depth, fusion::halved_intrinsics(intrinsics_, shift)).labels;
  if (shift == 0) return coarse;
  // Every full-resolution pixel takes the label of the coarse pixel covering it.
  frame_labels_.ensure_size(depth_m.width(), depth_m.height(), 1);
  parallel_for(std::size_t(depth_m.height()), [&](std::size_t row) {
    const int y = std::min(int(row) >> shift, depth.height() - 1);
    std::int32_t* out = frame_labels_.plane(0) + row * depth_m.width();
    for (int x = 0; x < depth_m.width(); ++x)
      out[x] = coarse.at(std::min(x >> shift, depth.width() - 1), y, 0);
  });
  return frame_labels_;
}

ReflectanceFrame ReflectancePipeline::process(const io::RgbdFrame& frame,
                                              const Image<std::int32_t>* ground_truth_segments) {
  ReflectanceFrame result;
  Stopwatch total, stage;
  result.geometry = geometry_.process(frame);
  timings_.add("geometry", stage.elapsed_ms());
  if (!result.geometry.integrated) {
    timings_.add("total", total.elapsed_ms());
    ++frame_;
    return result;
  }

  stage.restart();
  grid_.collect(frame.depth_m, frame.colour, intrinsics_, result.geometry.camera_to_world,
                params_.exposure, geometry_.volume(), frame_);
  result.observed_voxels = int(grid_.visible().size());
  timings_.add("observations", stage.elapsed_ms());

  stage.restart();
  if (ground_truth_segments) {
    if (ground_truth_segments->width() != frame.depth_m.width() ||
        ground_truth_segments->height() != frame.depth_m.height())
      throw Error("reflectance pipeline", "frame " + std::to_string(frame.index),
                  "ground-truth segment image differs in size from the depth image");
    segment_map_.update(grid_, grid_.visible(), *ground_truth_segments, true);
  } else {
    segment_map_.update(grid_, grid_.visible(), segment_frame(frame.depth_m), false);
  }
  result.segments = int(segment_map_.frame_segments().size());
  timings_.add("segmentation", stage.elapsed_ms());

  stage.restart();
  std::optional<fusion::BlockOccupancy> occupancy;
  if (transport_.enabled()) {
    occupancy.emplace(geometry_.volume());
    transport_.update_shadows(grid_, geometry_.volume(), *occupancy, lights_, frame_);
    timings_.add("shadows", stage.elapsed_ms());
    stage.restart();
    if (transport_.params().indirect && transport_.params().continue_plane &&
        frame_ % kPlaneEveryFrames == 0)
      continue_largest_plane();
    transport_.update_indirect(grid_, geometry_.volume(), *occupancy, lights_, frame_);
    timings_.add("indirect", stage.elapsed_ms());
    stage.restart();
  }
  specular_.update(grid_, segment_map_, segment_map_.frame_segments(), lights_, frame_,
                   &transport_);
  timings_.add("specular", stage.elapsed_ms());

  stage.restart();
  collect_albedo_due();
  if (occupancy) {
    transport_.update_mirrors(
        grid_, geometry_.volume(), *occupancy, lights_, albedo_due_, [&](int v) {
          const SegmentMaterial* material = specular_.material(grid_.segment(v));
          return material ? lobe_ray_alpha(material->ward) : 0.0f;
        });
    timings_.add("mirror", stage.elapsed_ms());
    stage.restart();
  }
  refine_albedo_of_visible(occupancy ? &*occupancy : nullptr);
  timings_.add("albedo", stage.elapsed_ms());
  timings_.add("total", total.elapsed_ms());
  ++frame_;
  return result;
}

}  // namespace glint::reflectance
