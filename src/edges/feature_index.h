#pragma once
// Label lookup against ground-truth feature curves given as line segments: a point is sharp
// within a band of a sharp segment and boundary within a band of a boundary segment (boundary
// wins where both apply). Shared by the procedural generator (edges/synth) and the CAD-kernel
// labeller (cad/), so both label with exactly the same rule.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace glint::edges {

inline constexpr std::uint8_t kLabelSharp = 1, kLabelBoundary = 2;

struct FeatureSegment {
  Eigen::Vector3d a, b;
  std::uint8_t label;  // kLabelSharp or kLabelBoundary
};

// Euclidean distance from p to the segment [a, b].
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b);

// Segments are cut into pieces no longer than the largest band and hashed by their midpoints
// on a grid whose cell covers band + half a piece, so 27 cells always suffice.
class FeatureIndex {
 public:
  // max_band: the largest band label() will be asked for (same unit as the positions).
  FeatureIndex(const std::vector<FeatureSegment>& segments, double max_band);

  // 0, kLabelSharp or kLabelBoundary; bands must not exceed max_band.
  std::uint8_t label(const Eigen::Vector3d& p, double sharp_band, double boundary_band) const;

 private:
  std::array<std::int64_t, 3> coordinates(const Eigen::Vector3d& p) const;
  static std::uint64_t pack(const std::array<std::int64_t, 3>& c);

  double cell_;
  std::unordered_map<std::uint64_t, std::vector<FeatureSegment>> cells_;
};

}  // namespace glint::edges
