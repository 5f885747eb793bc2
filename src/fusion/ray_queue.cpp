#include "fusion/ray_queue.h"

namespace glint::fusion {

RayQueue::RayQueue(const TsdfVolume& volume, const BlockOccupancy* occupancy)
    : voxel_m_(float(volume.params().voxel_size_m)),
      samplers_{TsdfSampler(volume, occupancy), TsdfSampler(volume, occupancy),
                TsdfSampler(volume, occupancy), TsdfSampler(volume, occupancy)} {}

void RayQueue::clear() {
  origins_.clear();
  directions_.clear();
  t_max_.clear();
  ends_.clear();
  marched_ = 0;
}

int RayQueue::add(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_max) {
  origins_.push_back(origin);
  directions_.push_back(direction);
  t_max_.push_back(t_max);
  ends_.emplace_back();
  return size() - 1;
}

// Also compiled for x86-64-v3, as the view ray cast is (fusion/raycast.cpp): each sample rounds
// three coordinates, one instruction there; fused multiply-adds change a hit's last bits.
#if defined(__clang__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#else
__attribute__((target_clones("arch=x86-64-v3", "default"), flatten))
#endif
void RayQueue::march() {
  std::array<RayMarch, kLanes> marches;
  std::array<int, kLanes> ray{};
  std::array<bool, kLanes> busy{};
  int next = marched_, in_flight = 0;
  const int count = size();
  const auto start_next = [&](int lane) {
    if (next >= count) return false;
    ray[lane] = next;
    marches[lane] = RayMarch(directions_[std::size_t(next)], t_max_[std::size_t(next)], voxel_m_);
    marches[lane].start(0.0f);
    ++next;
    return true;
  };
  for (int lane = 0; lane < kLanes; ++lane) in_flight += busy[lane] = start_next(lane);
  while (in_flight > 0)
    for (int lane = 0; lane < kLanes; ++lane) {
      if (!busy[lane]) continue;
      const auto r = std::size_t(ray[lane]);
      if (marches[lane].step(samplers_[lane], origins_[r], directions_[r])) continue;
      ends_[r] = marches[lane].end();
      if (!(busy[lane] = start_next(lane))) --in_flight;
    }
  marched_ = count;
}

}  // namespace glint::fusion
