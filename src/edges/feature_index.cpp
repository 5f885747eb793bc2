#include "edges/feature_index.h"

#include <algorithm>
#include <cmath>

namespace glint::edges {

using Vec = Eigen::Vector3d;

double segment_distance(const Vec& p, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

FeatureIndex::FeatureIndex(const std::vector<FeatureSegment>& segments, double max_band)
    : cell_(2.0 * max_band) {
  for (const FeatureSegment& s : segments) {
    const int pieces = std::max(1, static_cast<int>(std::ceil((s.b - s.a).norm() / max_band)));
    for (int i = 0; i < pieces; ++i) {
      const Vec a = s.a + (s.b - s.a) * (double(i) / pieces);
      const Vec b = s.a + (s.b - s.a) * (double(i + 1) / pieces);
      cells_[pack(coordinates(0.5 * (a + b)))].push_back({a, b, s.label});
    }
  }
}

std::uint8_t FeatureIndex::label(const Vec& p, double sharp_band, double boundary_band) const {
  std::uint8_t result = 0;
  const auto centre = coordinates(p);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = cells_.find(pack({centre[0] + dx, centre[1] + dy, centre[2] + dz}));
        if (it == cells_.end()) continue;
        for (const FeatureSegment& s : it->second)
          if (s.label > result && segment_distance(p, s.a, s.b) <=
                                      (s.label == kLabelBoundary ? boundary_band : sharp_band))
            result = s.label;
      }
  return result;
}

std::array<std::int64_t, 3> FeatureIndex::coordinates(const Vec& p) const {
  return {std::int64_t(std::floor(p.x() / cell_)), std::int64_t(std::floor(p.y() / cell_)),
          std::int64_t(std::floor(p.z() / cell_))};
}

std::uint64_t FeatureIndex::pack(const std::array<std::int64_t, 3>& c) {
  return (std::uint64_t(c[0] & 0x1fffff) << 42) | (std::uint64_t(c[1] & 0x1fffff) << 21) |
         std::uint64_t(c[2] & 0x1fffff);
}

}  // namespace glint::edges
