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

// Whose labels a cloud is read for: ground truth looks at "label" first; a prediction (e.g. a
// `glint edges classify` output, which keeps the input's own "label" beside its
// "scalar_label") looks at "scalar_label" first.
enum class LabelSource { truth, prediction };

// Per-point class labels from the first present attribute of "label", "scalar_label", "class",
// "scalar_class" (for predictions: "scalar_label", "scalar_class", "label", "class"); any
// numeric type, float values must be whole numbers in 0..255. std::nullopt when none is
// present; throws glint::Error("", attribute, reason) for values that are not whole numbers in
// 0..255.
std::optional<std::vector<std::uint8_t>> read_labels(const PointCloud& cloud,
                                                     LabelSource source = LabelSource::truth);

}  // namespace glint::io
