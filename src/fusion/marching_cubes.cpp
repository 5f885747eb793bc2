#include "fusion/marching_cubes.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "core/error.h"
#include "core/parallel.h"
#include "fusion/marching_cubes_table.h"

namespace glint::fusion {
namespace {

// Voxels per side of a block with its +x/+y/+z neighbours' first layers.
constexpr int kSide = kBlockSide + 1;
constexpr int kEdgeBits = 3 * kVoxelsPerBlock;  // bit 3 * voxel + axis: the edge towards +axis
constexpr int kEdgeWords = kEdgeBits / 64;

constexpr int local_index(int x, int y, int z) { return (z * kSide + y) * kSide + x; }

// Which of a block's voxel edges carry a vertex, and the set bits before each word: a vertex's
// index within its block is then a popcount, so no pass has to search for the vertices of the
// triangles that reach into a neighbouring block.
struct BlockEdges {
  std::array<std::uint64_t, kEdgeWords> bits{};
  std::array<std::uint16_t, kEdgeWords> before{};
  int vertices = 0;
  int triangles = 0;

  int index_of(int bit) const {
    const int word = bit >> 6;
    const std::uint64_t lower = (std::uint64_t{1} << (bit & 63)) - 1;
    return before[std::size_t(word)] + std::popcount(bits[std::size_t(word)] & lower);
  }
};

// Read access to the voxels of a block and of its +x/+y/+z neighbours (local coordinates in
// [0, 8] on each axis), their distances copied once.
class BlockNeighbourhood {
 public:
  BlockNeighbourhood(const TsdfVolume& volume, int block) : volume_(volume) {
    const Eigen::Vector3i coordinates = volume.hash().block(block);
    for (int n = 0; n < 8; ++n)
      blocks_[std::size_t(n)] =
          volume.hash().find(coordinates + Eigen::Vector3i(n & 1, (n >> 1) & 1, (n >> 2) & 1));
    // Each voxel is read once here instead of once per edge and cube corner it belongs to.
    constexpr float unobserved = std::numeric_limits<float>::quiet_NaN();
    for (int z = 0; z < kSide; ++z)
      for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x) {
          const int owner = block_of(x, y, z);
          const int voxel = voxel_in_block(x, y, z);
          const float sdf = owner >= 0 ? volume.sdf_m(owner)[voxel] : kUnobservedSdf;
          sdf_[std::size_t(local_index(x, y, z))] = observed(sdf) ? sdf : unobserved;
        }
  }
  // The pool index of the block holding local voxel (x, y, z), -1 where none is allocated.
  int block_of(int x, int y, int z) const {
    return blocks_[std::size_t((x >> 3) | ((y >> 3) << 1) | ((z >> 3) << 2))];
  }
  // NaN where unobserved (absent block or never observed).
  float sdf(int x, int y, int z) const { return sdf_[std::size_t(local_index(x, y, z))]; }
  Eigen::Vector3f colour(int x, int y, int z) const {
    if (!volume_.has_colour()) return Eigen::Vector3f::Zero();
    const int block = block_of(x, y, z);
    const int voxel = voxel_in_block(x, y, z);
    return {volume_.red(block)[voxel], volume_.green(block)[voxel], volume_.blue(block)[voxel]};
  }
  // The marching-cubes case of the cube whose lowest corner is voxel (x, y, z) (x, y, z < 8),
  // -1 where a corner is unobserved.
  int configuration(int x, int y, int z) const {
    int configuration = 0;
    for (int c = 0; c < 8; ++c) {
      const float s = sdf(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1));
      if (std::isnan(s)) return -1;
      if (s < 0) configuration |= 1 << c;
    }
    return configuration;
  }

 private:
  const TsdfVolume& volume_;
  std::array<int, 8> blocks_;
  std::array<float, kSide * kSide * kSide> sdf_;
};

// Does the edge from local voxel (x, y, z) towards +axis cross the surface?
bool edge_has_vertex(const BlockNeighbourhood& voxels, int x, int y, int z, int axis) {
  const float sdf0 = voxels.sdf(x, y, z);
  const float sdf1 = voxels.sdf(x + (axis == 0), y + (axis == 1), z + (axis == 2));
  return !std::isnan(sdf0) && !std::isnan(sdf1) && (sdf0 < 0) != (sdf1 < 0);
}

BlockEdges count_block(const TsdfVolume& volume, int block) {
  const BlockNeighbourhood voxels(volume, block);
  const auto& cases = marching_cubes_cases();
  BlockEdges edges;
  for (int z = 0; z < kBlockSide; ++z)
    for (int y = 0; y < kBlockSide; ++y)
      for (int x = 0; x < kBlockSide; ++x) {
        const int bit = 3 * voxel_in_block(x, y, z);
        for (int axis = 0; axis < 3; ++axis)
          if (edge_has_vertex(voxels, x, y, z, axis))
            edges.bits[std::size_t((bit + axis) >> 6)] |= std::uint64_t{1} << ((bit + axis) & 63);
        const int configuration = voxels.configuration(x, y, z);
        if (configuration >= 0) edges.triangles += cases[std::size_t(configuration)].triangle_count;
      }
  for (int word = 0; word < kEdgeWords; ++word) {
    edges.before[std::size_t(word)] = std::uint16_t(edges.vertices);
    edges.vertices += std::popcount(edges.bits[std::size_t(word)]);
  }
  return edges;
}

