#include "fusion/marching_cubes.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>

#include "core/parallel.h"
#include "fusion/marching_cubes_table.h"

namespace glint::fusion {
namespace {

// A vertex is identified by the voxel edge it lies on: the edge's lower voxel (global voxel
// coordinates, 20 bits each, offset 2^19) and its axis.
std::uint64_t edge_key(const Eigen::Vector3i& voxel, int axis) {
  constexpr int offset = 1 << 19;
  return (static_cast<std::uint64_t>(voxel.x() + offset) << 42) |
         (static_cast<std::uint64_t>(voxel.y() + offset) << 22) |
         (static_cast<std::uint64_t>(voxel.z() + offset) << 2) | static_cast<std::uint64_t>(axis);
}

// Read access to the voxels of a block and of its +x/+y/+z neighbours: local coordinates in
// [0, 8] on each axis.
class BlockNeighbourhood {
 public:
  BlockNeighbourhood(const TsdfVolume& volume, int block) : volume_(volume) {
    const Eigen::Vector3i coordinates = volume.hash().block(block);
    for (int n = 0; n < 8; ++n)
      blocks_[n] =
          volume.hash().find(coordinates + Eigen::Vector3i(n & 1, (n >> 1) & 1, (n >> 2) & 1));
  }
  // False when the voxel is unobserved (absent block or weight 0).
  bool get(int x, int y, int z, float& sdf) const {
    const int block = blocks_[(x >> 3) | ((y >> 3) << 1) | ((z >> 3) << 2)];
    if (block < 0) return false;
    const int voxel = voxel_in_block(x, y, z);
    if (volume_.weight(block)[voxel] <= 0) return false;
    sdf = volume_.sdf_m(block)[voxel];
    return true;
  }
  Eigen::Vector3f colour(int x, int y, int z) const {
    if (!volume_.has_colour()) return Eigen::Vector3f::Zero();
    const int block = blocks_[(x >> 3) | ((y >> 3) << 1) | ((z >> 3) << 2)];
    const int voxel = voxel_in_block(x, y, z);
    return {volume_.red(block)[voxel], volume_.green(block)[voxel], volume_.blue(block)[voxel]};
  }

 private:
  const TsdfVolume& volume_;
  std::array<int, 8> blocks_;
};

struct MeshPiece {
  std::vector<std::uint64_t> vertex_keys;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> colours;
  std::vector<std::array<std::uint64_t, 3>> triangles;
};

void extract_block(const TsdfVolume& volume, int block, MeshPiece& piece) {
  const BlockNeighbourhood voxels(volume, block);
  const Eigen::Vector3i first_voxel = volume.hash().block(block) * kBlockSide;
  const float voxel_size = static_cast<float>(volume.params().voxel_size_m);
  const auto& cases = marching_cubes_cases();
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      for (int x = 0; x < kBlockSide; ++x) {
        float sdf0;
        if (!voxels.get(x, y, z, sdf0)) continue;
        const Eigen::Vector3i voxel = first_voxel + Eigen::Vector3i(x, y, z);
        // Vertices on the three edges this voxel owns (towards +x, +y, +z).
        for (int axis = 0; axis < 3; ++axis) {
          const Eigen::Vector3i other = Eigen::Vector3i(x, y, z) + Eigen::Vector3i::Unit(axis);
          float sdf1;
          if (!voxels.get(other.x(), other.y(), other.z(), sdf1) || (sdf0 < 0) == (sdf1 < 0))
            continue;
          const float t = sdf0 / (sdf0 - sdf1);
          Eigen::Vector3f position = voxel.cast<float>() * voxel_size;
          position[axis] += t * voxel_size;
          piece.vertex_keys.push_back(edge_key(voxel, axis));
          piece.vertices.push_back(position);
          piece.colours.push_back((1 - t) * voxels.colour(x, y, z) +
                                  t * voxels.colour(other.x(), other.y(), other.z()));
        }
        // Triangles of the cube whose lowest corner is this voxel.
        int configuration = 0;
        bool observed = true;
        for (int c = 0; c < 8 && observed; ++c) {
          float sdf;
          observed = voxels.get(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1), sdf);
          if (observed && sdf < 0) configuration |= 1 << c;
        }
        if (!observed) continue;
        const CubeCase& cube = cases[configuration];
        for (int t = 0; t < cube.triangle_count; ++t) {
          std::array<std::uint64_t, 3> triangle;
          for (int k = 0; k < 3; ++k) {
            const CubeEdge& edge = kCubeEdges[cube.edges[3 * t + k]];
            const Eigen::Vector3i corner(edge.corner & 1, (edge.corner >> 1) & 1,
                                         (edge.corner >> 2) & 1);
            triangle[k] = edge_key(voxel + corner, edge.axis);
          }
          piece.triangles.push_back(triangle);
        }
      }
    }
  }
}

}  // namespace

TriangleMesh extract_mesh(const TsdfVolume& volume) {
  tbb::enumerable_thread_specific<MeshPiece> pieces;
  parallel_for(volume.block_count(), [&](std::size_t block) {
    extract_block(volume, static_cast<int>(block), pieces.local());
  });

  TriangleMesh mesh;
  std::vector<std::pair<std::uint64_t, int>> index_of_key;
  std::vector<std::array<std::uint64_t, 3>> triangle_keys;
  for (const MeshPiece& piece : pieces) {
    for (std::size_t i = 0; i < piece.vertices.size(); ++i)
      index_of_key.push_back({piece.vertex_keys[i], static_cast<int>(mesh.vertices.size() + i)});
    mesh.vertices.insert(mesh.vertices.end(), piece.vertices.begin(), piece.vertices.end());
    mesh.colours.insert(mesh.colours.end(), piece.colours.begin(), piece.colours.end());
    triangle_keys.insert(triangle_keys.end(), piece.triangles.begin(), piece.triangles.end());
  }
  tbb::parallel_sort(index_of_key.begin(), index_of_key.end());
  mesh.triangles.resize(triangle_keys.size());
  parallel_for(triangle_keys.size(), [&](std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      const auto found = std::lower_bound(index_of_key.begin(), index_of_key.end(),
                                          std::pair<std::uint64_t, int>{triangle_keys[t][k], -1});
      mesh.triangles[t][k] = found->second;
    }
  });
  return mesh;
}

}  // namespace glint::fusion
