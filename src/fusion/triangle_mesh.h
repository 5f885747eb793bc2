#pragma once
// TriangleMesh: indexed triangles with per-vertex linear colour, as extracted from the TSDF;
// PLY output and the measures the tests and reports use.
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace glint::fusion {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   // metres
  std::vector<Eigen::Vector3f> colours;    // linear RGB in [0,1], one per vertex (or empty)
  std::vector<Eigen::Vector3i> triangles;  // counter-clockwise seen from outside
  // Extra per-vertex float properties (PLY name, one value per vertex), e.g. material maps.
  std::vector<std::pair<std::string, std::vector<float>>> vertex_properties;
  // PLY header comments (one line each) that say what the colours and properties hold.
  std::vector<std::string> comments;
};

// Total triangle area, square metres.
double surface_area(const TriangleMesh& mesh);
// Signed enclosed volume by the divergence theorem, cubic metres (exact for a closed mesh;
// positive when the triangles face outwards).
double enclosed_volume(const TriangleMesh& mesh);

// Binary little-endian PLY: float x, y, z, uchar red, green, blue (8-bit sRGB), then the
// vertex_properties as floats, per vertex;
// "list uchar int vertex_indices" per face; the comments in the header. Written atomically;
// throws glint::Error naming the path (also for a comment with a line break).
void write_mesh_ply(const std::string& path, const TriangleMesh& mesh);

// Linear [0,1] -> 8-bit sRGB (IEC 61966-2-1), for colour output.
unsigned char linear_to_srgb8(float linear);

}  // namespace glint::fusion
