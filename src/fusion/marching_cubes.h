#pragma once
// Marching-cubes extraction of the TSDF's zero level set (Lorensen & Cline 1987) over all
// allocated blocks, in parallel. Cubes span 8 neighbouring voxels (across block borders); a
// cube with a corner never observed emits nothing. Each mesh vertex sits on a voxel
// edge, linearly interpolated between the two SDF values, and is shared by all triangles using
// that edge, so a closed surface gives a closed mesh. Vertices and triangles come in block order,
// the same for any number of threads.
#include "fusion/triangle_mesh.h"
#include "fusion/tsdf_volume.h"

namespace glint::fusion {

TriangleMesh extract_mesh(const TsdfVolume& volume);

}  // namespace glint::fusion
