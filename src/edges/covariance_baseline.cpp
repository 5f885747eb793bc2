#include "edges/covariance_baseline.h"

#include <Eigen/Eigenvalues>

#include "geometry/neighbourhoods.h"

namespace glint::edges {

std::vector<float> surface_variation(const PointCloud& cloud, int k) {
  std::vector<float> variation(cloud.size(), 0.f);
  geometry::NeighbourhoodParams params;
  params.nested_sizes = {k};
  geometry::for_each_neighbourhood(cloud, params, [&](const geometry::Neighbourhood& nb) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = 0; j < nb.size; ++j) mean += Eigen::Vector3d(nb.dx[j], nb.dy[j], nb.dz[j]);
    mean /= nb.size;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (int j = 0; j < nb.size; ++j) {
      const Eigen::Vector3d e = Eigen::Vector3d(nb.dx[j], nb.dy[j], nb.dz[j]) - mean;
      covariance += e * e.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d lambda = solver.eigenvalues().cwiseMax(0.0);
    const double total = lambda.sum();
    variation[nb.point] = total > 0 ? float(lambda[0] / total) : 0.f;
  });
  return variation;
}

std::vector<std::uint8_t> classify_covariance_baseline(const PointCloud& cloud,
                                                       const CovarianceBaselineParams& params) {
  const std::vector<float> variation = surface_variation(cloud, params.k);
  std::vector<std::uint8_t> labels(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) labels[i] = variation[i] > params.threshold;
  return labels;
}

}  // namespace glint::edges
