#include "reflectance/light_clustering.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace glint::reflectance {
namespace {

// Weighted mean of the samples within `radius` of `centre`; the centre itself when none is.
Eigen::Vector3d flat_kernel_mean(const std::vector<LightSample>& samples,
                                 const Eigen::Vector3d& centre, double radius, double* support) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0;
  const double radius2 = radius * radius;
  for (const LightSample& s : samples)
    if ((s.position - centre).squaredNorm() <= radius2) {
      sum += s.weight * s.position;
      weight += s.weight;
    }
  *support = weight;
  return weight > 0 ? Eigen::Vector3d(sum / weight) : centre;
}

std::vector<Eigen::Vector3d> grid_seeds(const std::vector<LightSample>& samples, double cell) {
  std::map<std::tuple<long, long, long>, std::pair<Eigen::Vector3d, double>> cells;
  for (const LightSample& s : samples) {
    const auto key =
        std::make_tuple(std::lround(s.position.x() / cell), std::lround(s.position.y() / cell),
                        std::lround(s.position.z() / cell));
    auto& [sum, weight] = cells.try_emplace(key, Eigen::Vector3d::Zero(), 0.0).first->second;
    sum += s.weight * s.position;
    weight += s.weight;
  }
  std::vector<Eigen::Vector3d> seeds;
  for (const auto& [key, value] : cells) seeds.push_back(value.first / value.second);
  return seeds;
}

}  // namespace

std::vector<LightSample> mean_shift(const std::vector<LightSample>& samples,
                                    const MeanShiftParams& params) {
  struct Mode {
    Eigen::Vector3d position;
    double support;
  };
  std::vector<Mode> modes;
  for (Eigen::Vector3d centre : grid_seeds(samples, params.bandwidth_m)) {
    double support = 0;
    for (int it = 0; it < params.max_iterations; ++it) {
      const Eigen::Vector3d moved = flat_kernel_mean(samples, centre, params.bandwidth_m, &support);
      const bool converged = (moved - centre).norm() < params.tolerance_m;
      centre = moved;
      if (converged) break;
    }
    modes.push_back({centre, support});
  }
  // Merge: visit modes by decreasing support and keep one unless a kept mode is within reach.
  std::sort(modes.begin(), modes.end(),
            [](const Mode& a, const Mode& b) { return a.support > b.support; });
  std::vector<Eigen::Vector3d> kept;
  for (const Mode& mode : modes)
    if (std::none_of(kept.begin(), kept.end(), [&](const Eigen::Vector3d& k) {
          return (k - mode.position).norm() < params.bandwidth_m;
        }))
      kept.push_back(mode.position);

  std::vector<LightSample> clusters(kept.size());
  for (LightSample& c : clusters) c.weight = 0;
  for (const LightSample& s : samples) {
    std::size_t nearest = 0;
    for (std::size_t k = 1; k < kept.size(); ++k)
      if ((kept[k] - s.position).squaredNorm() < (kept[nearest] - s.position).squaredNorm())
        nearest = k;
    LightSample& c = clusters[nearest];
    c.position += s.weight * s.position;
    c.radiance += float(s.weight) * s.radiance;
    c.weight += s.weight;
  }
  for (LightSample& c : clusters) {
    c.position /= c.weight;
    c.radiance /= float(c.weight);
  }
  std::sort(clusters.begin(), clusters.end(),
            [](const LightSample& a, const LightSample& b) { return a.weight > b.weight; });
  return clusters;
}

void LightFuser::add_frame(const std::vector<LightSample>& candidates) {
  ++frame_;
  for (const LightSample& candidate : candidates) {
    FusedLight* nearest = nullptr;
    double nearest_distance = params_.merge_radius_m;
    for (FusedLight& light : tracked_) {
      const double distance = (light.estimate.position - candidate.position).norm();
      if (distance <= nearest_distance) {
        nearest_distance = distance;
        nearest = &light;
      }
    }
    if (!nearest) {
      tracked_.push_back({candidate, 1, frame_});
      continue;
    }
    if (nearest->last_frame != frame_) ++nearest->frames;
    nearest->last_frame = frame_;
    // Position and radiance average over candidates, weighted by their pixel counts.
    nearest->estimate.weight += candidate.weight;
    const double step = candidate.weight / nearest->estimate.weight;
    nearest->estimate.position += step * (candidate.position - nearest->estimate.position);
    nearest->estimate.radiance += float(step) * (candidate.radiance - nearest->estimate.radiance);
  }
}

std::vector<FusedLight> LightFuser::lights() const {
  std::vector<FusedLight> accepted;
  for (const FusedLight& light : tracked_)
    if (light.frames >= params_.min_frames) accepted.push_back(light);
  std::sort(accepted.begin(), accepted.end(),
            [](const FusedLight& a, const FusedLight& b) { return a.frames > b.frames; });
  return accepted;
}

}  // namespace glint::reflectance
