#pragma once
// Whitespace or comma separated text point clouds: .xyz (x y z [more columns]) and .pts
// (optionally a first line holding only the point count, as Leica/ABC files have).
// Columns after x y z are kept as float attributes; a header line naming the columns
// ("//X Y Z label" or "x y z label") names them, otherwise they are "column3", "column4", ...
// except that a fourth integer column in an otherwise xyz file is named "label".
#include <string>

#include "core/point_cloud.h"

namespace glint::io {

PointCloud read_text_cloud(const std::string& path);
// x y z then every attribute, space separated, one point per line, with a "//x y z ..." header.
void write_text_cloud(const std::string& path, const PointCloud& cloud);

}  // namespace glint::io
