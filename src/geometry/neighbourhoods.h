#pragma once
// Exact k-nearest neighbourhoods of every point of a cloud, computed tile by tile.
//
// Why not one k-d tree query per point: at k = 128 a plain k-d tree answers ~70k queries/s on
// two cores, and storing all lists for 1M points costs 1 GB (thesis §5.5.9 asks for a tailored
// search). Here points are bucketed in a uniform grid whose cell is about half the k-th
// neighbour distance; all points of one cell share one gathered candidate set (the 5×5×5
// block around it, contiguous in memory), distances are computed in a tight loop and the k
// nearest bucket-sorted, reusing the previous query's k-th distance as the bucket range. A
// query is accepted only when its k-th distance is inside the block's guaranteed radius, so
// the result is exact; the few that are not (sparse regions, outliers) retry on a 9×9×9 block
// and then fall back to a k-d tree. Lists are handed to the visitor and never all stored (a
// caller may keep a sample's, KeptNeighbourhoods).
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "core/point_cloud.h"
#include "core/pool_memory.h"

namespace glint::geometry {

// One point's neighbourhood as seen by a visitor: its k nearest points (itself included),
// nearest first, so the first s entries are the s nearest for every s <= k (ties broken
// arbitrarily). Positions are relative to the query point (better float precision).
struct Neighbourhood {
  std::uint32_t point = 0;    // index of the query point in the cloud
  int size = 0;               // k
  const float* dx = nullptr;  // neighbour position minus query position, `size` entries
  const float* dy = nullptr;
  const float* dz = nullptr;
  const std::uint32_t* indices = nullptr;  // neighbour indices in the cloud
  const float* values = nullptr;  // neighbours' entries of the values given to for_each, or null
};

struct NeighbourhoodParams {
  int k = 128;
  // Grid cell size in the cloud's unit; 0 = estimate from a subsample (about half a high
  // quantile of the k-th neighbour distance).
  double cell_size = 0.0;
};

struct NeighbourhoodStats {
  double cell_size = 0.0;
  std::size_t cells = 0;
  std::size_t retried_queries = 0;   // needed the 9×9×9 block
  std::size_t fallback_queries = 0;  // needed the k-d tree
};

// The largest k for NeighbourhoodSearch::kth_nearest_squared_distances, where the search's own
// k is smaller.
inline constexpr int kMaxSmallK = 32;

// A cloud bucketed once for exact neighbourhoods of params.k points; the same grid also
// answers a smaller k, so a pass that needs both builds it once.
class NeighbourhoodSearch {
 public:
  // Keeps a reference to the cloud. Throws glint::Error when the cloud has fewer points than
  // params.k or params.k < 1.
  NeighbourhoodSearch(const PointCloud& cloud, const NeighbourhoodParams& params);
  ~NeighbourhoodSearch();
  NeighbourhoodSearch(const NeighbourhoodSearch&) = delete;
  NeighbourhoodSearch& operator=(const NeighbourhoodSearch&) = delete;

  // The size of every neighbourhood for_each visits.
  int k() const;

  // Calls visit(neighbourhood) once for every point, from several threads at once (the visitor
  // must be thread-safe; the Neighbourhood's arrays are valid only during the call).
  // progress(points_done) is called now and then from worker threads (may be empty).
  // values, one per point when given, are handed out per neighbour (Neighbourhood::values),
  // gathered with the positions. With `wanted`, only the points with a non-zero entry are
  // visited (cells without one are skipped). Throws glint::Error when values or wanted has
  // another size.
  NeighbourhoodStats for_each(const std::function<void(const Neighbourhood&)>& visit,
                              const std::function<void(std::size_t)>& progress = {},
                              std::span<const float> values = {},
                              std::span<const std::uint8_t> wanted = {}) const;

  // Every point's exact squared distance to its k-th nearest point, itself counted first (k = 9
  // gives the 8th nearest other point): a local spacing, for k up to params.k. The block of one
  // cell around a query's cell and a running list of the k smallest replace the sorted lists.
  // Computed as (x_j - x_q)² + (y_j - y_q)² + (z_j - z_q)² in float without fused multiply-adds,
  // as a visitor of for_each computes it from dx, dy, dz. Throws glint::Error when k is outside
  // [1, max(kMaxSmallK, k())] or the cloud has fewer than k points, or when `wanted` is given
  // with another size than the cloud's. With `wanted`, only the points with a non-zero entry are
  // queried (a sample costs what it holds, not the cloud); the other entries are 0.
  std::vector<float> kth_nearest_squared_distances(
      int k, const std::function<void(std::size_t)>& progress = {},
      std::span<const std::uint8_t> wanted = {}) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Neighbour lists of some points, kept from one pass of NeighbourhoodSearch::for_each so that a
// later pass visits them without searching again (visit_kept).
struct KeptNeighbourhoods {
  int k = 0;
  std::vector<std::uint32_t> points;  // the query points, increasing
  // k per point, nearest first, in the order of points. Megabytes for a gate's sample: a pool on
  // huge pages, since first touches of fresh 4 KiB pages cost about what a search of them does.
  PoolArray<std::uint32_t> neighbours;

  // Room for the lists of k neighbours of the points with a non-zero entry in `wanted`.
  KeptNeighbourhoods(std::span<const std::uint8_t> wanted, int k);
  KeptNeighbourhoods() = default;
  // Copies nb's list to its point's place. nb.size must be k and nb.point one of `points`
  // (glint::Error otherwise); safe from several threads for different points.
  void keep(const Neighbourhood& nb);
};

// Visits every kept neighbourhood as for_each visited it: the same neighbours in the same order,
// the same relative positions bit for bit, and their entries of `values` (one per point of the
// cloud) when given. From several threads at once; progress(points_done) as for_each's.
void visit_kept(const PointCloud& cloud, const KeptNeighbourhoods& kept,
                const std::function<void(const Neighbourhood&)>& visit,
                const std::function<void(std::size_t)>& progress = {},
                std::span<const float> values = {});

// NeighbourhoodSearch(cloud, params).for_each(visit, progress), for a single pass.
NeighbourhoodStats for_each_neighbourhood(const PointCloud& cloud,
                                          const NeighbourhoodParams& params,
                                          const std::function<void(const Neighbourhood&)>& visit,
                                          const std::function<void(std::size_t)>& progress = {});

}  // namespace glint::geometry
