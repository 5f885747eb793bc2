#pragma once
// Exact k-nearest-neighbour queries on a point cloud with a nanoflann k-d tree.
// The tree reads the cloud's x/y/z arrays in place (no copy): the cloud must outlive the tree
// and must not change while the tree exists. Queries are thread-safe (const).
#include <cstdint>
#include <memory>
#include <vector>

#include "core/point_cloud.h"

namespace glint::geometry {

struct KnnResult {
  int k = 0;
  std::vector<std::uint32_t> indices;    // n × k, row i = neighbours of point i, nearest first
  std::vector<float> squared_distances;  // n × k, matching
};

class KdTree {
 public:
  // Builds the tree; max_leaf_size trades build time for query time (nanoflann's default 10).
  explicit KdTree(const PointCloud& cloud, int max_leaf_size = 10);
  ~KdTree();
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  // The min(k, size) nearest points to `query`, nearest first (the point itself included when it
  // belongs to the cloud). Returns the number found; outputs must hold k entries.
  int knn(const float query[3], int k, std::uint32_t* indices, float* squared_distances) const;

  // k nearest neighbours of every cloud point, in parallel. Needs k <= size (glint::Error
  // otherwise).
  KnnResult knn_all(int k) const;

  std::size_t size() const;

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

}  // namespace glint::geometry
