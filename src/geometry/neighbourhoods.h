#pragma once
// Exact k-nearest neighbourhoods of every point of a cloud, computed tile by tile.
//
// Why not one k-d tree query per point: at k = 128 a plain k-d tree answers ~70k queries/s on
// two cores, and storing all lists for 1M points costs 1 GB (thesis §5.5.9 asks for a tailored
// search). Here points are bucketed in a uniform grid whose cell is about the k-th neighbour
// distance; all points of one cell share one gathered candidate set (the 3×3×3 block around
// it, contiguous in memory), distances are computed in a tight loop and the k nearest selected.
// A query is accepted only when its k-th distance is inside the block's guaranteed radius, so
// the result is exact; the few that are not (sparse regions, outliers) retry on a 5×5×5 block
// and then fall back to a k-d tree. Lists are handed to the visitor and never all stored.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/point_cloud.h"

namespace glint::geometry {

// One point's neighbourhood as seen by a visitor. Neighbours are ordered so that for every
// nested size s in NeighbourhoodParams::nested_sizes, the first s entries are exactly the s
// nearest (ties broken arbitrarily); beyond that the order is unspecified.
// Positions are relative to the query point (better float precision for the statistics).
struct Neighbourhood {
  std::uint32_t point = 0;       // index of the query point in the cloud
  int size = 0;                  // k = nested_sizes[0]
  const float* dx = nullptr;     // neighbour position minus query position, `size` entries
  const float* dy = nullptr;
  const float* dz = nullptr;
  const std::uint32_t* indices = nullptr;  // neighbour indices in the cloud
};

struct NeighbourhoodParams {
  // Neighbourhood sizes, largest first; the largest is the k of the search.
  std::vector<int> nested_sizes{128, 64, 32, 16};
  // Grid cell size in the cloud's unit; 0 = estimate as a high quantile of the k-th
  // neighbour distance from a subsample.
  double cell_size = 0.0;
};

struct NeighbourhoodStats {
  double cell_size = 0.0;
  std::size_t cells = 0;
  std::size_t retried_queries = 0;   // needed the 5×5×5 block
  std::size_t fallback_queries = 0;  // needed the k-d tree
};

// Calls visit(neighbourhood) once for every point, from several threads at once (the visitor
// must be thread-safe; the Neighbourhood's arrays are valid only during the call).
// progress(points_done) is called now and then from worker threads (may be empty).
// Throws glint::Error when the cloud has fewer points than k or k < 1.
NeighbourhoodStats for_each_neighbourhood(
    const PointCloud& cloud, const NeighbourhoodParams& params,
    const std::function<void(const Neighbourhood&)>& visit,
    const std::function<void(std::size_t)>& progress = {});

}  // namespace glint::geometry
