#include "fusion/icp_tracker.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>
#include <vector>

#include "fusion/tsdf_kernels.h"

namespace glint::fusion {
namespace {

// Normal equations of the linearised point-to-plane residuals, summed over pixels.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> lhs = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  double squared_error = 0;
  int count = 0;

  void add(const Eigen::Vector3f& point, const Eigen::Vector3f& normal, float residual) {
    // d residual / d (rotation, translation) = (point x normal, normal)
    const float jacobian[6] = {point.y() * normal.z() - point.z() * normal.y(),
                               point.z() * normal.x() - point.x() * normal.z(),
                               point.x() * normal.y() - point.y() * normal.x(),
                               normal.x(),
                               normal.y(),
                               normal.z()};
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) lhs(r, c) += double(jacobian[r] * jacobian[c]);
      rhs[r] -= double(jacobian[r] * residual);
    }
    squared_error += residual * residual;
    ++count;
  }
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
      k = k.scaled(0.5);
      k.width = depth.width();  // the 2x2 reduction drops an odd last row / column
      k.height = depth.height();
    }
    ImageF points = points_from_depth(depth, k);
    ImageF normals = normals_from_points(points, Eigen::Vector3d::Zero());
    levels.push_back({k, std::move(points), std::move(normals)});
  }
  return levels;
}

NormalEquations associate(const PyramidLevel& level, const SurfaceView& model,
                          const Intrinsics& model_intrinsics, const Pose& world_to_model_camera,
                          const Pose& camera_to_world, const TrackingParams& params) {
  const float cos_max_angle = float(std::cos(params.max_normal_angle_deg * std::numbers::pi / 180));
  const float max_squared_distance = float(params.max_distance_m * params.max_distance_m);
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f translation = camera_to_world.translation().cast<float>();
  const Eigen::Matrix3f model_rotation = world_to_model_camera.linear().cast<float>();
  const Eigen::Vector3f model_translation = world_to_model_camera.translation().cast<float>();
  const float fx = float(model_intrinsics.fx), fy = float(model_intrinsics.fy);
  const float cx = float(model_intrinsics.cx), cy = float(model_intrinsics.cy);
  const int model_width = model_intrinsics.width;
  const float* px = level.points.plane(0);
  const float* py = level.points.plane(1);
  const float* pz = level.points.plane(2);
  const float* nx = level.normals.plane(0);
  const float* ny = level.normals.plane(1);
  const float* nz = level.normals.plane(2);
  const float* qx = model.points_m.plane(0);
  const float* qy = model.points_m.plane(1);
  const float* qz = model.points_m.plane(2);
  const float* mx = model.normals.plane(0);
  const float* my = model.normals.plane(1);
  const float* mz = model.normals.plane(2);
  const std::size_t pixels = level.points.pixel_count();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, pixels, 1024), NormalEquations{},
      [&](const tbb::blocked_range<std::size_t>& range, NormalEquations sum) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3f p(px[i], py[i], pz[i]);
          const Eigen::Vector3f n(nx[i], ny[i], nz[i]);
          if (!p.allFinite() || !n.allFinite()) continue;
          const Eigen::Vector3f p_world = rotation * p + translation;
          const Eigen::Vector3f p_model = model_rotation * p_world + model_translation;
          if (p_model.z() <= 0) continue;
          int u, v;
          if (!nearest_pixel(fx * p_model.x() / p_model.z() + cx,
                             fy * p_model.y() / p_model.z() + cy, model_width,
                             model_intrinsics.height, u, v))
            continue;
          const std::size_t j = std::size_t(v) * model_width + u;
          const Eigen::Vector3f q(qx[j], qy[j], qz[j]);
          const Eigen::Vector3f m(mx[j], my[j], mz[j]);
          if (!q.allFinite() || !m.allFinite()) continue;
          if ((p_world - q).squaredNorm() > max_squared_distance) continue;
          if ((rotation * n).dot(m) < cos_max_angle) continue;
          sum.add(p_world, m, m.dot(p_world - q));
        }
        return sum;
      },
      [](NormalEquations a, const NormalEquations& b) {
        a.join(b);
        return a;
      });
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
      const Eigen::Matrix<double, 6, 6> lhs = last.lhs.selfadjointView<Eigen::Upper>();
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(lhs);
      if (solver.info() != Eigen::Success) break;
      const Eigen::Matrix<double, 6, 1> twist = solver.solve(last.rhs);
      if (!twist.allFinite()) break;
      estimate = twist_to_pose(twist) * estimate;
      if (twist.norm() < 1e-6) break;
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