// Writes the block's vertices from vertex_begin[block] and its triangles from
// triangle_begin[block]; a triangle's vertex on another block's edge is found through that
// block's edge bits.
void extract_block(const TsdfVolume& volume, int block, const std::vector<BlockEdges>& edges,
                   const std::vector<int>& vertex_begin, const std::vector<int>& triangle_begin,
                   TriangleMesh& mesh) {
  const BlockEdges& own = edges[std::size_t(block)];
  if (own.vertices == 0 && own.triangles == 0) return;  // most blocks: no need to read it again
  const BlockNeighbourhood voxels(volume, block);
  const Eigen::Vector3i first_voxel = volume.hash().block(block) * kBlockSide;
  const float voxel_size = static_cast<float>(volume.params().voxel_size_m);
  const auto& cases = marching_cubes_cases();
  int vertex = vertex_begin[std::size_t(block)];
  for (int word = 0; word < kEdgeWords; ++word)
    for (std::uint64_t bits = own.bits[std::size_t(word)]; bits != 0; bits &= bits - 1) {
      const int bit = word * 64 + std::countr_zero(bits);
      const int v = bit / 3, axis = bit % 3;
      const int x = v % kBlockSide, y = v / kBlockSide % kBlockSide,
                z = v / (kBlockSide * kBlockSide);
      const int x1 = x + (axis == 0), y1 = y + (axis == 1), z1 = z + (axis == 2);
      const float sdf0 = voxels.sdf(x, y, z);
      const float t = sdf0 / (sdf0 - voxels.sdf(x1, y1, z1));
      Eigen::Vector3f position =
          (first_voxel + Eigen::Vector3i(x, y, z)).cast<float>() * voxel_size;
      position[axis] += t * voxel_size;
      mesh.vertices[std::size_t(vertex)] = position;
      mesh.colours[std::size_t(vertex)] =
          (1 - t) * voxels.colour(x, y, z) + t * voxels.colour(x1, y1, z1);
      ++vertex;
    }
  int triangle = triangle_begin[std::size_t(block)];
  for (int z = 0; z < kBlockSide; ++z)
    for (int y = 0; y < kBlockSide; ++y)
      for (int x = 0; x < kBlockSide; ++x) {
        const int configuration = voxels.configuration(x, y, z);
        if (configuration < 0) continue;
        const CubeCase& cube = cases[std::size_t(configuration)];
        for (int t = 0; t < cube.triangle_count; ++t) {
          Eigen::Vector3i& indices = mesh.triangles[std::size_t(triangle++)];
          for (int k = 0; k < 3; ++k) {
            const CubeEdge& edge = kCubeEdges[cube.edges[3 * t + k]];
            const int ox = x + (edge.corner & 1), oy = y + ((edge.corner >> 1) & 1),
                      oz = z + ((edge.corner >> 2) & 1);
            const int owner = voxels.block_of(ox, oy, oz);
            indices[k] =
                vertex_begin[std::size_t(owner)] +
                edges[std::size_t(owner)].index_of(3 * voxel_in_block(ox, oy, oz) + edge.axis);
          }
        }
      }
}

}  // namespace

TriangleMesh extract_mesh(const TsdfVolume& volume) {
  const std::size_t blocks = volume.block_count();
  std::vector<BlockEdges> edges(blocks);
  parallel_for(blocks, [&](std::size_t block) { edges[block] = count_block(volume, int(block)); });

  // Vertices and triangles are laid out in the order of the blocks' coordinates, not of their
  // pool indices, which depend on how the threads happened to allocate them: a volume gives the
  // same mesh file on any number of threads.
  std::vector<std::uint64_t> keys(blocks);
  for (std::size_t block = 0; block < blocks; ++block) {
    const Eigen::Vector3i b = volume.hash().block(int(block));
    keys[block] = pack_block_key(b.x(), b.y(), b.z());
  }
  std::vector<int> order(blocks);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return keys[a] < keys[b]; });
  std::vector<int> vertex_begin(blocks), triangle_begin(blocks);
  std::int64_t vertices = 0, triangles = 0;
  for (const int block : order) {
    vertex_begin[block] = int(vertices);
    triangle_begin[block] = int(triangles);
    vertices += edges[block].vertices;
    triangles += edges[block].triangles;
    if (vertices > INT_MAX || triangles > INT_MAX)
      throw Error("marching cubes", "",
                  fmt::format("the mesh would have over {} vertices or triangles", INT_MAX));
  }
  TriangleMesh mesh;
  mesh.vertices.resize(std::size_t(vertices));
  mesh.colours.resize(std::size_t(vertices));
  mesh.triangles.resize(std::size_t(triangles));
  parallel_for(blocks, [&](std::size_t block) {
    extract_block(volume, int(block), edges, vertex_begin, triangle_begin, mesh);
  });
  return mesh;
}

}  // namespace glint::fusion
