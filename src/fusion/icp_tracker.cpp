#include "fusion/icp_tracker.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

#include "core/cpu_level.h"
#include "fusion/vector_lanes.h"

namespace glint::fusion {
namespace {

// Normal equations of the linearised point-to-plane residuals, summed over pixels: the upper
// triangle of lhs.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> lhs = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  double squared_error = 0;
  int count = 0;

  void join(const NormalEquations& other) {
    lhs += other.lhs;
    rhs += other.rhs;
    squared_error += other.squared_error;
    count += other.count;
  }
};

struct PyramidLevel {
  Intrinsics intrinsics;
  ImageF points;   // camera frame
  ImageF normals;  // camera frame
};

std::vector<PyramidLevel> build_pyramid(const ImageF& depth_m, const Intrinsics& intrinsics,
                                        const TrackingParams& params) {
  std::vector<PyramidLevel> levels;
  ImageF depth = bilateral_filter_depth(depth_m, params.bilateral);
  Intrinsics k = intrinsics;
  for (std::size_t level = 0; level < params.iterations.size(); ++level) {
    if (level > 0) {
      depth = downsample_depth(depth, params.bilateral.sigma_depth_m);
      k = halved_intrinsics(k, 1);
    }
    ImageF points = points_from_depth(depth, k);
    ImageF normals = normals_from_points(points, Eigen::Vector3d::Zero());
    levels.push_back({k, std::move(points), std::move(normals)});
  }
  return levels;
}

// One association pass's inputs: the level's points and normals, the model's, and the poses.
struct Association {
  const float* p[3];                     // frame points, camera frame, NaN where there is none
  const float* n[3];                     // their normals
  const float* q[3];                     // model points, world frame
  const float* m[3];                     // model normals
  float rotation[3][3], translation[3];  // frame camera to world (the estimate)
  float model_rotation[3][3], model_translation[3];  // world to model camera
  float fx, fy, cx, cy;
  int model_width, model_height;
  float max_squared_distance, cos_max_angle;
};

// The association runs eight pixels at a time in vector lanes (vector_lanes.h): pixel by pixel,
// the sums' 27 dependent double additions per pair were most of a tracked frame's association
// time.

// Lane-wise sums of a range's pairs, in float: a range holds at most 1024 pixels (the reduction's
// grain), 128 per lane; the ranges' sums are then added in double.
struct LaneSums {
  Floats lhs[21], rhs[6], squared_error;
  Ints count;
};

// Clears the lanes of `mask` where x is NaN or infinite.
[[gnu::always_inline]] inline void keep_finite(Ints& mask, const Floats& x) {
  mask &= (x - x) == 0;
}

// Pixels [i, i + kLaneCount) of `plane`; lanes at or beyond `end` read NaN (no point).
[[gnu::always_inline]] inline void load_lanes(const float* plane, std::size_t i, std::size_t end,
                                              Floats& out) {
  if (i + kLaneCount <= end) {
    std::memcpy(&out, plane + i, sizeof(out));
    return;
  }
  for (int lane = 0; lane < kLaneCount; ++lane)
    out[lane] = i + lane < end ? plane[i + lane] : std::numeric_limits<float>::quiet_NaN();
}

// Adds pixels [i, i + kLaneCount) (those before `end`): each frame point is moved into the world by
// the estimate, projected into the model view and paired with the model point at the nearest
// pixel; pairs farther apart than the limit or with normals too far apart are left out.
template <auto gather>
[[gnu::always_inline]] inline void associate_lanes(const Association& a, std::size_t i,
                                                   std::size_t end, LaneSums& sums) {
  Floats p[3], n[3];
  for (int axis = 0; axis < 3; ++axis) {
    load_lanes(a.p[axis], i, end, p[axis]);
    load_lanes(a.n[axis], i, end, n[axis]);
  }
  Ints valid = ~Ints{};
  for (int axis = 0; axis < 3; ++axis) {
    keep_finite(valid, p[axis]);
    keep_finite(valid, n[axis]);
  }
  Floats world[3], in_model[3], normal[3];
  for (int r = 0; r < 3; ++r) {
    world[r] = a.rotation[r][0] * p[0] + a.rotation[r][1] * p[1] + a.rotation[r][2] * p[2] +
               a.translation[r];
    normal[r] = a.rotation[r][0] * n[0] + a.rotation[r][1] * n[1] + a.rotation[r][2] * n[2];
  }
  for (int r = 0; r < 3; ++r)
    in_model[r] = a.model_rotation[r][0] * world[0] + a.model_rotation[r][1] * world[1] +
                  a.model_rotation[r][2] * world[2] + a.model_translation[r];
  const Floats u = a.fx * in_model[0] / in_model[2] + a.cx;
  const Floats v = a.fy * in_model[1] / in_model[2] + a.cy;
  valid &= in_model[2] > 0;
  Ints pixel;
  nearest_pixels(u, v, a.model_width, a.model_height, valid, pixel);
  Floats q[3], m[3];
  for (int axis = 0; axis < 3; ++axis) {
    gather(a.q[axis], pixel, q[axis]);
    gather(a.m[axis], pixel, m[axis]);
    keep_finite(valid, q[axis]);
    keep_finite(valid, m[axis]);
  }
  const Floats dx = world[0] - q[0], dy = world[1] - q[1], dz = world[2] - q[2];
  valid &= (dx * dx + dy * dy + dz * dz <= a.max_squared_distance) &
           (normal[0] * m[0] + normal[1] * m[1] + normal[2] * m[2] >= a.cos_max_angle);
  // d residual / d (rotation, translation) = (point x normal, normal); lanes left out add 0.
  const Floats zero{};
  const Floats residual = valid ? m[0] * dx + m[1] * dy + m[2] * dz : zero;
  const Floats jacobian[6] = {valid ? world[1] * m[2] - world[2] * m[1] : zero,
                              valid ? world[2] * m[0] - world[0] * m[2] : zero,
                              valid ? world[0] * m[1] - world[1] * m[0] : zero,
                              valid ? m[0] : zero,
                              valid ? m[1] : zero,
                              valid ? m[2] : zero};
  int entry = 0;
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) sums.lhs[entry++] += jacobian[r] * jacobian[c];
    sums.rhs[r] -= jacobian[r] * residual;
  }
  sums.squared_error += residual * residual;
  sums.count -= valid;  // a true lane is -1
}

