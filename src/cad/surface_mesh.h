#pragma once
// Triangle meshes as the labeller samples them: a CAD kernel's tessellation of a B-rep, or a
// user's own mesh (an ABC-style OBJ, a scan's reconstruction). For a user's mesh the feature
// curves come from the mesh itself: its edges are classified by the turn of the normals of the
// triangles beside them, the rule classify_edge applies to a B-rep edge's two faces.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "edges/feature_index.h"

namespace glint::cad {

struct EdgeClasses;

struct SurfaceMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside, if known
};

// One key for the edge between vertices a and b, whichever way it is run.
inline std::uint64_t edge_key(int a, int b) {
  return (std::uint64_t(std::min(a, b)) << 32) | std::uint32_t(std::max(a, b));
}

// Unit normal of a triangle by its winding ((0, 0, 1) for a degenerate one) and its area.
Eigen::Vector3d triangle_normal(const SurfaceMesh& mesh, const std::array<int, 3>& t);
double triangle_area(const SurfaceMesh& mesh, const std::array<int, 3>& t);

// Every mesh edge classified from the non-degenerate triangles beside it: one is an open border
// (boundary); two are sharp when their normals turn by at least sharp_angle_deg (a pair that
// runs the edge the same way is wound inconsistently and is compared with one normal flipped);
// more than two (non-manifold) is sharp. An edge beside a degenerate triangle is not a feature.
// Smooth edges are counted, not kept. Call on a welded mesh: copies of a vertex split edges.
EdgeClasses classify_mesh_edges(const SurfaceMesh& mesh, double sharp_angle_deg);

// How a cut treats the triangles the plane crosses: clip them at the plane (the cut is a
// straight run of new mesh edges) or drop them whole (the border is jagged, one triangle wide,
// as when the points on one side of a plane are deleted).
enum class CutMode { clip, drop };

// The part of the surface on the positive side of the plane through `point` with normal
// `normal` (a vertex on the plane is kept), without a cap: the border the cut leaves is a run
// of mesh edges with one triangle, an open border. Vertices no kept triangle uses are dropped.
// Throws glint::Error("--cut-plane", ...) when nothing of the mesh lies on the kept side or
// the normal is zero.
SurfaceMesh cut_mesh(const SurfaceMesh& mesh, const Eigen::Vector3d& point,
                     const Eigen::Vector3d& normal, CutMode mode = CutMode::clip);

// The parts of the segments on the positive side of the same plane (clipped where they cross
// it): feature curves given beside a mesh, cut as the mesh is.
void cut_segments(std::vector<edges::FeatureSegment>& segments, const Eigen::Vector3d& point,
                  const Eigen::Vector3d& normal);

}  // namespace glint::cad
