#pragma once
// Point-to-surface distances between two triangle meshes, for comparing reconstructions:
// area-uniform samples on one mesh, exact distance to the other's nearest triangle (candidate
// triangles: those around the k nearest vertices of a k-d tree).
#include <cstdint>
#include <vector>

#include "fusion/triangle_mesh.h"

namespace glint::bench {

struct DistanceSummary {
  double median_m = 0;
  double mean_m = 0;
  double p90_m = 0;
  std::size_t samples = 0;
};

// Distances from `samples` area-uniform random points on `from` (seeded) to the surface of `to`.
DistanceSummary surface_distance(const fusion::TriangleMesh& from, const fusion::TriangleMesh& to,
                                 std::size_t samples, std::uint32_t seed = 7);

}  // namespace glint::bench
