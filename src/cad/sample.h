#pragma once
// Labelled point clouds from a B-rep (OpenCASCADE shape) or a triangle mesh: the labels come
// from the B-rep's edges (or the mesh's, surface_mesh.h), never from the samples.
//
// Edge classes (classify_edges): an edge with one adjacent face is an open border (boundary);
// one with two faces is sharp when the faces' normals, sampled at 9 points along the edge, turn
// by at least sharp_angle_deg somewhere (so the tangent-continuous edges of fillets and blends
// are smooth, a chamfer's 45 degree edges are sharp); more than two faces is sharp; seams of
// periodic faces and degenerate edges are not features.
//
// Labels: sharp within band x local spacing of a sharp edge, boundary within boundary_band x
// local spacing of a boundary (boundary wins where both apply), the same rule and defaults as
// `glint edges synth` (0.3 and 0.6 spacings: a band about one point wide, as Bazazian's and
// PCEDNet's sets label). Scan samplings also label as boundary the points next to surface no
// viewpoint sees (scan borders, occlusion borders, silhouettes).
//
// Samplings:
//   vertices  the nodes of BRepMesh_IncrementalMesh's tessellation (as ABC and PCEDNet clouds
//             are), or a mesh's own vertices: dense along curved faces and feature curves,
//             sparse on planes (their large triangles may be split down to
//             plane_edge_fraction of the diagonal); local spacing = mean length of a vertex's
//             mesh edges;
//   uniform   uniform random on the surface, spacing sqrt(area / points);
//   scan      rays from 1..viewpoints scanner positions in scan-line patterns (rows coarser than
//             the points along a row), density falling with range, occlusion holes, grazing
//             returns dropped; local spacing = range x angular step / sqrt(cos incidence).
// Noise: Gaussian along the surface normal, sigma = noise x the cloud's median spacing;
// outliers are displaced 2-15 spacings in a random direction and labelled where they land.
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cad/surface_mesh.h"
#include "core/point_cloud.h"
#include "edges/feature_index.h"

namespace glint::cad {

enum class Sampling { vertices, uniform, scan };
const std::vector<std::string>& sampling_names();
// Throws glint::Error("--sampling", name, ...) listing the known names.
Sampling parse_sampling(const std::string& name);

struct EdgeClasses {
  std::vector<edges::FeatureSegment> segments;  // sharp and boundary edges as polylines
  int sharp = 0, smooth = 0, boundary = 0;      // B-rep edge counts
  double sharp_length = 0.0, boundary_length = 0.0;

  // One more edge of the class (0 smooth) and `length`.
  void count(std::uint8_t label, double length);
};

// One edge's class given its (unique) adjacent faces: 0 smooth, edges::kLabelSharp,
// edges::kLabelBoundary, or kNotAFeature (seams, degenerate edges).
inline constexpr std::uint8_t kNotAFeature = 255;
std::uint8_t classify_edge(const TopoDS_Edge& edge, const TopTools_ListOfShape& faces,
                           double sharp_angle_deg);

// Every edge of the shape classified. polyline_tolerance: largest distance between an edge and its
// polyline (shape units).
EdgeClasses classify_edges(const TopoDS_Shape& shape, double sharp_angle_deg,
                           double polyline_tolerance);

struct SampleParams {
  Sampling sampling = Sampling::uniform;
  int points = 20000;          // uniform, scan: target count; vertices: most kept (a random subset)
  double band = 0.3;           // sharp label half-width, local spacings
  double boundary_band = 0.6;  // boundary label half-width, local spacings
  double sharp_angle_deg = 25.0;       // normal turn along an edge from which it is sharp
  double linear_deflection = 0.002;    // vertices: BRepMesh deflection, fraction of the diagonal
  double angular_deflection_deg = 20;  // vertices: BRepMesh angular deflection
  double plane_edge_fraction = 0.0;    // vertices: split longer triangle edges (0 = never)
  int viewpoints = 1;                  // scan: 1..viewpoints scanner positions are drawn
  double noise = 0.0;                  // sigma along the normal, in median spacings
  double outlier_share = 0.0;          // share of points displaced as outliers
  bool normalise = false;              // centre the cloud and scale its bounding-box diagonal to 1
  std::uint64_t seed = 1;
};

// Throws glint::Error("sample parameters", key, reason).
void check_sample_params(const SampleParams& params);

struct LabelledCloud {
  PointCloud cloud;            // x y z and uchar "label" (0 non-edge, 1 sharp, 2 boundary)
  nlohmann::json description;  // sampling, spacing, mesh, noise, edge classes, label counts
};

// Tessellates (replacing any triangulation the shape holds), samples and labels. Throws
// glint::Error when the shape has no faces or the kernel cannot tessellate it.
LabelledCloud sample_shape(const TopoDS_Shape& shape, const SampleParams& params);

// A triangle mesh (shape units) welded, sampled and labelled from its own edges
// (classify_mesh_edges); the deflections do not apply. `sharp_curves`, when given, replaces the
// sharp edges the mesh's angles find (an ABC features file's curves, abc_features.h); the
// boundaries stay the mesh's. "mesh_edges" in the description counts the edge classes.
// Throws glint::Error(name, ...) when the mesh has no triangles or no extent.
LabelledCloud sample_mesh(SurfaceMesh mesh, const SampleParams& params, const std::string& name,
                          const EdgeClasses* sharp_curves = nullptr);

}  // namespace glint::cad
