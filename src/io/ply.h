#pragma once
// PLY (Stanford polygon format) point clouds: ascii, binary_little_endian and
// binary_big_endian; every scalar vertex property is kept as a typed attribute (x, y, z become
// the positions); list properties and every other element (faces, edges, ...) are skipped.
#include <string>

#include "core/point_cloud.h"

namespace glint::io {

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

PointCloud read_ply(const std::string& path);
// Writes x, y, z as float then every attribute with its own type, in insertion order.
void write_ply(const std::string& path, const PointCloud& cloud,
               PlyFormat format = PlyFormat::binary_little_endian);

}  // namespace glint::io