template <auto gather>
[[gnu::always_inline]] inline void sum_range(const Association& a, std::size_t begin,
                                             std::size_t end, NormalEquations& out) {
  LaneSums sums{};
  for (std::size_t i = begin; i < end; i += kLaneCount) associate_lanes<gather>(a, i, end, sums);
  for (int lane = 0; lane < kLaneCount; ++lane) {
    int entry = 0;
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) out.lhs(r, c) += double(sums.lhs[entry++][lane]);
      out.rhs[r] += double(sums.rhs[r][lane]);
    }
    out.squared_error += double(sums.squared_error[lane]);
    out.count += sums.count[lane];
  }
}

using RangeKernel = void (*)(const Association&, std::size_t, std::size_t, NormalEquations&);

[[gnu::flatten]] void associate_range_baseline(const Association& a, std::size_t begin,
                                               std::size_t end, NormalEquations& out) {
  sum_range<gather_lane_by_lane>(a, begin, end, out);
}
#if defined(__x86_64__)
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] void associate_range_x86_64_v3(
    const Association& a, std::size_t begin, std::size_t end, NormalEquations& out) {
  sum_range<gather_avx2>(a, begin, end, out);
}
#endif

RangeKernel range_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v3()) return associate_range_x86_64_v3;
#endif
  return associate_range_baseline;
}

