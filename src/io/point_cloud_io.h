#pragma once
// Format dispatch by file extension (case-insensitive): .ply, .xyz/.txt/.pts/.csv, .pcd.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/point_cloud.h"

namespace glint::io {

// Throws glint::Error for unknown extensions, missing/unreadable files, malformed or truncated
// content, and non-finite coordinates (naming the vertex).
PointCloud read_point_cloud(const std::string& path);
// .ply (binary little-endian) or .xyz/.txt/.pts (text); written atomically.
void write_point_cloud(const std::string& path, const PointCloud& cloud);

// Per-point class labels from the first present attribute of "label", "scalar_label", "class",
// "scalar_class" (any numeric type; float values must be whole numbers in 0..255).
// std::nullopt when none is present; throws glint::Error("", attribute, reason) for values that
// are not whole numbers in 0..255.
std::optional<std::vector<std::uint8_t>> read_labels(const PointCloud& cloud);

}  // namespace glint::io
