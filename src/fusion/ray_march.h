#pragma once
// RayMarch: the search along one ray through the TSDF for its first zero crossing, shared by the
// view ray cast (fusion/raycast.h) and the single rays of shadow and indirect-light queries
// (fusion/ray_queue.h). Through unallocated space to the end of the region known to hold no
// block (its block, its empty cell of blocks, or the space outside all of them: a shadow or
// gather ray crosses metres of it), a few voxels through unobserved ones, 0.8 * |sdf| (at least
// one voxel) through observed ones, trilinear values within 2 voxels of the surface. The first
// crossing from + to - is located by linear interpolation between the two samples around it; a
// negative sample with no positive one just before it is a back face.
#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "fusion/tsdf_sampler.h"

namespace glint::fusion {

// The t at which origin + t * ray, inside the box [low, high], leaves it: the nearest of the
// faces ahead of it along each axis; infinity where it never does (bounds may be infinite).
inline float box_exit(const Eigen::Vector3f& origin, const Eigen::Vector3f& ray,
                      const Eigen::Vector3f& low, const Eigen::Vector3f& high) {
  float exit = std::numeric_limits<float>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (ray[axis] > 0) exit = std::min(exit, (high[axis] - origin[axis]) / ray[axis]);
    if (ray[axis] < 0) exit = std::min(exit, (low[axis] - origin[axis]) / ray[axis]);
  }
  return exit;
}

// Voxels a ray skips per step through unobserved voxels of allocated blocks (space behind
// surfaces, or beside them, that no frame saw). Landing on observed space after such a stride,
// it steps back and crosses the stride again voxel by voxel, so only an observed stretch
// shorter than the stride can be missed; with the default band (at least 2 cm) and 5 mm voxels,
// the observed band in front of any surface is at least 4 voxels deep.
constexpr int kUnobservedStride = 3;

// Where a march ended: the depth t (metres along the optical axis) of the first + to - crossing,
// or 0 when there is none; back_face when it entered a surface from behind (a negative observed
// sample with no positive one just before it).
struct MarchEnd {
  float t = 0;
  bool back_face = false;
};

// The search for the first + to - crossing along origin + t * ray up to t_max (ray has z = 1
// in camera space), one sample per step(): each sample's position depends on the one before, so
// a ray is a chain of dependent loads, and a thread advances several rays in turn to overlap
// their chains. start() begins (or begins again) at a given t.
class RayMarch {
 public:
  RayMarch() = default;
  RayMarch(const Eigen::Vector3f& ray, float t_max, float voxel)
      : t_max_(t_max),
        voxel_(voxel),
        inverse_length_(1.0f / ray.norm()),
        voxel_step_(voxel * inverse_length_) {}

  void start(float t_min) {
    state_ = State{};
    state_.t = state_.fine_until = t_min;
  }

  // Takes the next sample; false once the march has ended (end() says how).
  bool step(TsdfSampler& sampler, const Eigen::Vector3f& origin, const Eigen::Vector3f& ray) {
    State& s = state_;
    if (!(s.t <= t_max_)) return false;
    const Eigen::Vector3f p = origin + ray * s.t;
    float sdf;
    TsdfSampler::Sample sample = sampler.nearest(p, sdf);
    if (sample != TsdfSampler::Sample::unallocated && s.stride_start >= 0) {
      if (sample == TsdfSampler::Sample::observed) {
        s.fine_until = s.t;
        s.t = s.stride_start + voxel_step_;
        s.stride_start = -1;
        return true;
      }
      s.stride_start = -1;
    }
    if (sample == TsdfSampler::Sample::unobserved && s.t >= s.fine_until) {
      s.stride_start = s.t;
      s.t += kUnobservedStride * voxel_step_;
      s.previous_observed = false;
      return true;
    }
    // Near the surface, the trilinear value (a voxel without all 8 neighbours observed counts
    // as unobserved).
    if (sample == TsdfSampler::Sample::observed && sdf < 2 * voxel_ && !sampler.trilinear(p, sdf))
      sample = TsdfSampler::Sample::unobserved;
    if (sample != TsdfSampler::Sample::observed) {
      s.previous_observed = false;
      s.t = sample == TsdfSampler::Sample::unallocated ? past_empty(sampler, origin, ray, p)
                                                       : s.t + voxel_step_;
      return true;
    }
    if (sdf < 0) {
      // Entered behind a surface (a back face), or a crossing between two samples.
      s.end = s.previous_observed
                  ? MarchEnd{.t = s.previous_t +
                                  (s.t - s.previous_t) * s.previous_sdf / (s.previous_sdf - sdf)}
                  : MarchEnd{.back_face = true};
      s.t = std::numeric_limits<float>::infinity();  // ended
      return false;
    }
    s.previous_t = s.t;
    s.previous_sdf = sdf;
    s.previous_observed = true;
    s.t += std::max(voxel_, 0.8f * sdf) * inverse_length_;
    return true;
  }

  const MarchEnd& end() const { return state_.end; }

 private:
  // The t just past the empty region around p (TsdfSampler::empty_box), or infinity where the
  // ray never leaves it; at least kMinEmptyStep voxels on, so that rounding cannot hold it.
  float past_empty(const TsdfSampler& sampler, const Eigen::Vector3f& origin,
                   const Eigen::Vector3f& ray, const Eigen::Vector3f& p) const {
    Eigen::Vector3f low, high;
    sampler.empty_box(p, low, high);
    return std::max(box_exit(origin, ray, low, high), state_.t) + kMinEmptyStep * voxel_step_;
  }
  static constexpr float kMinEmptyStep = 1.0f / 64;

  struct State {
    float t = 0;
    // The start of the last stride through unobserved voxels (-1: none), and where voxel steps
    // end again after stepping back over it.
    float stride_start = -1, fine_until = 0;
    float previous_t = 0, previous_sdf = 0;
    bool previous_observed = false;
    MarchEnd end;
  };
  float t_max_ = -1;
  float voxel_ = 0, inverse_length_ = 0, voxel_step_ = 0;
  State state_;
};

}  // namespace glint::fusion
