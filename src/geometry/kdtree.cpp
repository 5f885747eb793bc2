#include "geometry/kdtree.h"

#include <nanoflann.hpp>
#include <string>

#include "core/error.h"
#include "core/parallel.h"

namespace glint::geometry {
namespace {

// nanoflann's dataset adaptor contract over the SoA arrays.
struct CloudAdaptor {
  const PointCloud& cloud;
  std::size_t kdtree_get_point_count() const { return cloud.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return dim == 0 ? cloud.x[i] : (dim == 1 ? cloud.y[i] : cloud.z[i]);
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>,
                                                 CloudAdaptor, 3, std::uint32_t>;

}  // namespace

struct KdTree::Index {
  Index(const PointCloud& cloud, int max_leaf_size)
      : adaptor{cloud}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(max_leaf_size)) {
    tree.buildIndex();
  }
  CloudAdaptor adaptor;
  Tree tree;
};

KdTree::KdTree(const PointCloud& cloud, int max_leaf_size)
    : index_(std::make_unique<Index>(cloud, max_leaf_size)) {}

KdTree::~KdTree() = default;

std::size_t KdTree::size() const { return index_->adaptor.cloud.size(); }

int KdTree::knn(const float query[3], int k, std::uint32_t* indices,
                float* squared_distances) const {
  if (k <= 0 || size() == 0) return 0;
  nanoflann::KNNResultSet<float, std::uint32_t> result(static_cast<std::uint32_t>(k));
  result.init(indices, squared_distances);
  index_->tree.findNeighbors(result, query, nanoflann::SearchParams());
  return static_cast<int>(result.size());
}

KnnResult KdTree::knn_all(int k) const {
  const std::size_t n = size();
  if (k <= 0 || static_cast<std::size_t>(k) > n) {
    throw Error("", "k-nearest-neighbour search",
                "k = " + std::to_string(k) + " needs 1 <= k <= number of points (" +
                    std::to_string(n) + ")");
  }
  KnnResult result;
  result.k = k;
  result.indices.resize(n * k);
  result.squared_distances.resize(n * k);
  const PointCloud& cloud = index_->adaptor.cloud;
  parallel_for(n, [&](std::size_t i) {
    const float query[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
    knn(query, k, &result.indices[i * k], &result.squared_distances[i * k]);
  });
  return result;
}

}  // namespace glint::geometry