NormalEquations associate(const PyramidLevel& level, const SurfaceView& model,
                          const Intrinsics& model_intrinsics, const Pose& world_to_model_camera,
                          const Pose& camera_to_world, const TrackingParams& params) {
  // Lanes without a pair still read the model's pixel 0.
  if (model.points_m.pixel_count() == 0) return {};
  Association a;
  for (int axis = 0; axis < 3; ++axis) {
    a.p[axis] = level.points.plane(axis);
    a.n[axis] = level.normals.plane(axis);
    a.q[axis] = model.points_m.plane(axis);
    a.m[axis] = model.normals.plane(axis);
    a.translation[axis] = float(camera_to_world.translation()[axis]);
    a.model_translation[axis] = float(world_to_model_camera.translation()[axis]);
    for (int c = 0; c < 3; ++c) {
      a.rotation[axis][c] = float(camera_to_world.linear()(axis, c));
      a.model_rotation[axis][c] = float(world_to_model_camera.linear()(axis, c));
    }
  }
  a.fx = float(model_intrinsics.fx);
  a.fy = float(model_intrinsics.fy);
  a.cx = float(model_intrinsics.cx);
  a.cy = float(model_intrinsics.cy);
  a.model_width = model_intrinsics.width;
  a.model_height = model_intrinsics.height;
  a.max_squared_distance = float(params.max_distance_m * params.max_distance_m);
  a.cos_max_angle = float(std::cos(params.max_normal_angle_deg * std::numbers::pi / 180));
  static const RangeKernel associate_range = range_kernel();
  // Deterministic splits and joins: the float lane sums round differently in other ranges, and a
  // tracked run's poses should not depend on the scheduling.
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, level.points.pixel_count(), 1024), NormalEquations{},
      [&](const tbb::blocked_range<std::size_t>& range, NormalEquations sum) {
        associate_range(a, range.begin(), range.end(), sum);
        return sum;
      },
      [](NormalEquations a, const NormalEquations& b) {
        a.join(b);
        return a;
      },
      tbb::simple_partitioner());
}

// The least-squares twist of `equations` within the directions they constrain: along an
// eigenvector of the normal matrix whose eigenvalue is under min_ratio times the largest (the
// translation along a floor that is most of what the pairs see, at a pyramid's coarse levels) the
// solution is noise over almost nothing, so the twist has no component there and the estimate
// keeps the prediction. False where the system is empty or not finite.
bool solve_constrained(const NormalEquations& equations, double min_ratio,
                       Eigen::Matrix<double, 6, 1>& twist) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(
      equations.lhs.selfadjointView<Eigen::Upper>());
  if (eigen.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 6, 1>& values = eigen.eigenvalues();  // ascending
  if (!(values[5] > 0) || !std::isfinite(values[5])) return false;
  twist.setZero();
  for (int k = 0; k < 6; ++k) {
    if (!(values[k] > min_ratio * values[5])) continue;
    const auto direction = eigen.eigenvectors().col(k);
    twist += direction * (direction.dot(equations.rhs) / values[k]);
  }
  return twist.allFinite();
}

// exp of a small twist (rotation vector, translation) as a rigid transform.
Pose twist_to_pose(const Eigen::Matrix<double, 6, 1>& twist) {
  Pose update = Pose::Identity();
  const Eigen::Vector3d rotation = twist.head<3>();
  const double angle = rotation.norm();
  if (angle > 0) update.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  update.translation() = twist.tail<3>();
  return update;
}

}  // namespace

TrackingResult track_frame(const ImageF& depth_m, const Intrinsics& intrinsics,
                           const SurfaceView& model, const Intrinsics& model_intrinsics,
                           const Pose& model_camera_to_world, const Pose& initial_camera_to_world,
                           const TrackingParams& params) {
  const std::vector<PyramidLevel> levels = build_pyramid(depth_m, intrinsics, params);
  const Pose world_to_model_camera = model_camera_to_world.inverse();
  TrackingResult result;
  result.camera_to_world = initial_camera_to_world;
  Pose estimate = initial_camera_to_world;
  NormalEquations last;
  for (int level = int(levels.size()) - 1; level >= 0; --level) {
    for (int iteration = 0; iteration < params.iterations[level]; ++iteration) {
      last = associate(levels[level], model, model_intrinsics, world_to_model_camera, estimate,
                       params);
      if (last.count < 6) break;
      Eigen::Matrix<double, 6, 1> twist;
      if (!solve_constrained(last, params.min_constraint_ratio, twist)) break;
      estimate = twist_to_pose(twist) * estimate;
      if (twist.norm() < params.converged_twist) break;
    }
  }
  last = associate(levels[0], model, model_intrinsics, world_to_model_camera, estimate, params);
  result.inliers = last.count;
  result.rmse_m = last.count ? std::sqrt(last.squared_error / last.count) : 0;
  const double needed = params.min_inlier_fraction * double(levels[0].points.pixel_count());
  if (last.count >= needed && last.count >= 6) {
    result.status = TrackingStatus::tracked;
    result.camera_to_world = estimate;
    result.camera_to_world.linear() =
        Eigen::Quaterniond(estimate.rotation()).normalized().toRotationMatrix();
  }
  return result;
}

}  // namespace glint::fusion
