#pragma once
// PCD (Point Cloud Library) reader: DATA ascii and binary (binary_compressed is rejected with a
// clear error); FIELDS/SIZE/TYPE/COUNT honoured, multi-count fields skipped, "rgb" packed
// floats unpacked to red/green/blue uint8 attributes. Points with NaN coordinates (how PCL marks
// missing returns in organised clouds) are dropped.
#include <string>

#include "core/point_cloud.h"

namespace glint::io {

PointCloud read_pcd(const std::string& path);

}  // namespace glint::io
