#pragma once
// Triangle meshes from PLY files: the "vertex" element's x, y, z and the "face" element's
// vertex_indices (or vertex_index) list, polygons fan-triangulated; ascii and binary of either
// byte order. Every other element and property is skipped. Used by load_mesh (mesh_loader.h).
#include <string>

#include "render/mesh_loader.h"

namespace glint::render {

// Throws glint::Error naming the file (and the element) for a malformed header, a missing
// x/y/z or face list, truncated data or an index out of range.
TriangleMesh read_ply_mesh(const std::string& path);

}  // namespace glint::render
