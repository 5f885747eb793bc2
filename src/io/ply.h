#pragma once
// PLY (Stanford polygon format) point clouds and triangle meshes: ascii, binary_little_endian
// and binary_big_endian; every scalar vertex property is kept as a typed attribute (x, y, z
// become the positions); read_ply skips list properties and every other element (faces,
// edges, ...), read_ply_mesh also reads the faces. Positions are read in double and re-centred
// (core/point_cloud.h, set_positions); an ascii body holds one record per line, and a line with
// fewer or more values than its element's properties is an error naming the line.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/point_cloud.h"

namespace glint::io {

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

PointCloud read_ply(const std::string& path);

struct PlyMesh {
  PointCloud vertices;                     // as read_ply reads them
  std::vector<Eigen::Vector3i> triangles;  // indices into vertices, in the file's winding
};
// The vertices and the "face" element's vertex_indices (or vertex_index) lists, polygons
// fan-triangulated (faces of fewer than three corners give none). Throws glint::Error as
// read_ply does, and for a face element without that list, a file without triangles or a
// vertex index out of range.
PlyMesh read_ply_mesh(const std::string& path);
// Writes x, y, z as float (as double, origin + position, for a cloud re-centred on a non-zero
// origin) then every attribute with its own type, in insertion order.
void write_ply(const std::string& path, const PointCloud& cloud,
               PlyFormat format = PlyFormat::binary_little_endian);

}  // namespace glint::io
