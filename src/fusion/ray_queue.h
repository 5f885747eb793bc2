#pragma once
// RayQueue: the first surfaces of many single rays through the TSDF (the shadow and gather rays
// of reflectance/light_transport.h), marched kLanes at a time in turn. A march is a chain of
// dependent loads, and in a volume of many blocks most of them miss the caches; interleaved, the
// misses of different rays overlap (as in the view ray cast, fusion/raycast.cpp). Each lane has
// its own block cache, since the rays of a queue diverge (a point's shadow rays to different
// lights). One per thread; reused, it keeps its memory.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "fusion/block_occupancy.h"
#include "fusion/ray_march.h"
#include "fusion/tsdf_sampler.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

class RayQueue {
 public:
  static constexpr int kLanes = 4;

  // `occupancy` as for TsdfSampler (of `volume` after its last allocation, or null).
  RayQueue(const TsdfVolume& volume, const BlockOccupancy* occupancy);

  // Empties the queue.
  void clear();
  // Queues the search for the first surface along origin + t * direction, t in [0, t_max] (in
  // units of |direction|); returns the ray's index.
  int add(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_max);
  // Marches every ray queued since the last march().
  void march();

  int size() const { return int(origins_.size()); }
  const Eigen::Vector3f& origin(int ray) const { return origins_[std::size_t(ray)]; }
  const Eigen::Vector3f& direction(int ray) const { return directions_[std::size_t(ray)]; }
  float t_max(int ray) const { return t_max_[std::size_t(ray)]; }
  // Where ray `ray` ended once marched: MarchEnd::t > 0 at a + to - crossing, back_face where it
  // entered a surface from behind, neither where it met none.
  const MarchEnd& end(int ray) const { return ends_[std::size_t(ray)]; }
  // The TSDF's voxel size (metres): how far a crossing may lie from the surface it interpolates.
  float voxel_m() const { return voxel_m_; }

 private:
  float voxel_m_;
  std::array<TsdfSampler, kLanes> samplers_;
  std::vector<Eigen::Vector3f> origins_, directions_;
  std::vector<float> t_max_;
  std::vector<MarchEnd> ends_;
  int marched_ = 0;
};

}  // namespace glint::fusion
