#include "reflectance/specular_estimation.h"

#include <tbb/parallel_for_each.h>

#include <algorithm>

#include "core/error.h"
#include "core/log.h"
#include "render/perceptual.h"

namespace glint::reflectance {
namespace {

using Parameters = ClampedRunningMean<7>::Vector;

Parameters to_vector(const render::WardMaterial& m) {
  Parameters p;
  p << m.kd, m.ks, m.alpha;
  return p;
}

render::WardMaterial to_material(const Parameters& p) {
  render::WardMaterial m;
  m.kd = p.head<3>();
  m.ks = p.segment<3>(3);
  m.alpha = p[6];
  return m;
}

// A fit's weight in the fusion: the variation its lobe explains over the variation it leaves.
// The fitted parameters' variance grows with the residual and shrinks with the explained
// variation, so this is their inverse-variance weight up to a constant: a fit explaining 95 %
// counts 35 times one explaining 35 %. (On cubes, fits explaining under half missed the true
// ks by 2-7 times more than those explaining over 90 %: broad, weak lobes fitted where the
// sample held no view of the highlight.)
float fit_weight(const SpecularFit& fit) {
  const float explained = std::min(fit.explained, 0.999f);
  return explained / (1.0f - explained);
}

}  // namespace

SpecularEstimator::SpecularEstimator(const HemiCnn& network, const SpecularParams& params)
    : network_(network), params_(params) {
  if (params.voxels_per_estimate < 1 || params.min_distinct_voxels < 1)
    throw Error("specular estimation", "voxels_per_estimate",
                "voxels_per_estimate and min_distinct_voxels must be >= 1");
  hemi_.projection = network.projection();
}

const SegmentMaterial* SpecularEstimator::material(int segment) const {
  const auto found = materials_.find(segment);
  return found == materials_.end() ? nullptr : &found->second;
}

void SpecularEstimator::fuse_refined_albedo(int segment, const Eigen::Vector3f& kd) {
  const auto material = materials_.find(segment);
  if (material == materials_.end()) return;
  auto& fused = fused_refined_kd_.try_emplace(segment, params_.fusion_divisor).first->second;
  fused.add(kd);
  material->second.kd_refined = fused.mean();
}

void SpecularEstimator::update(const ObservationGrid& grid, const SegmentMap& segment_map,
                               const std::vector<int>& segments,
                               const std::vector<render::PointLight>& lights, int frame,
                               const LightTransport* transport) {
  const auto lighting = [transport, &grid](int v) {
    return transport ? transport->lighting(v, grid.segment(v)) : PointLighting{};
  };
  const int count = params_.voxels_per_estimate;
  const int image_floats = 3 * hemi_.size * hemi_.size;
  std::vector<std::optional<render::WardMaterial>> estimates(segments.size());
  std::vector<std::optional<SpecularFit>> fits(segments.size());
  tbb::parallel_for(std::size_t(0), segments.size(), [&](std::size_t i) {
    // Seeded per (seed, frame, segment): the same run gives the same samples on any thread.
    std::mt19937_64 random(params_.seed * 0x9E3779B97F4A7C15ull + std::uint64_t(frame) * 7919u +
                           std::uint64_t(segments[i]));
    std::vector<int> voxels(count);
    const int sampled = segment_map.sample(grid, segments[i], count, params_.min_observations,
                                           random, voxels.data());
    if (sampled < std::min(count, params_.min_distinct_voxels)) {
      log().debug("frame {}: segment {} has {} of {} voxels with {} observations (reservoir {})",
                  frame, segments[i], sampled, count, params_.min_observations,
                  segment_map.reservoir_size(segments[i]));
      return;
    }
    for (int k = sampled; k < count; ++k) voxels[std::size_t(k)] = voxels[std::size_t(k % sampled)];
    std::vector<float> images(std::size_t(count) * image_floats);
    for (int k = 0; k < sampled; ++k) {
      const int v = voxels[k];
      const Eigen::Vector3f scale =
          hemi_input_scale(network_.input(), lights, grid.position(v), grid.normal(v), lighting(v));
      make_hemi_image(grid.observations(v), grid.observation_count(v), grid.normal(v), hemi_,
                      images.data() + std::size_t(k) * image_floats, scale);
    }
    // The repeated voxels' images are copies, not made again.
    for (int k = sampled; k < count; ++k)
      std::copy_n(images.data() + std::size_t(k % sampled) * image_floats, image_floats,
                  images.data() + std::size_t(k) * image_floats);
    estimates[i] = render::from_perceptual(network_.predict(images.data(), count));
    if (!params_.fit_lobe) return;
    std::vector<FitVoxel> fit_voxels(count);
    for (int k = 0; k < count; ++k)
      fit_voxels[k] = {grid.observations(voxels[k]), grid.observation_count(voxels[k]),
                       grid.position(voxels[k]), grid.normal(voxels[k]), lighting(voxels[k])};
    fits[i] = fit_specular(fit_voxels, lights, params_.fit);
  });
  for (std::size_t i = 0; i < segments.size(); ++i) {
    if (!estimates[i]) continue;
    auto fused = fused_.try_emplace(segments[i], params_.fusion_divisor).first;
    fused->second.add(to_vector(*estimates[i]));
    SegmentMaterial& material = materials_[segments[i]];
    material.ward = to_material(fused->second.mean());
    material.latest = *estimates[i];
    if (fits[i]) {
      auto& lobe = fused_lobe_.try_emplace(segments[i], params_.fusion_divisor).first->second;
      lobe.add(Eigen::Vector4f(fits[i]->ks.x(), fits[i]->ks.y(), fits[i]->ks.z(), fits[i]->alpha),
               fit_weight(*fits[i]));
      material.latest.ks = fits[i]->ks;
      material.latest.alpha = fits[i]->alpha;
      ++material.fitted;
    }
    // Once fitted often enough, a segment's ks and alpha are the fused fits alone: the
    // network's estimates of the frames without a fit would pull them towards its own bias.
    if (const auto lobe = fused_lobe_.find(segments[i]);
        lobe != fused_lobe_.end() && material.fitted >= params_.min_fits) {
      material.ward.ks = lobe->second.mean().head<3>();
      material.ward.alpha = lobe->second.mean()[3];
    }
    ++material.estimates;
    material.last_frame = frame;
  }
}

}  // namespace glint::reflectance
