#include "reflectance/continued_plane.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "reflectance/light_incidence.h"

namespace glint::reflectance {

Eigen::Vector3f ContinuedPlane::radiance(const Eigen::Vector3f& p,
                                         const std::vector<render::PointLight>& lights) const {
  Eigen::Vector3f irradiance = Eigen::Vector3f::Zero();
  for (const render::PointLight& light : lights)
    irradiance += incidence(light, p, normal).irradiance;
  return albedo.cwiseProduct(irradiance) / float(M_PI);
}

ContinuedPlane largest_plane(const ObservationGrid& grid, float thickness_m,
                             const std::function<Eigen::Vector3f(int)>& albedo) {
  // Per segment: voxel count, sums of positions, of their outer products and of normals.
  struct Moments {
    double count = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), normals = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  };
  std::vector<Moments> segments;
  for (int v = 0; v < int(grid.voxel_count()); ++v) {
    const int segment = grid.segment(v);
    if (!grid.has_surface(v) || segment <= 0) continue;
    if (std::size_t(segment) >= segments.size()) segments.resize(std::size_t(segment) + 1);
    Moments& m = segments[std::size_t(segment)];
    const Eigen::Vector3d p = grid.position(v).cast<double>();
    m.count += 1;
    m.sum += p;
    m.outer += p * p.transpose();
    m.normals += grid.normal(v).cast<double>();
  }
  const double min_cosine = std::cos(25.0 * M_PI / 180.0);
  ContinuedPlane best;
  double best_count = 0;
  for (int segment = 1; segment < int(segments.size()); ++segment) {
    const Moments& m = segments[std::size_t(segment)];
    if (m.count < 3 || m.count <= best_count) continue;
    const Eigen::Vector3d mean = m.sum / m.count;
    const Eigen::Matrix3d covariance = m.outer / m.count - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    Eigen::Vector3d normal = solver.eigenvectors().col(0);  // the smallest eigenvalue's
    if (normal.dot(m.normals) < 0) normal = -normal;
    const bool planar = std::sqrt(std::max(0.0, solver.eigenvalues()(0))) <= thickness_m &&
                        normal.dot(m.normals) >= min_cosine * m.normals.norm();
    const Eigen::Vector3f kd = albedo(segment);
    if (!planar || !kd.allFinite()) continue;
    best = {.normal = normal.cast<float>(), .offset = float(normal.dot(mean)), .albedo = kd};
    best_count = m.count;
  }
  return best;
}

}  // namespace glint::reflectance
