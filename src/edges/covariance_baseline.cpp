#include "edges/covariance_baseline.h"

#include "geometry/covariance.h"
#include "geometry/neighbourhoods.h"

namespace glint::edges {

std::vector<float> surface_variation(const PointCloud& cloud, int k) {
  std::vector<float> variation(cloud.size(), 0.f);
  geometry::NeighbourhoodParams params;
  params.k = k;
  geometry::for_each_neighbourhood(cloud, params, [&](const geometry::Neighbourhood& nb) {
    geometry::Moments moments;
    for (int j = 0; j < nb.size; ++j) moments.add(nb.dx[j], nb.dy[j], nb.dz[j]);
    const Eigen::Vector3d lambda = geometry::eigenvalues_descending(moments.covariance());
    const double total = lambda.sum();
    variation[nb.point] = total > 0 ? float(lambda[2] / total) : 0.f;
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
