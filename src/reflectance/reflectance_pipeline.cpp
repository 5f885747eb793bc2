#include "reflectance/reflectance_pipeline.h"

#include <string>

#include "core/error.h"
#include "core/parallel.h"
#include "reflectance/albedo_refinement.h"

namespace glint::reflectance {

ReflectancePipeline::ReflectancePipeline(const Intrinsics& intrinsics,
                                         const ReflectanceParams& params, const HemiCnn& network,
                                         std::vector<render::PointLight> lights)
    : intrinsics_(intrinsics),
      params_(params),
      geometry_(intrinsics, params.geometry),
      grid_(params.observations),
      segment_map_(params.segments),
      specular_(network, params.specular),
      lights_(std::move(lights)) {
  if (lights_.empty())
    throw Error("reflectance pipeline", "lights",
                "needs at least one light (estimate them with `glint lights`)");
}

void ReflectancePipeline::refine_albedo_of_visible() {
  const std::vector<VisibleVoxel>& visible = grid_.visible();
  parallel_for(visible.size(), [&](std::size_t i) {
    const int v = visible[i].voxel;
    const SegmentMaterial* material = specular_.material(grid_.segment(v));
    if (!material) return;
    const auto kd =
        refine_albedo(grid_.observations(v), grid_.observation_count(v), grid_.position(v),
                      grid_.normal(v), lights_, material->ward.ks, material->ward.alpha);
    // Each voxel is written by one iteration only: the visible list holds it once.
    grid_.has_refined_kd(v) = kd.has_value();
    if (kd) grid_.refined_kd(v) = kd->cwiseMax(0.0f).cwiseMin(1.0f);
  });
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
    const DepthSegmentation segmentation =
        segment_depth(frame.depth_m, intrinsics_, params_.segmentation);
    segment_map_.update(grid_, grid_.visible(), segmentation.labels, false);
  }
  result.segments = int(segment_map_.frame_segments().size());
  timings_.add("segmentation", stage.elapsed_ms());

  stage.restart();
  specular_.update(grid_, segment_map_, segment_map_.frame_segments(), frame_);
  timings_.add("specular", stage.elapsed_ms());

  stage.restart();
  refine_albedo_of_visible();
  timings_.add("albedo", stage.elapsed_ms());
  timings_.add("total", total.elapsed_ms());
  ++frame_;
  return result;
}

}  // namespace glint::reflectance
